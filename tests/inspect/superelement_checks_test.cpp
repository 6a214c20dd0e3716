// femb-inspect's checks: pass on a good superelement, fail on each kind of broken one.
#include "inspect/superelement_checks.h"

#include <gtest/gtest.h>

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
}

}  // namespace
}  // namespace femb
