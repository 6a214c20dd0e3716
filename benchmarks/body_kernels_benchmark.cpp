// One body's kernels, timed call by call: the work of a Newton iteration of generalized-alpha on
// one superelement (a tube segment with 2 interface nodes and 2 internal modes, 14 coordinates;
// more modes with an argument), linear and with the geometric stiffening and exact inertia
// (the stiffening's cost ratio), split into the passes femb-solve makes: the body data (Evaluate:
// local coordinates and kinematics), the residual pass (elastic, inertia and gravity forces, the
// inertia load factors) and the matrix pass (tangent, mass and gyroscopic matrices,
// configuration tangent of the inertia force). Prints microseconds per call and heap
// allocations per call measured on this run. The stage rows are differences of cumulative runs
// (best of interleaved rounds): on a shared machine they move by a few microseconds run to run.
// Usage: body_kernels_benchmark [INTERNAL_MODES [REPEATS]]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "benchmarks/allocation_count.h"
#include "formats/part_file.h"
#include "reducer/reduce_part.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace {

struct Timing {
  double us = 0.0;
  double allocations = 0.0;
};

// Every work timed in rounds of `repeats` calls, the works interleaved within a round so that a
// slow spell of the (noisy, shared) machine touches them all; the best of 9 rounds is the cost.
std::vector<Timing> MeasureInterleaved(int repeats, const std::vector<std::function<void()>>& works) {
  std::vector<Timing> best(works.size(), Timing{1e300, 0.0});
  for (int round = 0; round < 9; ++round) {
    for (size_t k = 0; k < works.size(); ++k) {
      const long before = femb_allocations.load();
      const auto start = std::chrono::steady_clock::now();
      for (int i = 0; i < repeats; ++i) works[k]();
      const double us = 1e6 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / repeats;
      if (us < best[k].us) best[k] = {us, double(femb_allocations.load() - before) / repeats};
    }
  }
  return best;
}

// One kind's body and state: a linear file (kind 0); a stiffened file with the stiffening
// switched off (kind 1: body option geometric_stiffening: false, the exact inertia alone); the
// stiffened file as it is (kind 2). A deformed, turned configuration and a spinning,
// accelerating motion. False when the reduction or the frame fails.
struct Setup {
  std::unique_ptr<femb::SuperelementBody> body;
  femb::BodyConfiguration c;
  femb::FrameSolution frame;
  Eigen::VectorXd w, wdot;
};

bool MakeSetup(int kind, int modes, Setup& u) {
  const bool stiffening = kind >= 1;
  const femb::PartSpec part = femb::ParsePart(
      "name: seg\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
      "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
      "beam:\n  points: {A: [0, 0, 0], B: [0.5, 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: 8}]\n"
      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: " +
          std::to_string(modes) +
          ", keep_mesh: false, geometric_stiffening: " + std::string(stiffening ? "true" : "false") + "}\n",
      "bench.yaml");
  const femb::ReduceResult reduced = femb::ReducePart(part, nullptr);
  if (!reduced.ok) return false;
  femb::SuperelementOptions options;
  options.geometric_stiffening = kind == 2;
  u.body = std::make_unique<femb::SuperelementBody>(reduced.superelement, options);
  const femb::SuperelementBody& body = *u.body;
  const int n = body.n_coordinates();
  // A deformed, turned configuration and a spinning, accelerating motion.
  u.c = InitialConfiguration(body);
  const Eigen::Matrix3d turn = femb::ExpSO3(Eigen::Vector3d(0.3, -0.2, 0.5));
  for (size_t k = 0; k < u.c.x.size(); ++k) {
    u.c.x[k] = turn * u.c.x[k] + Eigen::Vector3d(0.01 * double(k), -0.02, 0.005 * double(k));
    u.c.R[k] = femb::ExpSO3(Eigen::Vector3d(0.02 * double(k), 0.01, -0.03 * double(k))) * turn * u.c.R[k];
  }
  for (int i = 0; i < u.c.eta.size(); ++i) u.c.eta[i] = 1e-3 * (i + 1);
  u.frame = SolveFrame(body, u.c, GuessFrame(body, u.c));
  if (!u.frame.ok) return false;
  u.w.resize(n);
  u.wdot.resize(n);
  for (int i = 0; i < n; ++i) {
    u.w[i] = std::sin(1.0 + i);
    u.wdot[i] = 10.0 * std::cos(2.0 + i);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const int modes = argc > 1 ? std::max(0, std::atoi(argv[1])) : 2;
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 2000;
  std::printf(
      "One body's kernels: tube segment, 2 interface nodes, %d internal modes; microseconds per call "
      "(best of 9 interleaved rounds of %d), heap allocations per call\n\n",
      modes, repeats);
  std::printf("%-48s %10s %7s %12s %7s %12s %7s %7s %7s\n", "kernel", "linear us", "allocs", "exact in. us", "allocs",
              "stiffened us", "allocs", "ratio", "ratio");
  std::printf("%-48s %10s %7s %12s %7s %12s %7s %7s %7s\n", "", "", "", "", "", "", "", "st/lin", "st/ex");
  // Each kind's setup (MakeSetup), then its works: names and calls (each call on fresh body data,
  // as an iteration has).
  std::vector<Setup> setups(3);
  const Eigen::Vector3d g(0, -9.81, 0);
  const std::vector<std::string> names = {"floating frame (SolveFrame from the last)",
                                          "body data (Evaluate)",
                                          "  + residual pass (forces, load factors)",
                                          "  + elastic tangent (with d_load)",
                                          "  + mass and gyroscopic matrices",
                                          "  + inertia configuration tangent",
                                          "a Newton iteration (data, residual, matrices)"};
  std::vector<std::function<void()>> works;
  double sink = 0.0;
  for (int kind = 0; kind < 3; ++kind) {
    if (!MakeSetup(kind, modes, setups[size_t(kind)])) return 3;
    const Setup& u = setups[size_t(kind)];
    const Setup* p = &u;
    // Stages of an iteration, cumulative: 0 data, 1 + residual, 2 + elastic tangent,
    // 3 + mass and gyroscopic, 4 + configuration tangent.
    auto iteration = [p, g, &sink](int stages) {
      const femb::SuperelementBody& b = *p->body;
      femb::BodyData d = Evaluate(b, p->c, p->frame);
      if (stages < 1) return;
      const bool s = b.has_inertia_stiffening();
      femb::InertiaLoadFactors load;
      Eigen::VectorXd f_int, f_in, f_acc;
      if (s) InertiaLoads(b, d, p->w, p->wdot, g, load);
      ElasticForce(b, d, &f_int, nullptr, s ? &load : nullptr);
      InertiaForce(b, d, p->w, p->wdot, &f_in, nullptr, nullptr, &f_acc);
      Eigen::VectorXd f_grav;
      GravityForce(b, d, g, f_grav);
      sink += f_int.sum() + f_in.sum() + f_acc.sum() + f_grav.sum();
      if (stages < 2) return;
      Eigen::MatrixXd K, M, C, d_load, K_inertia;
      ElasticForce(b, d, nullptr, &K, s ? &load : nullptr, s ? &d_load : nullptr);
      if (stages < 3) return;
      InertiaForce(b, d, p->w, p->wdot, nullptr, &M, &C);
      if (s) {
        M.noalias() += d_load * load.d_wdot;
        C.noalias() += d_load * load.d_w;
      }
      if (stages < 4) return;
      InertiaConfigurationTangent(b, d, p->w, p->wdot, false, K_inertia);
      K += K_inertia;
      sink += K.sum() + M.sum() + C.sum();
    };
    works.push_back([p] {
      const femb::FrameSolution f = SolveFrame(*p->body, p->c, p->frame);
      if (!f.ok) std::abort();
    });
    for (int stages = 0; stages <= 4; ++stages) works.push_back([iteration, stages] { iteration(stages); });
  }
  const std::vector<Timing> t = MeasureInterleaved(repeats, works);
  // Per kind: frame, then the cumulative stages 0..4; rows are the frame, the data, the
  // increments of stages 1..4 and the whole iteration.
  std::vector<std::pair<std::string, Timing>> rows[3];
  for (int kind = 0; kind < 3; ++kind) {
    const Timing* k = &t[size_t(6 * kind)];
    rows[kind].push_back({names[0], k[0]});
    rows[kind].push_back({names[1], k[1]});
    for (int stage = 1; stage <= 4; ++stage)
      rows[kind].push_back(
          {names[size_t(stage + 1)], {k[stage + 1].us - k[stage].us, k[stage + 1].allocations - k[stage].allocations}});
    rows[kind].push_back({names[6], k[5]});
  }
  if (sink == 12345.678) std::printf(" ");
  for (size_t i = 0; i < rows[0].size(); ++i) {
    const Timing& l = rows[0][i].second;
    const Timing& e = rows[1][i].second;
    const Timing& s = rows[2][i].second;
    std::printf("%-48s %10.2f %7.0f %12.2f %7.0f %12.2f %7.0f %7.2f %7.2f\n", rows[0][i].first.c_str(), l.us,
                l.allocations, e.us, e.allocations, s.us, s.allocations, s.us / l.us, s.us / e.us);
  }
  return 0;
}
