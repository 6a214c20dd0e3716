// femb-inspect's checks: pass on a good superelement, fail on each kind of broken one.
#include "inspect/superelement_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "formats/input_error.h"
#include "test_util.h"

namespace femb {
namespace {

Superelement Good() {
  return test::Reduce(test::StraightBeamYaml(0.3, 10, "{shape: circle, diameter: 0.006}",
                                             "{E: 2.0e11, nu: 0.3, rho: 7870}", "[{name: A}, {name: B}]",
                                             "reduction: {internal_modes: 4}\n"));
}

bool Passed(const SuperelementAnalysis& a, const std::string& name) {
  for (const Check& c : a.checks) {
    if (c.name == name) return c.ok;
  }
  ADD_FAILURE() << "no check " << name;
  return false;
}

TEST(SuperelementChecks, GoodSuperelementPassesAll) {
  const SuperelementAnalysis a = AnalyzeSuperelement(Good());
  EXPECT_TRUE(a.all_ok());
  EXPECT_EQ(a.rigid_body_mode_count, 6);
  EXPECT_EQ(a.free_free_frequencies_hz.size(), 16);
  for (int k = 6; k < 16; ++k) EXPECT_GT(a.free_free_frequencies_hz[k], 100.0);
}

TEST(SuperelementChecks, EachDefectIsCaught) {
  {
    Superelement se = Good();
    se.K(0, 1) += 1e-3 * se.K.cwiseAbs().maxCoeff();
    EXPECT_FALSE(Passed(AnalyzeSuperelement(se), "K_symmetric"));
  }
  {
    Superelement se = Good();
    se.M(2, 3) += 1e-6;
    EXPECT_FALSE(Passed(AnalyzeSuperelement(se), "M_symmetric"));
  }
  {
    Superelement se = Good();
    se.M(12, 12) = -1.0;
    EXPECT_FALSE(Passed(AnalyzeSuperelement(se), "M_positive_definite"));
  }
  {
    // A grounding spring on one coordinate removes a rigid-body mode.
    Superelement se = Good();
    se.K(1, 1) += 1e3;
    const SuperelementAnalysis a = AnalyzeSuperelement(se);
    EXPECT_FALSE(Passed(a, "rigid_body_modes"));
    EXPECT_EQ(a.rigid_body_mode_count, 5);
  }
  {
    Superelement se = Good();
    se.floating_frame.Phi_CB(0, 0) += 0.1;
    EXPECT_FALSE(Passed(AnalyzeSuperelement(se), "floating_frame"));
  }
  {
    // Found by fuzzing (tests/fuzz/regressions/superelement_fuzz/phi_cb_mode_column_1e308): a
    // huge entry in an internal mode's column of Phi_CB, which Phi_CB Phi_rig0 = 1 does not see
    // (Phi_rig0 is zero on the modal rows), made the elastic force Inf.
    Superelement se = Good();
    ASSERT_GT(se.floating_frame.Phi_CB.cols(), se.n_interface_dofs());
    se.floating_frame.Phi_CB(5, se.floating_frame.Phi_CB.cols() - 1) = 1e308;
    EXPECT_TRUE(Passed(AnalyzeSuperelement(se), "finite"));
    EXPECT_FALSE(Passed(AnalyzeSuperelement(se), "floating_frame"));
    se.floating_frame.Phi_CB(5, se.floating_frame.Phi_CB.cols() - 1) = 1e12;
    EXPECT_FALSE(Passed(AnalyzeSuperelement(se), "floating_frame"));
    // Where K Phi_rig0 is exactly zero in that rigid direction the residual stays 0; the
    // projector's M-norm still catches it (phi_cb_mode_column_1e308_zero_residual).
    se = Good();
    const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, se.floating_frame.origin);
    se.K -= se.K * Phi_rig0 * se.floating_frame.Phi_CB;  // K Phi_rig0 = 0 to round-off
    se.K = 0.5 * (se.K + se.K.transpose()).eval();
    se.floating_frame.Phi_CB(2, se.floating_frame.Phi_CB.cols() - 1) = 1e308;
    EXPECT_FALSE(Passed(AnalyzeSuperelement(se), "floating_frame"));
  }
  {
    // A valid file's projector is moderate: the check passes with its norm printed.
    const SuperelementAnalysis a = AnalyzeSuperelement(Good());
    EXPECT_TRUE(Passed(a, "floating_frame"));
  }
  {
    Superelement se = Good();
    se.interfaces[1].orientation(0, 1) += 1e-3;
    EXPECT_FALSE(Passed(AnalyzeSuperelement(se), "interface_orientations"));
  }
  {
    Superelement se = Good();
    se.mass_properties.mass *= 1.01;
    EXPECT_FALSE(Passed(AnalyzeSuperelement(se), "mass"));
  }
  {
    Superelement se = Good();
    se.n_modal_derivatives = 1;
    se.modal_derivative_pairs = {{0, 99}};
    EXPECT_FALSE(Passed(AnalyzeSuperelement(se), "modal_derivative_pairs"));
    // Labels of out-of-range coordinates and pairs are said, not indexed (found by
    // tests/fuzz/superelement_fuzz: a pair (-5, ...) indexed kComponents[-5]).
    se.modal_derivative_pairs = {{-5, 99}};
    EXPECT_EQ(ReducedCoordinateLabel(se, -5), "coordinate -5 (out of range)");
    EXPECT_EQ(ReducedCoordinateLabel(se, se.n_reduced_dofs() + 3),
              "coordinate " + std::to_string(se.n_reduced_dofs() + 3) + " (out of range)");
    EXPECT_NE(ReducedCoordinateLabel(se, se.n_interface_dofs() + se.n_internal_modes()).find("(-5 x 99)"),
              std::string::npos);
  }
}

// A NaN or Inf anywhere is named by dataset and entry (a NaN once made the symmetry check report
// max|A - A^T| = 0, and crashed femb-solve in Phi_CB, the origin or the interface frames).
TEST(SuperelementChecks, EveryNonFiniteDatasetIsNamed) {
  const double nan = std::nan(""), inf = HUGE_VAL;
  const std::vector<std::pair<std::string, std::function<void(Superelement&)>>> cases = {
      {"/reduced/K", [&](Superelement& se) { se.K(3, 3) = nan; }},
      {"/reduced/M", [&](Superelement& se) { se.M(0, 5) = -inf; }},
      {"/floating_frame/Phi_CB", [&](Superelement& se) { se.floating_frame.Phi_CB(0, 0) = nan; }},
      {"/floating_frame/origin", [&](Superelement& se) { se.floating_frame.origin[1] = inf; }},
      {"/interfaces/positions", [&](Superelement& se) { se.interfaces[1].position[0] = nan; }},
      {"/interfaces/orientations", [&](Superelement& se) { se.interfaces[0].orientation(1, 1) = nan; }},
      {"/mass_properties/inertia_com", [&](Superelement& se) { se.mass_properties.inertia_com(2, 2) = nan; }},
      {"/reduced/internal_frequencies_hz", [&](Superelement& se) { se.internal_frequencies_hz[0] = inf; }}};
  for (const auto& [dataset, corrupt] : cases) {
    Superelement se = Good();
    corrupt(se);
    const SuperelementChecks c = CheckSuperelement(se);
    ASSERT_NE(c.first_failure(), nullptr) << dataset;
    EXPECT_EQ(c.first_failure()->name, "finite") << dataset;
    EXPECT_EQ(c.first_failure()->dataset, dataset);
    EXPECT_EQ(c.checks.size(), 1u) << "later checks are not evaluated on non-finite data";
    try {
      RequireValidSuperelement(se, "part.h5");
      ADD_FAILURE() << dataset << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("part.h5: " + dataset + ": check finite failed"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_NO_THROW(RequireValidSuperelement(Good(), "part.h5"));
}

}  // namespace
}  // namespace femb
