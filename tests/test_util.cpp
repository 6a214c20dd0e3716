#include "test_util.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "reducer/fe/beam_model.h"
#include "reducer/reduce_part.h"
#include "reducer/reduction/full_modes.h"

namespace femb::test {

// Elastica of a cantilever under a tip load P that stays vertical: theta(s) the downward
// rotation, EI theta'' = -P cos(theta), theta(0) = 0, theta'(L) = 0. Its first integral
// EI theta'^2 / 2 = P (sin theta_L - sin theta) gives theta'(0) = sqrt(2 P sin(theta_L) / EI) for
// a tip angle theta_L in (0, pi/2); shooting on theta_L by bisection: the arc length at which
// theta' first reaches 0 (theta = theta_L) grows monotonically with theta_L and must equal L.
// RK4, 4000 steps.
// Returns the tip (horizontal shortening, downward deflection).
Eigen::Vector2d ElasticaTip(double P, double EI, double L) {
  auto shoot = [&](double theta_L, Eigen::Vector2d* tip) {
    const int n = 4000;
    const double h = L / n;
    Eigen::Vector4d y(0, std::sqrt(2 * P * std::sin(theta_L) / EI), 0, 0);  // theta, theta', x, w
    auto rhs = [&](const Eigen::Vector4d& s) {
      return Eigen::Vector4d(s[1], -P / EI * std::cos(s[0]), std::cos(s[0]), std::sin(s[0]));
    };
    bool stopped = false;  // theta' reached 0 before s = L
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector4d k1 = rhs(y), k2 = rhs(y + 0.5 * h * k1), k3 = rhs(y + 0.5 * h * k2), k4 = rhs(y + h * k3);
      y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      stopped |= y[1] < 0;
    }
    if (tip) *tip = Eigen::Vector2d(L - y[2], y[3]);
    return stopped;
  };
  double lo = 1e-9, hi = M_PI / 2 - 1e-12;
  EXPECT_TRUE(shoot(lo, nullptr));
  EXPECT_FALSE(shoot(hi, nullptr));
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (shoot(mid, nullptr) ? lo : hi) = mid;
  }
  Eigen::Vector2d tip;
  shoot(0.5 * (lo + hi), &tip);
  return tip;
}

std::string StraightBeamYaml(double L, int elements, const std::string& section, const std::string& material,
                             const std::string& interfaces, const std::string& extra) {
  std::ostringstream s;
  s.precision(17);
  s << "name: test_beam\ntype: beam\nmaterial: " << material << "\nsection: " << section
    << "\nbeam:\n  points:\n    A: [0, 0, 0]\n    B: [" << L << ", 0, 0]\n"
    << "  segments:\n    - {from: A, to: B, elements: " << elements << "}\n"
    << "interfaces: " << interfaces << "\n"
    << extra;
  return s.str();
}

SystemModel ClampedOneBodyModel(const Superelement& se, double L, const Eigen::Vector3d& tip_force) {
  SystemModel model;
  AddNode(model, "n0", Eigen::Vector3d::Zero());
  AddNode(model, "n1", Eigen::Vector3d(L, 0, 0));
  model.bodies.emplace_back(se, SuperelementOptions{}, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  model.body_nodes.push_back({0, 1});
  Clamp(model, 0);
  NodeLoad load;
  load.node = 1;
  load.force = tip_force;
  model.loads.push_back(load);
  model.Number();
  return model;
}

Superelement TubeSegment(double L, int elements, bool stiffened) {
  return Reduce(
      "name: seg\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
      "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
      "beam:\n  points: {A: [0, 0, 0], B: [" +
      std::to_string(L) +
      ", 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: " +
      std::to_string(elements) +
      "}]\n"
      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: 2, keep_mesh: false, "
      "geometric_stiffening: " +
      std::string(stiffened ? "true" : "false") + "}\n");
}

DynamicState AdvanceSteps(const SystemModel& model, DynamicState s, Integrator integrator, double h, int steps,
                          double tolerance) {
  DynamicOptions options;
  options.integrator = integrator;
  options.step = h;
  options.end_time = s.t + steps * h;
  options.tolerance = tolerance;
  options.threads = 1;
  const DynamicResult r = SolveDynamic(model, s, options, nullptr);
  EXPECT_TRUE(r.ok) << r.message;
  return s;
}

SystemModel SliderCrankModel(const Superelement& crank, const Superelement& rod, double Lc, double Lr,
                             const SuperelementOptions& options) {
  SystemModel model;
  const int O = AddNode(model, "O", Eigen::Vector3d::Zero());
  const int A = AddNode(model, "A", Eigen::Vector3d(Lc, 0, 0));
  const int a = AddNode(model, "rod_a", Eigen::Vector3d(Lc, 0, 0));
  const int m = AddNode(model, "rod_mid", Eigen::Vector3d(Lc + Lr, 0, 0));
  const int b = AddNode(model, "rod_b", Eigen::Vector3d(Lc + 2 * Lr, 0, 0));
  const int s = AddNode(model, "slider", Eigen::Vector3d(Lc + 2 * Lr, 0, 0));
  model.bodies.emplace_back(crank, SuperelementOptions{}, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  model.body_nodes.push_back({O, A});
  for (int i = 0; i < 2; ++i) {
    model.bodies.emplace_back(rod, options, Eigen::Matrix3d::Identity(), Eigen::Vector3d(Lc + i * Lr, 0, 0));
    model.body_nodes.push_back({i == 0 ? a : m, i == 0 ? m : b});
  }
  RevoluteToGround(model, O, Eigen::Vector3d::UnitZ());
  SystemModel::Prescribed drive;
  drive.node = O;
  drive.value = [](double t) { return 150.0 * t; };
  drive.rate = [](double) { return 150.0; };
  drive.acceleration = [](double) { return 0.0; };
  model.prescribed.push_back(drive);
  PrismaticToGround(model, s, Eigen::Vector3d::UnitX());
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  model.joints.push_back(MakeNodeJoint(JointType::kRevolute, a, A, z, model.node_x0[A], model.node_R0[A],
                                       model.node_x0[a], model.node_R0[a]));
  model.joints.push_back(MakeNodeJoint(JointType::kRevolute, b, s, z, model.node_x0[s], model.node_R0[s],
                                       model.node_x0[b], model.node_R0[b]));
  model.gravity = Eigen::Vector3d(0, -9.81, 0);
  model.Number();
  return model;
}

std::string Number(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

Superelement Reduce(const std::string& yaml, const std::vector<std::string>& overrides) {
  PartSpec part = ParsePart(yaml, "test.yaml", overrides);
  ReduceResult r = ReducePart(part, nullptr);
  EXPECT_TRUE(r.ok) << r.message;
  return r.superelement;
}

Superelement BendingShapesRod(double L) {
  const std::string beam = StraightBeamYaml(L, 20, "{shape: circle, diameter: 0.02}", "{E: 2.0e9, nu: 0.3, rho: 7800}",
                                            "[{name: A}, {name: B}]");
  const FeModel model = BuildBeamModel(ParsePart(beam, "rod.yaml"));
  Eigen::MatrixXd modes;
  Eigen::VectorXd lambda;
  EXPECT_TRUE(FullFreeFreeFrequencies(model, 10, 1.0, &modes, &lambda).ok);
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("femb_bending_shapes_" + std::to_string(::getpid()) + ".mtx");
  {
    std::ofstream out(path);
    out.precision(17);
    out << "%%MatrixMarket matrix array real general\n" << modes.rows() << " 4\n";
    for (long j = 6; j < 10; ++j)
      for (long i = 0; i < modes.rows(); ++i) out << modes(i, j) << "\n";
  }
  const Superelement se =
      Reduce(beam + "reduction: {method: general, basis: {file: " + path.string() + "}, floating_frame: mean_axes}\n");
  std::filesystem::remove(path);
  EXPECT_EQ(se.interface_constraint.rows(), 2);
  return se;
}

}  // namespace femb::test

std::string femb::test::Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at == std::string::npos) return text;
  return text.replace(at, from.size(), to);
}

Eigen::MatrixXd femb::test::StaticTangentByDifferences(const SystemModel& model, const DofMap& dofs,
                                                       const SystemState& state, double lambda, double h) {
  const int n = dofs.n_dofs();
  Eigen::MatrixXd K(n, n);
  for (int i = 0; i < n; ++i) {
    SystemState plus = state, minus = state;
    ApplyIncrement(model, dofs, h * Eigen::VectorXd::Unit(n, i), plus);
    ApplyIncrement(model, dofs, -h * Eigen::VectorXd::Unit(n, i), minus);
    K.col(i) = -(AssembleStatic(model, dofs, plus, lambda, false).residual -
                 AssembleStatic(model, dofs, minus, lambda, false).residual) /
               (2 * h);
  }
  return K;
}

namespace femb::test {

InertiaLoadFactors InertiaLoadsOf(const SuperelementBody& body, BodyData d, const BodyVelocity& w,
                                  const BodyVelocity& wdot, const Eigen::Vector3d& gravity) {
  InertiaLoadFactors out;
  InertiaLoads(body, d, w, wdot, gravity, out);
  return out;
}

Eigen::VectorXd GravityForceOf(const SuperelementBody& body, BodyData d, const Eigen::Vector3d& g) {
  Eigen::VectorXd f;
  GravityForce(body, d, g, f);
  return f;
}

Eigen::MatrixXd InertiaConfigurationTangentOf(const SuperelementBody& body, BodyData d, const BodyVelocity& w,
                                              const BodyVelocity& wdot, bool quadratic) {
  Eigen::MatrixXd tangent;
  InertiaConfigurationTangent(body, d, w, wdot, quadratic, tangent);
  return tangent;
}

BodyVelocityMaps MapsAt(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& frame) {
  BodyData d = Evaluate(body, c, frame);
  return MapsOf(body, d);
}

Eigen::MatrixXd MomentumDerivativeOf(const SuperelementBody& body, const BodyVelocityMaps& maps,
                                     const BodyVelocity& w) {
  Eigen::MatrixXd D;
  BodyScratch scratch;
  MomentumDerivative(body, maps, w, D, scratch);
  return D;
}

Eigen::VectorXd MomentumSourceOf(const SuperelementBody& body, const BodyVelocityMaps& maps, const BodyVelocity& w,
                                 const Eigen::VectorXd& p) {
  Eigen::VectorXd out;
  BodyScratch scratch;
  MomentumSource(body, maps, w, p, out, scratch);
  return out;
}

}  // namespace femb::test
