// Newton's convergence test weighs each unknown's residual by the force scale of the bodies acting
// on it (Assembly::dof_scale), not by the largest body's, so that one very stiff body does not
// loosen the tolerance of the others' unknowns. The slider-crank of test::SliderCrankModel
// (aluminium tube crank, a rod of two bodies, crank driven at 150 rad/s, gravity) with its crank
// made 10^4 times stiffer (K scaled; its force floor, 1e-4 of its stiffness, grows with it):
//  - the scales: the unknowns only the rod bodies act on (the rod's modes, its middle node) are
//    judged against the rod's forces, 10^4 times and more below the crank's; the crank's modes
//    against the crank's (the whole model's largest); in the dynamic and in the static assembly;
//  - the effect: at Newton tolerance 1e-3 against 1e-10, the rod midpoint's path with the stiff
//    crank. Measured 2.8e-4 m with the test per unknown, 4.4e-4 m with the whole model's scale
//    (the test reverted), 6e-5 m with the crank as is: the rod's own unknowns are solved as
//    tightly as with the soft crank, what remains comes through the unknowns the stiff crank
//    shares with the rod (its tip node, judged against the crank's forces). Asserted: below
//    3.5e-4 m (the whole-model scale's error less 20%).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdio>
#include <vector>

#include "solver/analysis/dynamic_analysis.h"
#include "solver/analysis/dynamic_step.h"
#include "solver/assembly/system.h"
#include "tests/test_util.h"

namespace femb {
namespace {

std::vector<Eigen::Vector3d> MidPath(const SystemModel& model, double tolerance) {
  DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(model.dofs().n_dofs()));
  DynamicOptions options;
  options.step = 1e-4;
  options.end_time = 0.042;  // one crank revolution
  options.rho_inf = 0.8;
  options.tolerance = tolerance;
  options.body_matrices_every = 8;  // Newton's matrix lags: the last iteration contracts linearly
  std::vector<Eigen::Vector3d> path;
  const DynamicResult r = SolveDynamic(model, s, options, [&](const DynamicStepReport&, const DynamicState& st) {
    path.push_back(st.config.x[3]);  // rod_mid
  });
  EXPECT_TRUE(r.ok) << r.message;
  return path;
}

double Largest(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  EXPECT_EQ(a.size(), b.size());
  double d = 0.0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return d;
}

SystemModel Model(bool stiff_crank) {
  Superelement rod = test::TubeSegment(0.25, 8, false);
  rod.K *= 1e-2;  // a soft rod (E = 0.7 GPa): it deflects visibly under the crank's drive
  Superelement crank = test::TubeSegment(0.15, 6, false);
  if (stiff_crank) crank.K *= 1e4;
  return test::SliderCrankModel(crank, rod, 0.15, 0.25);
}

TEST(NewtonScale, EachUnknownIsJudgedByTheBodiesActingOnIt) {
  const SystemModel model = Model(true);
  const DofMap& dofs = model.dofs();
  DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(dofs.n_dofs()));
  const Assembly a = dynamic_internal::AssembleDynamic(model, dofs, s, 0.0, false);
  ASSERT_TRUE(a.ok) << a.message;
  ASSERT_EQ(a.dof_scale.size(), dofs.n_dofs());
  const int mid = 3;  // rod_mid: a free node between the two rod bodies
  double rod_largest = 0.0;
  for (int b = 1; b <= 2; ++b)
    for (int m = 0; m < model.bodies[size_t(b)].n_modes(); ++m)
      rod_largest = std::max(rod_largest, a.dof_scale[dofs.mode_dof(b) + m]);
  for (int k = 0; k < dofs.node_count(mid); ++k)
    rod_largest = std::max(rod_largest, a.dof_scale[dofs.node_first(mid) + k]);
  double crank_smallest = HUGE_VAL;
  for (int m = 0; m < model.bodies[0].n_modes(); ++m)
    crank_smallest = std::min(crank_smallest, a.dof_scale[dofs.mode_dof(0) + m]);
  std::printf("[ info ] scales: the whole model %.3e N, the crank's modes %.3e N, the rod's unknowns at most %.3e N\n",
              a.scale, crank_smallest, rod_largest);
  EXPECT_EQ(crank_smallest, a.scale);
  EXPECT_GT(rod_largest, 0.0);
  EXPECT_LT(rod_largest, 1e-4 * a.scale);
}

TEST(NewtonScale, StaticsJudgesEachUnknownByItsBodiesToo) {
  // The same scales in a static assembly (AssembleStatic, static_analysis.cpp's test): at rest
  // the bodies' force floors, the crank's 10^6 times the soft rod's.
  const SystemModel model = Model(true);
  const DofMap& dofs = model.dofs();
  SystemState state = InitialState(model);
  const SystemForces f = AssembleStatic(model, dofs, state, 1.0, false);
  ASSERT_TRUE(f.ok) << f.message;
  ASSERT_EQ(f.dof_scale.size(), dofs.n_dofs());
  double rod_largest = 0.0, crank_smallest = HUGE_VAL;
  for (int b = 1; b <= 2; ++b)
    for (int m = 0; m < model.bodies[size_t(b)].n_modes(); ++m)
      rod_largest = std::max(rod_largest, f.dof_scale[dofs.mode_dof(b) + m]);
  for (int m = 0; m < model.bodies[0].n_modes(); ++m)
    crank_smallest = std::min(crank_smallest, f.dof_scale[dofs.mode_dof(0) + m]);
  std::printf("[ info ] static scales: the crank's modes %.3e N, the rod's modes at most %.3e N\n", crank_smallest,
              rod_largest);
  EXPECT_GT(rod_largest, 0.0);
  EXPECT_LT(rod_largest, 1e-4 * crank_smallest);
}

TEST(NewtonScale, AStiffBodyLoosensTheOthersLess) {
  const SystemModel soft = Model(false), stiff = Model(true);
  const double soft_error = Largest(MidPath(soft, 1e-3), MidPath(soft, 1e-10));
  const double stiff_error = Largest(MidPath(stiff, 1e-3), MidPath(stiff, 1e-10));
  std::printf("[ info ] rod midpoint path at tolerance 1e-3 against 1e-10: crank as is %.2e m, 1e4 x stiffer %.2e m\n",
              soft_error, stiff_error);
  EXPECT_GT(soft_error, 0.0);  // the loose tolerance is visible at all
  EXPECT_LT(stiff_error, 3.5e-4);
}

}  // namespace
}  // namespace femb
