// Rotating clamped cantilever in ONE body (a geometric stiffening study): the first flapwise and in-plane
// frequency about the steadily rotating state, measured from a free vibration, against an
// independent converged 1-D rotating-beam model and Southwell's closed form, with and without
// geometric stiffening, for an interface frame (at the hub) and a centre-of-mass frame. "1 body":
// a file with the stiffening (and so the exact inertia); "no stiff.": without either (the
// thesis' corotational inertia). Then stiffened bases whose shapes stretch the part (more modes,
// modal derivatives; a solid bar too). Prints the tables; no pass/fail (the linearized check is
// tests/solver/analysis/exact_inertia_test.cpp).
// Usage: build/bin/rotating_cantilever_frequency
#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "formats/part_file.h"
#include "reducer/reduce_part.h"
#include "solver/analysis/dynamic_analysis.h"
#include "tests/rotating_beam_reference.h"

namespace femb {
namespace {

// The rotating beam example's tube, 1 m: EI = 189.1 N m^2, rho A = 0.1612 kg/m.
constexpr double kL = 1.0, kE = 70e9, kRho = 2700, kRo = 0.01, kRi = 0.009;
const double kI = M_PI / 4 * (std::pow(kRo, 4) - std::pow(kRi, 4));
const double kA = M_PI * (kRo * kRo - kRi * kRi);

Superelement Reduced(const std::string& yaml) {
  ReduceResult r = ReducePart(ParsePart(yaml, "part.yaml", {}), nullptr);
  if (!r.ok) std::printf("reduction failed: %s\n", r.message.c_str());
  return r.superelement;
}

// `basis`: the reduction's keys before the stiffening and the frame.
Superelement Tube(bool stiffening, const std::string& frame, const std::string& basis = "internal_modes: 4") {
  return Reduced(
      "name: tube\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
      "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
      "beam:\n  theory: euler_bernoulli\n  points: {A: [0, 0, 0], B: [1, 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: 40}]\ninterfaces: [{name: A}, {name: B}]\n"
      "reduction: {" +
      basis + ", geometric_stiffening: " + std::string(stiffening ? "true" : "false") + ", floating_frame: '" + frame +
      "'}\n");
}

// A steel bar 1 m x 20 mm x 20 mm (TET10, 10 mm; RBE2 end faces), stiffened: EI = E a^4 / 12.
constexpr double kBarSide = 0.02, kBarE = 2.1e11, kBarRho = 7850;
Superelement Bar(int modes, const std::string& frame, const std::string& more = "") {
  return Reduced(
      "name: bar\ntype: solid\nunits: SI\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
      "geometry: {shape: box, size: [1.0, 0.02, 0.02]}\nmesh: {size: 0.01, order: 2}\n"
      "interfaces:\n  - {name: A, group: xmin}\n  - {name: B, group: xmax}\n"
      "reduction: {internal_modes: " +
      std::to_string(modes) + more + ", floating_frame: '" + frame + "'}\n");
}

// The converged 1-D rotating-beam model (tests/rotating_beam_reference.h).
double ReferenceOmega2(double Omega, bool in_plane, double EI = kE * kI, double rhoA = kRho * kA) {
  return reference::RotatingBeamOmega2(EI, rhoA, kL, Omega, in_plane);
}

// The first bending frequency of ONE body rotating steadily about z at Omega (hub clamped to a
// revolute joint whose angle is Omega t), from a free vibration started by a small tip velocity
// (z: flapwise, y: in-plane): the peak of the Hann-windowed spectrum of the tip deflection in the
// hub frame over 40 periods (searched within +-35% of the guess on a 0.01% grid);
// generalized-alpha with rho_inf = 0.5 (the start-up axial vibration damped, the bending mode at
// omega h = 0.04 untouched) at 150 steps per period.
double MeasuredOmega(const Superelement& se, double Omega, bool in_plane, double omega_guess,
                     const SuperelementOptions& body_options = {}) {
  SystemModel model;
  AddNode(model, "n0", Eigen::Vector3d::Zero());
  AddNode(model, "n1", Eigen::Vector3d(kL, 0, 0));
  model.bodies.emplace_back(se, body_options, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  model.body_nodes.push_back({0, 1});
  RevoluteToGround(model, 0, Eigen::Vector3d::UnitZ());
  SystemModel::Prescribed p;
  p.node = 0;
  p.value = [Omega](double t) { return Omega * t; };
  p.rate = [Omega](double) { return Omega; };
  p.acceleration = [](double) { return 0.0; };
  model.prescribed.push_back(p);
  model.Number();
  const DofMap& dofs = model.dofs();
  Eigen::VectorXd v0 = Eigen::VectorXd::Zero(dofs.n_dofs());
  v0[dofs.node_first(0)] = Omega;
  const double kick = 1e-3 * omega_guess * kL;  // tip amplitude ~1e-3 L
  v0.segment<3>(dofs.node_first(1)) = Eigen::Vector3d(0, Omega * kL + (in_plane ? kick : 0), in_plane ? 0 : kick);
  v0.segment<3>(dofs.node_first(1) + 3) = Eigen::Vector3d(0, 0, Omega);
  DynamicState s = InitialDynamicState(model, InitialState(model), v0);
  const double period = 2 * M_PI / omega_guess;
  DynamicOptions options;
  options.step = period / 150;
  options.end_time = 40 * period;
  options.rho_inf = 0.5;
  std::vector<double> t, d;
  const DynamicResult result =
      SolveDynamic(model, s, options, [&](const DynamicStepReport& rep, const DynamicState& st) {
        const Eigen::Vector3d rel = st.config.R[0].transpose() * (st.config.x[1] - st.config.x[0]);
        t.push_back(rep.t);
        d.push_back(in_plane ? rel.y() : rel.z());
      });
  if (!result.ok) std::printf("  (run stopped: %s)\n", result.message.c_str());
  if (d.size() < 100) return 0.0;
  double mean = 0.0;
  for (double v : d) mean += v / double(d.size());
  const double T = t.back() - t.front();
  double best = 0.0, best_power = -1.0;
  for (double f = 0.65 * omega_guess; f <= 1.35 * omega_guess; f *= 1.0001) {
    double re = 0.0, im = 0.0;
    for (size_t i = 0; i < d.size(); ++i) {
      const double window = 0.5 - 0.5 * std::cos(2 * M_PI * (t[i] - t.front()) / T);
      re += window * (d[i] - mean) * std::cos(f * t[i]);
      im += window * (d[i] - mean) * std::sin(f * t[i]);
    }
    if (re * re + im * im > best_power) best_power = re * re + im * im, best = f;
  }
  return best;
}

}  // namespace
}  // namespace femb

int main() {
  using namespace femb;
  const double omega0_ref = std::sqrt(ReferenceOmega2(0.0, false));
  std::printf("omega_0 = %.3f rad/s (1-D reference), 3.516 sqrt(EI / m L^4) = %.3f\n", omega0_ref,
              3.5160 * std::sqrt(kE * kI / (kRho * kA * std::pow(kL, 4))));
  std::printf("%-16s %-9s %7s %10s %10s %9s %10s %12s %9s %14s %9s\n", "frame", "motion", "Omega/w0", "reference",
              "Southwell", "1 body", "error", "no stiff.", "error", "no quad. vel.", "error");
  for (const char* frame : {"interface:A", "center_of_mass"}) {
    const Superelement stiff = Tube(true, frame), plain = Tube(false, frame);
    SuperelementOptions no_quadratic;
    no_quadratic.quadratic_velocity_terms = false;
    for (bool in_plane : {false, true}) {
      for (double ratio : {0.0, 0.5, 1.0, 2.0}) {
        const double Omega = ratio * omega0_ref;
        const double reference = std::sqrt(ReferenceOmega2(Omega, in_plane));
        const double southwell = std::sqrt(omega0_ref * omega0_ref + (in_plane ? 0.193 : 1.193) * Omega * Omega);
        const double measured = MeasuredOmega(stiff, Omega, in_plane, reference);
        const double linear = MeasuredOmega(plain, Omega, in_plane, reference);
        const double no_quad = MeasuredOmega(plain, Omega, in_plane, reference, no_quadratic);
        std::printf("%-16s %-9s %7.1f %10.3f %10.3f %9.3f %+9.2f%% %12.3f %+8.2f%% %14.3f %+8.2f%%\n", frame,
                    in_plane ? "in-plane" : "flapwise", ratio, reference, southwell, measured,
                    100 * (measured / reference - 1), linear, 100 * (linear / reference - 1), no_quad,
                    100 * (no_quad / reference - 1));
        std::fflush(stdout);
      }
    }
  }
  std::printf("(+-35.00%%: no spectral peak within +-35%% of the reference)\n");
  // Stiffened bases whose shapes stretch the part (their stress, balanced by body forces, does no
  // work on the interface rotation completion): the tube with 14 internal modes (the 14th its
  // first axial mode) and with the derivatives of every pair of 4 modes; the bar with 4 and 20
  // internal modes, and with the derivatives of its 4 modes' pairs.
  const double bar_EI = kBarE * std::pow(kBarSide, 4) / 12, bar_rhoA = kBarRho * kBarSide * kBarSide;
  std::printf("\n%-34s %-16s %-9s %7s %10s %9s %10s\n", "part, basis (stiffened)", "frame", "motion", "Omega/w0",
              "reference", "1 body", "error");
  for (const char* frame : {"interface:A", "center_of_mass"}) {
    const struct {
      const char* name;
      Superelement se;
      double EI, rhoA;
    } parts[] = {
        {"tube, 14 modes", Tube(true, frame, "internal_modes: 14"), kE * kI, kRho * kA},
        {"tube, 4 modes + derivatives", Tube(true, frame, "internal_modes: 4, modal_derivatives: true"), kE * kI,
         kRho * kA},
        {"bar TET10, 4 modes", Bar(4, frame), bar_EI, bar_rhoA},
        {"bar TET10, 20 modes", Bar(20, frame), bar_EI, bar_rhoA},
        {"bar TET10, 4 modes + derivatives", Bar(4, frame, ", modal_derivatives: {of: internal}"), bar_EI, bar_rhoA}};
    for (const auto& part : parts) {
      const double w0 = std::sqrt(ReferenceOmega2(0.0, false, part.EI, part.rhoA));
      for (bool in_plane : {false, true}) {
        for (double ratio : {1.0, 2.0}) {
          const double reference = std::sqrt(ReferenceOmega2(ratio * w0, in_plane, part.EI, part.rhoA));
          const double measured = MeasuredOmega(part.se, ratio * w0, in_plane, reference);
          std::printf("%-34s %-16s %-9s %7.1f %10.3f %9.3f %+9.2f%%\n", part.name, frame,
                      in_plane ? "in-plane" : "flapwise", ratio, reference, measured, 100 * (measured / reference - 1));
          std::fflush(stdout);
        }
      }
    }
  }
  return 0;
}
