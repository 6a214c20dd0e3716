// The system assembly (unit tests for it): the numbering of the unknowns
// (nodes on every kind of support, joint children, modal coordinates, the multipliers of cut
// joints and of body constraints, prescribed coordinates), increments that keep each support's
// motion exact (a revolute node turns about its fixed axis by the sum of its increments), the
// static residual of a free body balancing its loads (the internal forces have no resultant and
// no moment: the floating frame's rigid-body invariance), and the static tangent of a chain on
// cylindrical, spherical and prismatic supports under a follower load and gravity (the weight's
// configuration derivative included) against central differences.
#include "solver/assembly/system.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include "solver/analysis/dynamic_analysis.h"
#include "solver/analysis/dynamic_step.h"
#include "solver/analysis/modal_analysis.h"
#include "solver/analysis/static_analysis.h"
#include "solver/rotation.h"
#include "test_util.h"

namespace femb {
namespace {

constexpr double kL = 0.4;

// A rod along x; `stiffened`: with geometric stiffening and the exact inertia; otherwise linear
// inside with the corotational inertia.
Superelement Rod(int modes, bool stiffened = false) {
  return test::Reduce(test::StraightBeamYaml(
      kL, 6, "{shape: circle, diameter: 0.02}", "{E: 2.0e9, nu: 0.3, rho: 7800}", "[{name: A}, {name: B}]",
      "reduction: {internal_modes: " + std::to_string(modes) +
          (stiffened ? ", geometric_stiffening: true" : ", geometric_stiffening: false") + "}\n"));
}

void AddRod(SystemModel& model, const Superelement& se, int a, int b) {
  SuperelementOptions options;
  options.exact_inertia = !se.inertia_stiffness.empty();  // as Rod says: the exact inertia with the stiffening
  model.bodies.emplace_back(se, options, Eigen::Matrix3d::Identity(), model.node_x0[size_t(a)]);
  model.body_nodes.push_back({a, b});
}

// One rod on two free nodes, a at the origin and b at (kL, 0, 0).
SystemModel OneFreeRod(const Superelement& rod) {
  SystemModel model;
  AddNode(model, "a", Eigen::Vector3d::Zero());
  AddNode(model, "b", Eigen::Vector3d(kL, 0, 0));
  AddRod(model, rod, 0, 1);
  model.Number();
  return model;
}

TEST(System, DofMapNumbersNodesModesAndMultipliers) {
  Superelement rod = Rod(2);
  Superelement held = rod;
  held.interface_constraint = Eigen::MatrixXd::Zero(1, 12);  // A.u_x = B.u_x: no stretch
  held.interface_constraint(0, 0) = M_SQRT1_2;
  held.interface_constraint(0, 6) = -M_SQRT1_2;
  SystemModel model;
  for (int k = 0; k < 6; ++k) AddNode(model, "n" + std::to_string(k), Eigen::Vector3d(kL * (k / 2 + k % 2), 0, 0));
  // n0 (0) - n1 (L): rod 0; n2 (L) - n3 (2L): rod 1, held; n4 (2L) - n5 (3L): rod 2.
  AddRod(model, rod, 0, 1);
  AddRod(model, held, 2, 3);
  AddRod(model, rod, 4, 5);
  RevoluteToGround(model, 0, Eigen::Vector3d::UnitZ());  // 1 coordinate
  model.joints.push_back(MakeNodeJoint(JointType::kSpherical, 2, 1, Eigen::Vector3d::UnitZ(), model.node_x0[1],
                                       model.node_R0[1], model.node_x0[2],
                                       model.node_R0[2]));  // 3
  Pin(model, 3);                                            // 3
  Clamp(model, 4);                                          // 0
  // n5 free (6), closing a loop to n3 through a cut revolute joint (5 equations).
  CutJoint cut;
  cut.joint = MakeNodeJoint(JointType::kRevolute, 5, 3, Eigen::Vector3d::UnitZ(), model.node_x0[3], model.node_R0[3],
                            model.node_x0[5], model.node_R0[5]);
  cut.name = "cut";
  for (int i = 0; i < 5; ++i) cut.equations.push_back(i);
  model.cut_joints.push_back(cut);
  model.prescribed.push_back(
      {0, 0, [](double t) { return t; }, [](double) { return 1.0; }, [](double) { return 0.0; }});
  model.Number();
  const DofMap dofs(model);
  const int counts[6] = {1, 6, 3, 3, 0, 6};
  int first = 0;
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(dofs.node_first(k), first) << k;
    EXPECT_EQ(dofs.node_count(k), counts[k]) << k;
    first += counts[k];
  }
  // Supports are joints to the ground too: n0's revolute is joint 0, n2's spherical joint 1.
  EXPECT_EQ(dofs.joint_of(0), 0);
  EXPECT_EQ(dofs.joint_of(2), 1);
  EXPECT_EQ(model.joints[2].parent, kGround);
  EXPECT_EQ(dofs.joint_of(4), 3);
  EXPECT_EQ(dofs.joint_of(1), -1);
  EXPECT_TRUE(dofs.free(1));
  for (int b = 0; b < 3; ++b) EXPECT_EQ(dofs.mode_dof(b), first + 2 * b) << b;
  EXPECT_EQ(dofs.first_multiplier(), first + 6);
  EXPECT_EQ(dofs.multiplier_first(0), first + 6);
  EXPECT_EQ(dofs.body_multiplier_first(0), -1);
  EXPECT_EQ(dofs.body_multiplier_first(1), first + 6 + 5);
  EXPECT_EQ(dofs.body_multiplier_first(2), -1);
  EXPECT_EQ(dofs.n_multipliers(), 6);
  EXPECT_EQ(dofs.n_dofs(), first + 6 + 6);
  EXPECT_TRUE(model.has_constraints());
  // The prescribed revolute coordinate is not solved for; everything else is.
  EXPECT_TRUE(dofs.prescribed(0));
  EXPECT_EQ(int(dofs.solved().size()), dofs.n_dofs() - 1);
  EXPECT_EQ(dofs.solved().front(), 1);
  // Parents before children.
  const std::vector<int>& order = dofs.order();
  EXPECT_LT(std::find(order.begin(), order.end(), 1) - order.begin(),
            std::find(order.begin(), order.end(), 2) - order.begin());
}

// The model owns its numbering (SystemModel::dofs()): made once and shared by
// the analyses, made anew when the structure changes, and valid after the model is gone (the
// map holds no reference into the model, which a Scene moves). Supports are joints to the
// ground: a second support of a node replaces the first.
TEST(System, ModelOwnsItsDofMap) {
  const Superelement rod = Rod(2);
  SystemModel model = OneFreeRod(rod);
  const DofMap* first = &model.dofs();
  EXPECT_EQ(first->n_dofs(), 14);   // two free nodes and two modes
  EXPECT_EQ(&model.dofs(), first);  // kept, not made again
  const SystemModel copy = model;
  EXPECT_EQ(&copy.dofs(), first);                        // a copy of the model shares it
  RevoluteToGround(model, 0, Eigen::Vector3d::UnitZ());  // the structure changes
  EXPECT_THROW(model.dofs(), std::logic_error);          // not numbered for it yet
  model.Number();
  EXPECT_EQ(model.dofs().n_dofs(), 9);
  EXPECT_EQ(model.dofs().node_count(0), 1);
  RevoluteToGround(model, 0, Eigen::Vector3d::UnitY());  // same shape, another axis
  ASSERT_EQ(model.joints.size(), 1u);                    // replaced, not added
  EXPECT_EQ(model.dofs().n_dofs(), 9);                   // the numbering still holds
  const SystemState state = InitialState(model);
  ASSERT_EQ(state.J[0].size(), 1u);
  EXPECT_EQ(state.J[0][0].second.tail<3>(), Eigen::Vector3d::UnitY());
  EXPECT_EQ(copy.dofs().n_dofs(), 14);  // the copy keeps its own
  std::unique_ptr<DofMap> kept;
  {
    SystemModel moved = std::move(model);
    kept = std::make_unique<DofMap>(moved.dofs());
  }
  EXPECT_EQ(kept->node_count(0), 1);  // valid without the model
  EXPECT_TRUE(kept->free(1));
  EXPECT_EQ(kept->node_count(1), 6);
  SystemModel unnumbered;
  AddNode(unnumbered, "a", Eigen::Vector3d::Zero());
  EXPECT_THROW(unnumbered.dofs(), std::logic_error);
}

TEST(System, IncrementsKeepEachSupportsMotionExact) {
  const Superelement rod = Rod(0);
  SystemModel model;
  const Eigen::Vector3d axis = Eigen::Vector3d(0.36, 0.48, 0.8);
  const Eigen::Matrix3d R0 = ExpSO3(Eigen::Vector3d(0.3, -0.2, 0.5));
  AddNode(model, "revolute", Eigen::Vector3d::Zero(), R0);
  AddNode(model, "prismatic", Eigen::Vector3d(kL, 0, 0), R0);
  AddNode(model, "free", Eigen::Vector3d(2 * kL, 0, 0), R0);
  AddRod(model, rod, 0, 1);
  AddRod(model, rod, 1, 2);
  RevoluteToGround(model, 0, axis);
  PrismaticToGround(model, 1, axis);
  model.Number();
  const DofMap dofs(model);
  SystemState state = InitialState(model);
  const double phi[3] = {0.7, -1.9, 2.6};
  double total = 0.0;
  Eigen::Matrix3d R_free = R0;
  Eigen::Vector3d x_free = model.node_x0[2];
  for (const double p : phi) {
    Eigen::VectorXd delta = Eigen::VectorXd::Zero(dofs.n_dofs());
    delta[dofs.node_first(0)] = p;
    delta[dofs.node_first(1)] = 0.1 * p;
    const Eigen::Matrix<double, 6, 1> free_step =
        (Eigen::Matrix<double, 6, 1>() << 0.01, -0.02, 0.03, p, 0.5 * p, -p).finished();
    delta.segment<6>(dofs.node_first(2)) = free_step;
    ApplyIncrement(model, dofs, delta, state);
    total += p;
    R_free = ExpSO3(Eigen::Vector3d(free_step.tail<3>())) * R_free;  // spatial increments
    x_free += free_step.head<3>();
  }
  const Eigen::Matrix3d R_expected = ExpSO3(Eigen::Vector3d(total * axis)) * R0;
  EXPECT_LT((state.R[0] - R_expected).norm(), 1e-14);
  EXPECT_LT(state.x[0].norm(), 1e-15);
  EXPECT_LT((state.x[1] - (model.node_x0[1] + 0.1 * total * axis)).norm(), 1e-15);
  EXPECT_LT((state.R[1] - R0).norm(), 1e-15);
  EXPECT_LT((state.R[2] - R_free).norm(), 1e-14);
  EXPECT_LT((state.x[2] - x_free).norm(), 1e-15);
  // The node Jacobians: the revolute node's column is its axis on the rotation rows.
  ASSERT_EQ(state.J[0].size(), 1u);
  EXPECT_LT((state.J[0][0].second.tail<3>() - axis).norm(), 1e-15);
  EXPECT_LT(state.J[0][0].second.head<3>().norm(), 1e-15);
}

TEST(System, StaticResidualOfAFreeBodyBalancesItsLoads) {
  const Superelement rod = Rod(2);
  SystemModel model = OneFreeRod(rod);
  NodeLoad load;
  load.node = 1;
  load.force = Eigen::Vector3d(3, -5, 2);
  load.moment = Eigen::Vector3d(0.2, 0.1, -0.4);
  model.loads.push_back(load);
  const DofMap dofs(model);
  SystemState state = InitialState(model);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd shift(dofs.n_dofs());
  for (int i = 0; i < shift.size(); ++i) shift[i] = 0.3 * u(rng);  // a large rotation and a deformation
  ApplyIncrement(model, dofs, shift, state);
  const SystemForces f = AssembleStatic(model, dofs, state, 1.0, false);
  ASSERT_TRUE(f.ok) << f.message;
  // residual = loads - internal forces; the internal forces of a body have no resultant and no
  // moment about the origin (rotation rows: spatial moments about each node).
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
  for (int k = 0; k < 2; ++k) {
    const Eigen::Matrix<double, 6, 1> r = f.residual.segment<6>(dofs.node_first(k));
    force += r.head<3>();
    moment += state.x[size_t(k)].cross(Eigen::Vector3d(r.head<3>())) + r.tail<3>();
  }
  const Eigen::Vector3d load_moment = state.x[1].cross(load.force) + load.moment;
  const double scale = f.residual.norm();
  std::printf(
      "[ info ] free body, deformed and turned: resultant %.2e N off the load, moment %.2e N m off "
      "(residual "
      "%.3g)\n",
      (force - load.force).norm(), (moment - load_moment).norm(), scale);
  EXPECT_GT(scale, 10 * load.force.norm());  // the deformation's internal forces are large
  EXPECT_LT((force - load.force).norm(), 1e-9 * scale);
  EXPECT_LT((moment - load_moment).norm(), 1e-9 * scale * kL);
}

// Also with a stiffened file, whose bodies use the exact inertia (its weight's tangent by
// differences) and the weight's geometric stiffness.
TEST(System, StaticTangentOnEveryKindOfSupportMatchesFiniteDifferences) {
  for (const bool stiffened : {false, true}) {
    const Superelement rod = Rod(2, stiffened);
    SystemModel model;
    const Eigen::Vector3d axis = Eigen::Vector3d(0.36, 0.48, 0.8);
    AddNode(model, "n0", Eigen::Vector3d::Zero());
    AddNode(model, "n1", Eigen::Vector3d(kL, 0, 0));
    AddNode(model, "n2", Eigen::Vector3d(2 * kL, 0, 0));
    AddNode(model, "n3", Eigen::Vector3d(3 * kL, 0, 0));
    AddRod(model, rod, 0, 1);
    AddRod(model, rod, 1, 2);
    AddRod(model, rod, 2, 3);
    CylindricalToGround(model, 0, axis);
    Pin(model, 2);
    PrismaticToGround(model, 3, Eigen::Vector3d::UnitX());
    NodeLoad load;
    load.node = 1;
    load.force = Eigen::Vector3d(10, -20, 15);
    load.moment = Eigen::Vector3d(1, 2, -1);
    load.follower = true;
    model.loads.push_back(load);
    model.gravity = Eigen::Vector3d(0, -9.81, 0);
    model.static_gravity_end = 1.0;
    model.Number();
    const DofMap dofs(model);
    SystemState state = InitialState(model);
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(-1, 1);
    Eigen::VectorXd shift(dofs.n_dofs());
    for (int i = 0; i < shift.size(); ++i) shift[i] = 0.05 * u(rng);
    ApplyIncrement(model, dofs, shift, state);
    const SystemForces f = AssembleStatic(model, dofs, state, 1.0, true);
    ASSERT_TRUE(f.ok) << f.message;
    const Eigen::MatrixXd K(f.tangent);
    const Eigen::MatrixXd K_fd = test::StaticTangentByDifferences(model, dofs, state, 1.0);
    const double error = (K - K_fd).norm() / K_fd.norm();
    std::printf(
        "[ info ] 3 %s rods on cylindrical, spherical and prismatic supports, follower load, "
        "gravity: %d "
        "unknowns, tangent error %.2e\n",
        stiffened ? "stiffened" : "linear", dofs.n_dofs(), error);
    EXPECT_LT(error, 1e-6);
  }
}

// The dynamic iteration matrix's K = -dr/dq of a flexible chain under gravity, at rest (no
// velocity terms) in a displaced configuration with accelerations, against central differences
// of the residual: the inertia's configuration derivative and the weight's together (for the
// corotational and the exact inertia; the latter is the inertia force's acceleration part at
// the uniform field g, so one derivative takes both).
TEST(System, DynamicIterationMatrixUnderGravityMatchesFiniteDifferences) {
  for (const bool stiffened : {false, true}) {
    const Superelement rod = Rod(2, stiffened);
    SystemModel model;
    AddNode(model, "n0", Eigen::Vector3d::Zero());
    AddNode(model, "n1", Eigen::Vector3d(kL, 0, 0));
    AddNode(model, "n2", Eigen::Vector3d(kL, 0, 0));
    AddNode(model, "n3", Eigen::Vector3d(2 * kL, 0, 0));
    AddRod(model, rod, 0, 1);
    AddRod(model, rod, 2, 3);
    RevoluteToGround(model, 0, Eigen::Vector3d::UnitZ());
    model.joints.push_back(MakeNodeJoint(JointType::kRevolute, 2, 1, Eigen::Vector3d(0.36, 0.48, 0.8), model.node_x0[1],
                                         model.node_R0[1], model.node_x0[2], model.node_R0[2]));
    model.gravity = Eigen::Vector3d(0, -9.81, 0);
    model.Number();
    const DofMap dofs(model);
    const int n = dofs.n_dofs();
    DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(n));
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(-1, 1);
    Eigen::VectorXd shift(n);
    for (int i = 0; i < n; ++i) shift[i] = 0.3 * u(rng), s.Wdot[i] = 5.0 * u(rng);
    ApplyIncrement(model, dofs, shift, s.config);
    s.W.setZero();
    using namespace dynamic_internal;
    BodyWorkspace work;
    DynamicState base = s;
    Assembly a = AssembleDynamicResidual(model, dofs, base, s.t, work);
    AddDynamicMatrices(model, dofs, base, s.t, work, false, a);
    const Eigen::MatrixXd K(a.K);
    auto residual = [&](const DynamicState& state) {
      DynamicState copy = state;
      BodyWorkspace w;
      return AssembleDynamicResidual(model, dofs, copy, s.t, w).residual;
    };
    Eigen::MatrixXd K_fd(n, n);
    for (int j = 0; j < n; ++j) {
      const double h = 1e-6;
      DynamicState plus = s, minus = s;
      ApplyIncrement(model, dofs, h * Eigen::VectorXd::Unit(n, j), plus.config);
      ApplyIncrement(model, dofs, -h * Eigen::VectorXd::Unit(n, j), minus.config);
      K_fd.col(j) = -(residual(plus) - residual(minus)) / (2 * h);
    }
    const double error = (K - K_fd).norm() / K_fd.norm();
    std::printf(
        "[ info ] %s flexible double pendulum at rest under gravity, accelerating: K against "
        "differences "
        "%.2e\n",
        stiffened ? "stiffened" : "linear", error);
    // The exact inertia's configuration derivative is the corotational one's without
    // full_inertia_tangent (superelement_body.h): exact only for the corotational inertia.
    EXPECT_LT(error,
              stiffened ? 1e-5 : 1e-6);  // measured 2.1e-6 and 1.3e-10 (3.5e-6 without the weight)
  }
}

// A steel rod hanging from a revolute joint to ground, solved statically from its unstretched
// placement: the first tangent is singular (no tension yet, so nothing resists a swing), the
// weight does not drive the swing, and one minimum-norm step along the rod makes it regular.
// References: the stretch under its own weight, rho g L^2 / (2 E) (closed form), and the swing
// frequency about that state, the compound pendulum's sqrt(3 g / 2 L) / 2 pi (the rod is stiff:
// its bending frequencies are 100x higher); the swing's stiffness is the weight's tangent and
// the tension's geometric stiffness together.
TEST(System, HangingRodSolvesStaticallyAndSwingsAtThePendulumFrequency) {
  const double E = 2.0e11, rho = 7800, g = 9.81;
  const Superelement rod =
      test::Reduce(test::StraightBeamYaml(kL, 6, "{shape: circle, diameter: 0.02}", "{E: 2.0e11, nu: 0.3, rho: 7800}",
                                          "[{name: A}, {name: B}]", "reduction: {internal_modes: 2}\n"));
  SystemModel model;
  const Eigen::Matrix3d down = ExpSO3(Eigen::Vector3d(0, 0, -M_PI / 2));
  AddNode(model, "a", Eigen::Vector3d::Zero(), down);
  AddNode(model, "b", Eigen::Vector3d(0, -kL, 0), down);
  model.bodies.emplace_back(rod, SuperelementOptions{}, down, Eigen::Vector3d::Zero());
  model.body_nodes.push_back({0, 1});
  RevoluteToGround(model, 0, Eigen::Vector3d::UnitZ());
  model.gravity = Eigen::Vector3d(0, -g, 0);
  model.static_gravity_end = 1.0;
  model.Number();
  SystemState state = InitialState(model);
  StaticOptions options;
  options.steps = 2;
  const StaticResult r = SolveStatic(model, state, options);
  ASSERT_TRUE(r.ok) << r.message;
  const double stretch = -state.x[1].y() - kL, closed = rho * g * kL * kL / (2 * E);
  const ModalResult modes = LinearizedModes(model, state, 1.0, 3);
  ASSERT_TRUE(modes.ok) << modes.message;
  const double pendulum = std::sqrt(3 * g / (2 * kL)) / (2 * M_PI);
  std::printf(
      "[ info ] hanging rod: stretch %.6e m (rho g L^2 / 2E %.6e m); swing %.5f Hz (compound "
      "pendulum %.5f "
      "Hz, %+.3f%%), next mode %.1f Hz\n",
      stretch, closed, modes.frequencies_hz[0], pendulum, 100 * (modes.frequencies_hz[0] / pendulum - 1),
      modes.frequencies_hz[1]);
  EXPECT_NEAR(stretch, closed, 1e-3 * closed);
  EXPECT_NEAR(modes.frequencies_hz[0], pendulum, 1e-3 * pendulum);
  EXPECT_GT(modes.frequencies_hz[1], 50 * pendulum);
}

}  // namespace
}  // namespace femb
