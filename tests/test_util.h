// Helpers shared by the tests: parts built from text, reduced in memory.
#pragma once

#include <Eigen/Core>
#include <string>

#include "formats/input_error.h"
#include "formats/part_file.h"
#include "formats/superelement.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/assembly/system.h"

namespace femb::test {

/// The message of the InputError that f() throws ("" when it throws none).
template <class F>
std::string ErrorOf(const F& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// x with 17 significant digits (round-trips through YAML).
std::string Number(double x);

/// A straight beam part along x from 0 to L with interfaces at the named ends ("A" at x = 0,
/// "B" at x = L), `extra` appended to the YAML (e.g. a reduction block).
std::string StraightBeamYaml(double L, int elements, const std::string& section, const std::string& material,
                             const std::string& interfaces, const std::string& extra = "");

/// Elastica of a clamped inextensible Euler-Bernoulli cantilever (bending stiffness EI, length
/// L) under a tip force P that stays perpendicular to the undeformed axis, by shooting with RK4
/// (4000 steps) on the tip angle: the tip's (horizontal shortening, deflection).
Eigen::Vector2d ElasticaTip(double P, double EI, double L);

/// One body on nodes n0 at the origin (clamped) and n1 at (L, 0, 0), default options, a dead
/// force on n1.
SystemModel ClampedOneBodyModel(const Superelement& se, double L, const Eigen::Vector3d& tip_force);

/// An aluminium tube segment (outer radius 10 mm, wall 1 mm) of length L along x in `elements`
/// beam elements, interfaces A and B at its ends, 2 internal modes, with or without geometric
/// stiffening (and with it the exact inertia), reduced in memory.
Superelement TubeSegment(double L, int elements, bool stiffened);

/// A rod of length L along x (20 beam elements, d = 20 mm, E = 2e9 Pa, rho = 7800, interfaces A
/// and B at its ends) reduced on its four lowest free-free bending shapes (two per plane) through
/// femb-reduce's general basis from a Matrix Market file on the beam's DOFs: it cannot stretch or
/// twist, and carries the interface constraint C q_int = 0 (2 rows; thesis 8.2 case 4).
Superelement BendingShapesRod(double L);

/// A slider-crank: crank O-A of length Lc (body `crank`, default options) driven at 150 rad/s
/// about z (revolute to ground, prescribed), a rod of two bodies `rod` of length Lr each hinged to
/// A (node rod_a) and to the slider node (rod_b), which slides along x (prismatic to ground);
/// nodes O, A, rod_a, rod_mid, rod_b, slider (indices 0-5); gravity -9.81 along y. `options`:
/// the rod bodies'.
SystemModel SliderCrankModel(const Superelement& crank, const Superelement& rod, double Lc, double Lr,
                             const SuperelementOptions& options = SuperelementOptions{});

/// The state after `steps` fixed steps of h from `s` under `integrator` (Newton tolerance
/// `tolerance`, one thread); fails the calling test when the run stops.
DynamicState AdvanceSteps(const SystemModel& model, DynamicState s, Integrator integrator, double h, int steps,
                          double tolerance);

/// -d(residual)/d(unknowns) of AssembleStatic at `state` (load factor `lambda`) by central
/// differences with steps h along each unknown (ApplyIncrement): the reference for static
/// tangents.
Eigen::MatrixXd StaticTangentByDifferences(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                                           double lambda, double h = 1e-6);

/// `text` with its first `from` replaced by `to`; fails the calling test when `from` is missing.
std::string Replace(std::string text, const std::string& from, const std::string& to);

/// A temporary as an lvalue until the end of the full expression: a body's kernels write their
/// scratch into the data they are given, so `ElasticForce(body, test::Lvalue(Evaluate(body, c,
/// frame)), ...)` evaluates the body for one call.
template <class T>
T& Lvalue(T&& value) {
  return value;
}

/// A body's kernels as values, for tests that compare them in expressions (the product has the
/// in-place forms only; these call them with their own copy of the data).
InertiaLoadFactors InertiaLoadsOf(const SuperelementBody& body, BodyData d, const BodyVelocity& w,
                                  const BodyVelocity& wdot, const Eigen::Vector3d& gravity);
Eigen::VectorXd GravityForceOf(const SuperelementBody& body, BodyData d, const Eigen::Vector3d& g);
Eigen::MatrixXd InertiaConfigurationTangentOf(const SuperelementBody& body, BodyData d, const BodyVelocity& w,
                                              const BodyVelocity& wdot, bool quadratic);
/// The corotational velocity maps at (c, frame) (MapsOf).
BodyVelocityMaps MapsAt(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& frame);
Eigen::MatrixXd MomentumDerivativeOf(const SuperelementBody& body, const BodyVelocityMaps& maps, const BodyVelocity& w);
Eigen::VectorXd MomentumSourceOf(const SuperelementBody& body, const BodyVelocityMaps& maps, const BodyVelocity& w,
                                 const Eigen::VectorXd& p);

/// Parses and reduces; fails the calling test on error.
Superelement Reduce(const std::string& yaml, const std::vector<std::string>& overrides = {});

/// Expects `fn` to throw femb::InputError whose message contains every one of `parts`.
template <typename Fn>
std::string ThrownMessage(Fn fn);

}  // namespace femb::test

#include "formats/input_error.h"

template <typename Fn>
std::string femb::test::ThrownMessage(Fn fn) {
  try {
    fn();
  } catch (const femb::InputError& e) {
    return e.what();
  }
  return "(no InputError thrown)";
}
