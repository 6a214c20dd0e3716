// Issue 14: no heap allocation inside a time step or a Newton iteration. This program replaces
// malloc, calloc and realloc (benchmarks/allocation_count.h: every operator new and every Eigen
// allocation goes through them) and counts the allocations between the ends of consecutive
// steps of SolveDynamic: the predictor, every Newton iteration (residual, iteration matrix,
// factorization, solve, increment), the convergence test, the step's bookkeeping and the energy
// and momentum it reports. The first steps may allocate (the workspaces grow to their sizes and
// the sparse pattern is analysed); from the third on, none may.
// Covered: generalized-alpha with fixed steps; bodies from linear files (the corotational
// inertia) and from stiffened files (geometric stiffening, exact inertia); free, clamped,
// revolute-to-ground (driven) and prismatic-to-ground nodes; revolute joints between nodes;
// gravity and a dead load; bodies on one thread and on two; fixed and error-controlled steps
// (but the restart at a breakpoint of a load or drive). Not covered (they may still allocate):
// the midpoint scheme, closed loops and interface constraints, spring-dampers, follower
// loads, results recording (femb-solve's output, outside SolveDynamic).
// FEMB_ALLOCATION_TRACE=1 prints the call stack of every allocation counted (to find them);
// =linear, =stiffened, =threads or =adaptive: of those cases only.
#include <execinfo.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "benchmarks/allocation_count.h"
#include "solver/analysis/dynamic_analysis.h"
#include "test_util.h"

namespace femb {
namespace {

bool armed = false;

void PrintStack() {
  if (!armed) return;
  void* frames[24];
  const int n = backtrace(frames, 24);
  const char line[] = "---- allocation inside a step:\n";
  if (write(2, line, sizeof line - 1) < 0) return;
  backtrace_symbols_fd(frames, n, 2);
}

Superelement Tube(double L, bool stiffened) {
  return test::Reduce("name: seg\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
                      "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
                      "beam:\n  points: {A: [0, 0, 0], B: [" + std::to_string(L) + ", 0, 0]}\n"
                      "  segments: [{from: A, to: B, elements: 2}]\n"
                      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: 2, keep_mesh: false, "
                      "geometric_stiffening: " + std::string(stiffened ? "true" : "false") + "}\n");
}

// A chain of 4 bodies clamped at one end, hanging under gravity with a dead load at its tip.
SystemModel Chain(const Superelement& se, double L) {
  SystemModel model;
  for (int i = 0; i <= 4; ++i) AddNode(model, "n" + std::to_string(i), Eigen::Vector3d(i * L, 0, 0));
  Clamp(model, 0);
  for (int i = 0; i < 4; ++i) {
    model.bodies.emplace_back(se, SuperelementOptions{}, Eigen::Matrix3d::Identity(), Eigen::Vector3d(i * L, 0, 0));
    model.body_nodes.push_back({i, i + 1});
  }
  model.gravity = Eigen::Vector3d(0, -9.81, 0);
  NodeLoad tip;
  tip.node = 4;
  tip.force = Eigen::Vector3d(0, 0, 5.0);
  tip.scale = [](double) { return 1.0; };
  model.loads.push_back(tip);
  return model;
}

// A slider-crank: crank O-A driven at 150 rad/s about z (revolute to ground), a rod of two
// bodies hinged to A and to the slider node, which slides along x (prismatic to ground).
SystemModel SliderCrank(const Superelement& crank, const Superelement& rod, double Lc, double Lr) {
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
    model.bodies.emplace_back(rod, SuperelementOptions{}, Eigen::Matrix3d::Identity(),
                              Eigen::Vector3d(Lc + i * Lr, 0, 0));
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
  return model;
}

// The allocations of each step of a 30-step run from the third step on: their largest number.
long LargestAllocationsPerStep(const SystemModel& model, double h, const char* kind, long* steps, int threads = 1,
                               bool adaptive = false) {
  DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(DofMap(model).n_dofs()));
  DynamicOptions options;
  options.step = h;
  options.end_time = 30 * h;
  options.rho_inf = 0.8;
  options.threads = threads;
  options.adaptive = adaptive;  // from h, at the default step_tolerance
  long last = 0, largest = 0, counted = 0;
  int step = 0;
  const char* trace_kind = std::getenv("FEMB_ALLOCATION_TRACE");
  const bool trace = trace_kind && (std::string(trace_kind) == "1" || std::string(trace_kind) == kind);
  if (trace) femb_on_allocation = PrintStack;
  const DynamicResult r = SolveDynamic(model, s, options, [&](const DynamicStepReport&, const DynamicState&) {
    const long now = femb_allocations.load();
    if (++step > 2) {
      largest = std::max(largest, now - last);
      ++counted;
    }
    armed = trace && step >= 2;
    last = femb_allocations.load();
  });
  armed = false;
  femb_on_allocation = nullptr;
  EXPECT_TRUE(r.ok) << r.message;
  *steps = counted;
  return largest;
}

#ifndef FEMB_NO_MALLOC_COUNT
TEST(AllocationFree, GeneralizedAlphaStepsAllocateNothing) {
  // The counter must see an allocation at all, or a zero below would prove nothing.
  const long before = femb_allocations.load();
  Eigen::VectorXd probe(std::getenv("FEMB_NO_SUCH_VARIABLE") ? 3 : 4);  // a size the compiler cannot know
  probe.setZero();
  ASSERT_GT(femb_allocations.load(), before);
  for (const bool stiffened : {false, true}) {
    const double L = 0.25;
    const Superelement se = Tube(L, stiffened);
    long steps = 0;
    const long chain = LargestAllocationsPerStep(Chain(se, L), 1e-3, stiffened ? "stiffened" : "linear", &steps);
    std::printf("[ info ] %s chain of 4 bodies: at most %ld allocations in a step (%ld steps counted)\n",
                stiffened ? "stiffened" : "linear", chain, steps);
    EXPECT_EQ(chain, 0);
    const long crank = LargestAllocationsPerStep(SliderCrank(Tube(0.15, stiffened), se, 0.15, L), 1e-5,
                                                 stiffened ? "stiffened" : "linear", &steps);
    std::printf("[ info ] %s slider-crank: at most %ld allocations in a step (%ld steps counted)\n",
                stiffened ? "stiffened" : "linear", crank, steps);
    EXPECT_EQ(crank, 0);
  }
  // Bodies on two threads (BodyThreads): a pass allocates nothing either, on any thread.
  const Superelement se = Tube(0.25, true);
  long steps = 0;
  const long two = LargestAllocationsPerStep(Chain(se, 0.25), 1e-3, "threads", &steps, 2);
  std::printf("[ info ] stiffened chain on 2 threads: at most %ld allocations in a step (%ld steps counted)\n", two, steps);
  EXPECT_EQ(two, 0);
  // Error-controlled steps (analysis.step: auto): the error estimate and the step's choice.
  const long adaptive =
      LargestAllocationsPerStep(SliderCrank(Tube(0.15, true), se, 0.15, 0.25), 1e-5, "adaptive", &steps, 1, true);
  std::printf("[ info ] stiffened slider-crank, step: auto: at most %ld allocations in a step (%ld steps counted)\n",
              adaptive, steps);
  EXPECT_EQ(adaptive, 0);
}
#endif

}  // namespace
}  // namespace femb
