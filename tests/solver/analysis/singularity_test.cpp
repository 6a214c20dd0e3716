// Singular system matrices: the dense solver refuses them (it once reported success), and the
// diagnosis names the free motion in the user's words.
#include "solver/analysis/singularity.h"

#include <gtest/gtest.h>

#include "solver/analysis/static_analysis.h"
#include "test_util.h"

namespace femb {
namespace {

Superelement Rod() {
  return test::Reduce(
      "name: rod\ntype: beam\nmaterial: {E: 2.0e11, nu: 0.3, rho: 7800}\n"
      "section: {shape: circle, diameter: 0.02}\n"
      "beam:\n  points: {A: [0, 0, 0], B: [1, 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: 4}]\n"
      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: 2}\n");
}

// One rod on nodes a (at the origin) and b (at x = 1), b loaded along y.
SystemModel Cantilever(const Superelement& se) {
  SystemModel model;
  AddNode(model, "a", Eigen::Vector3d::Zero());
  AddNode(model, "b", Eigen::Vector3d::UnitX());
  model.bodies.emplace_back(se, SuperelementOptions{}, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  model.body_nodes.push_back({0, 1});
  model.body_names.push_back("rod");
  NodeLoad load;
  load.node = 1;
  load.force = Eigen::Vector3d(0, -100, 0);
  model.loads.push_back(load);
  model.Number();
  return model;
}

TEST(Singularity, ClampedCantileverIsRegular) {
  const Superelement se = Rod();
  SystemModel model = Cantilever(se);
  Clamp(model, 0);
  model.Number();
  const DofMap dofs(model);
  SystemState state = InitialState(model);
  const SystemForces f = AssembleStatic(model, dofs, state, 1.0, true);
  EXPECT_EQ(DescribeSingular(model, dofs, state, f.tangent), "");
  FreeSolver solver;
  EXPECT_TRUE(solver.Factor(dofs, f.tangent));
}

// A rod on a revolute joint about z at a: one free motion, the rotation about z; the dense
// solver refuses the matrix and the static analysis says which motion is free.
TEST(Singularity, RevoluteSupportLeavesTheRotationAboutItsAxis) {
  const Superelement se = Rod();
  SystemModel model = Cantilever(se);
  RevoluteToGround(model, 0, Eigen::Vector3d::UnitZ());
  model.Number();
  const DofMap dofs(model);
  SystemState state = InitialState(model);
  const SystemForces f = AssembleStatic(model, dofs, state, 1.0, true);
  FreeSolver solver;
  EXPECT_FALSE(solver.Factor(dofs, f.tangent));
  const std::string why = DescribeSingular(model, dofs, state, f.tangent);
  EXPECT_NE(why.find("(1 free motion,"), std::string::npos) << why;
  EXPECT_NE(why.find("node b: translation along y, rotation about z"), std::string::npos) << why;
  EXPECT_NE(why.find("node a: rotation about z"), std::string::npos) << why;
  SystemState s = InitialState(model);
  const StaticResult r = SolveStatic(model, s, StaticOptions{});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("static tangent at the start: the system matrix is singular"), std::string::npos)
      << r.message;
}

// Units do not count: the same regular system scaled (translations in mm, say) stays regular
// for the scaled solver, although its plain condition number passes 1e16.
TEST(Singularity, BadlyScaledRegularMatrixIsRegular) {
  SystemModel model;
  AddNode(model, "a", Eigen::Vector3d::Zero());
  model.Number();
  const DofMap dofs(model);
  Triplets t;
  const double scales[6] = {1e12, 1e12, 1e12, 1e-6, 1e-6, 1e-6};
  for (int i = 0; i < 6; ++i) t.emplace_back(i, i, scales[i] * (2.0 + i));
  t.emplace_back(0, 3, 1e3);
  t.emplace_back(3, 0, 1e3);
  const SystemMatrix S = ToMatrix(6, t);
  FreeSolver solver;
  ASSERT_TRUE(solver.Factor(dofs, S));
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(6, 1.0, 2.0);
  const Eigen::VectorXd b = S * x;
  // Error in the energy-like norm sqrt(s_ii) |x_i| (the plain norm would be the 1e-6 entries').
  const Eigen::VectorXd w = Eigen::VectorXd(S.diagonal()).cwiseSqrt();
  EXPECT_LT((w.asDiagonal() * (solver.Solve(b) - x)).norm() / (w.asDiagonal() * x).norm(), 1e-14);
  const SystemState state = InitialState(model);
  EXPECT_EQ(DescribeSingular(model, dofs, state, S), "");
}

}  // namespace
}  // namespace femb
