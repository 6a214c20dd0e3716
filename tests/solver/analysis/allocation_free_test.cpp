// No heap allocation inside a time step or a Newton iteration. This program replaces
// malloc, calloc and realloc (benchmarks/allocation_count.h: every operator new and every Eigen
// allocation goes through them) and counts the allocations between the ends of consecutive
// steps of SolveDynamic: the predictor, every Newton iteration (residual, iteration matrix,
// factorization, solve, increment), the convergence test, the step's bookkeeping and the energy
// and momentum it reports. The first steps may allocate (the workspaces grow to their sizes and
// the sparse pattern is analysed); from the third on, none may.
// Covered: generalized-alpha with fixed steps; bodies from linear files (the corotational
// inertia) and from stiffened files (geometric stiffening, exact inertia); free, clamped,
// revolute-to-ground (driven) and prismatic-to-ground nodes; revolute joints between nodes;
// gravity and a dead load; bodies on one thread and on two; fixed and error-controlled steps;
// the bodies' inertia matrices kept in their frames (body_matrices_every)
// (but the restart at a breakpoint of a load or drive); the same for the midpoint scheme but
// the kept matrices; spring-dampers, a follower load, a closed loop (cut joint), bodies with
// interface constraints. Not covered (it may still allocate): results recording (femb-solve's
// output, outside SolveDynamic).
// FEMB_ALLOCATION_TRACE=1 prints the call stack of every allocation counted (to find them);
// =linear, =stiffened, =threads, =adaptive, =kept, =midpoint, =springs, =loop or =constrained: of those cases only.
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

[[maybe_unused]] Superelement Tube(double L, bool stiffened) { return test::TubeSegment(L, 2, stiffened); }

// A chain of 4 bodies clamped at one end, hanging under gravity with a dead load at its tip.
[[maybe_unused]] SystemModel Chain(const Superelement& se, double L) {
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
  model.Number();
  return model;
}

// The chain closed into a loop through the ground: its tip joined to a clamped node by a cut
// revolute joint (5 constraint equations, multipliers among the unknowns).
[[maybe_unused]] SystemModel PinnedChain(const Superelement& se, double L) {
  SystemModel model = Chain(se, L);
  const int pin = AddNode(model, "pin", Eigen::Vector3d(4 * L, 0, 0));
  Clamp(model, pin);
  CutJoint cut;
  cut.joint = MakeNodeJoint(JointType::kRevolute, 4, pin, Eigen::Vector3d::UnitZ(), model.node_x0[size_t(pin)],
                            model.node_R0[size_t(pin)], model.node_x0[4], model.node_R0[4]);
  cut.name = "pin";
  for (int i = 0; i < ConstraintCount(JointType::kRevolute); ++i) cut.equations.push_back(i);
  model.cut_joints.push_back(cut);
  model.Number();
  return model;
}

// Two rods on bending shapes alone (interface constraints with multipliers) hanging as a
// pendulum: revolute to ground at n0, n2 hinged to n1, gravity -y.
[[maybe_unused]] SystemModel ConstrainedPendulum(const Superelement& se, double L) {
  SystemModel model;
  AddNode(model, "n0", Eigen::Vector3d::Zero());
  AddNode(model, "n1", Eigen::Vector3d(L, 0, 0));
  AddNode(model, "n2", Eigen::Vector3d(L, 0, 0));
  AddNode(model, "n3", Eigen::Vector3d(2 * L, 0, 0));
  for (int b = 0; b < 2; ++b) {
    model.bodies.emplace_back(se, SuperelementOptions{}, Eigen::Matrix3d::Identity(), Eigen::Vector3d(b * L, 0, 0));
    model.body_nodes.push_back({2 * b, 2 * b + 1});
  }
  RevoluteToGround(model, 0, Eigen::Vector3d::UnitZ());
  model.joints.push_back(MakeNodeJoint(JointType::kRevolute, 2, 1, Eigen::Vector3d::UnitZ(), model.node_x0[1],
                                       model.node_R0[1], model.node_x0[2], model.node_R0[2]));
  model.gravity = Eigen::Vector3d(0, -9.81, 0);
  model.Number();
  return model;
}

// The chain with a spring-damper from its tip to a point above it and one between two of its
// nodes, its tip load a follower load (turning with the node).
[[maybe_unused]] SystemModel SprungChain(const Superelement& se, double L) {
  SystemModel model = Chain(se, L);
  model.loads[0].follower = true;
  SpringDamper to_ground;
  to_ground.node_a = 4;
  to_ground.ground = Eigen::Vector3d(4 * L, 0.5, 0);
  to_ground.stiffness = 200.0;
  to_ground.damping = 2.0;
  to_ground.free_length = 0.4;
  model.springs.push_back(to_ground);
  SpringDamper between;
  between.node_a = 1;
  between.node_b = 3;
  between.stiffness = 50.0;
  between.damping = 0.5;
  between.free_length = 2 * L;
  model.springs.push_back(between);
  return model;
}

// The allocations of each step of a 30-step run after the first `warmup` steps: their largest
// number.
[[maybe_unused]] long LargestAllocationsPerStep(const SystemModel& model, double h, const char* kind, long* steps,
                                                int threads = 1, bool adaptive = false, int body_matrices_every = 1,
                                                Integrator integrator = Integrator::kGeneralizedAlpha, int warmup = 2) {
  DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(DofMap(model).n_dofs()));
  DynamicOptions options;
  options.step = h;
  options.end_time = 30 * h;
  options.rho_inf = 0.8;
  options.threads = threads;
  options.adaptive = adaptive;  // from h, at the default step_tolerance
  options.body_matrices_every = body_matrices_every;
  options.integrator = integrator;
  long last = 0, largest = 0, counted = 0;
  int step = 0;
  const char* trace_kind = std::getenv("FEMB_ALLOCATION_TRACE");
  const bool trace = trace_kind && (std::string(trace_kind) == "1" || std::string(trace_kind) == kind);
  if (trace) femb_on_allocation = PrintStack;
  const DynamicResult r = SolveDynamic(model, s, options, [&](const DynamicStepReport&, const DynamicState&) {
    const long now = femb_allocations.load();
    if (++step > warmup) {
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
    const long crank = LargestAllocationsPerStep(test::SliderCrankModel(Tube(0.15, stiffened), se, 0.15, L), 1e-5,
                                                 stiffened ? "stiffened" : "linear", &steps);
    std::printf("[ info ] %s slider-crank: at most %ld allocations in a step (%ld steps counted)\n",
                stiffened ? "stiffened" : "linear", crank, steps);
    EXPECT_EQ(crank, 0);
  }
  // Bodies on two threads (BodyThreads): a pass allocates nothing either, on any thread.
  const Superelement se = Tube(0.25, true);
  long steps = 0;
  const long two = LargestAllocationsPerStep(Chain(se, 0.25), 1e-3, "threads", &steps, 2);
  std::printf("[ info ] stiffened chain on 2 threads: at most %ld allocations in a step (%ld steps counted)\n", two,
              steps);
  EXPECT_EQ(two, 0);
  // Error-controlled steps (analysis.step: auto): the error estimate and the step's choice.
  const long adaptive = LargestAllocationsPerStep(test::SliderCrankModel(Tube(0.15, true), se, 0.15, 0.25), 1e-5,
                                                  "adaptive", &steps, 1, true);
  std::printf("[ info ] stiffened slider-crank, step: auto: at most %ld allocations in a step (%ld steps counted)\n",
              adaptive, steps);
  EXPECT_EQ(adaptive, 0);
  // The bodies' inertia matrices kept in their frames and turned (body_matrices_every).
  const long kept = LargestAllocationsPerStep(test::SliderCrankModel(Tube(0.15, true), se, 0.15, 0.25), 1e-5, "kept",
                                              &steps, 1, false, 4);
  std::printf(
      "[ info ] stiffened slider-crank, body_matrices_every 4: at most %ld allocations in a step (%ld steps counted)\n",
      kept, steps);
  EXPECT_EQ(kept, 0);
  // Spring-dampers (their forces, matrices and energy) and a follower load.
  const long sprung = LargestAllocationsPerStep(SprungChain(se, 0.25), 1e-3, "springs", &steps);
  std::printf(
      "[ info ] stiffened chain with 2 spring-dampers and a follower load: at most %ld allocations in a step (%ld "
      "steps counted)\n",
      sprung, steps);
  EXPECT_EQ(sprung, 0);
  // A closed loop (cut joint): its equations, forces and matrix blocks.
  const long loop = LargestAllocationsPerStep(PinnedChain(se, 0.25), 1e-3, "loop", &steps);
  std::printf("[ info ] stiffened chain closed by a cut joint: at most %ld allocations in a step (%ld steps counted)\n",
              loop, steps);
  EXPECT_EQ(loop, 0);
  // Bodies with interface constraints (their multipliers; the bodies' data of the pass reused).
  const long constrained =
      LargestAllocationsPerStep(ConstrainedPendulum(test::BendingShapesRod(0.5), 0.5), 1e-3, "constrained", &steps);
  std::printf(
      "[ info ] pendulum of 2 interface-constrained rods: at most %ld allocations in a step (%ld steps counted)\n",
      constrained, steps);
  EXPECT_EQ(constrained, 0);
}

TEST(AllocationFree, RadauStepsAllocateNothing) {
  // The Radau IIA step: the stages' kinematics and states, their residuals and matrices, the
  // iteration matrix over the stages (dense here), its factor and solve, the predictor.
  const Superelement se = Tube(0.25, true);
  long steps = 0;
  const long crank = LargestAllocationsPerStep(test::SliderCrankModel(Tube(0.15, true), se, 0.15, 0.25), 1e-4, "radau",
                                               &steps, 1, false, 1, Integrator::kRadau);
  std::printf("[ info ] Radau IIA, stiffened slider-crank: at most %ld allocations in a step (%ld steps counted)\n",
              crank, steps);
  EXPECT_EQ(crank, 0);
  const long chain = LargestAllocationsPerStep(Chain(se, 0.25), 1e-3, "radau", &steps, 1, false, 1, Integrator::kRadau);
  std::printf(
      "[ info ] Radau IIA, stiffened chain of 4 bodies: at most %ld allocations in a step (%ld steps counted)\n", chain,
      steps);
  EXPECT_EQ(chain, 0);
  // The loop's stage matrices leave out their exact zeros; their pattern is complete from the
  // third step on here (measured: 336 triplets of K in the first two steps' stages, 664 from the
  // third), one step later than generalized-alpha's, so the count starts after it.
  const long loop =
      LargestAllocationsPerStep(PinnedChain(se, 0.25), 1e-3, "radau", &steps, 1, false, 1, Integrator::kRadau, 3);
  std::printf(
      "[ info ] Radau IIA, stiffened chain closed by a cut joint: at most %ld allocations in a step (%ld steps "
      "counted)\n",
      loop, steps);
  EXPECT_EQ(loop, 0);
}

TEST(AllocationFree, MidpointStepsAllocateNothing) {
  // The momentum-conserving midpoint scheme: its kinematics (the column maps T and V), the
  // momentum terms at both ends and at the mid configuration, the discrete gradients of the
  // joints and of gravity, the iteration matrix K T + (C + M V) / h from triplets, and the step's
  // measures from the end state's data. The chain's nodes but the clamped one are free (the
  // split momentum source); the slider-crank's hang on joints (the mean source, the discrete
  // gradient of the node Jacobians).
  for (const bool stiffened : {false, true}) {
    const double L = 0.25;
    const Superelement se = Tube(L, stiffened);
    long steps = 0;
    const long chain =
        LargestAllocationsPerStep(Chain(se, L), 1e-3, "midpoint", &steps, 1, false, 1, Integrator::kMidpoint);
    std::printf("[ info ] midpoint, %s chain of 4 bodies: at most %ld allocations in a step (%ld steps counted)\n",
                stiffened ? "stiffened" : "linear", chain, steps);
    EXPECT_EQ(chain, 0);
    const long crank = LargestAllocationsPerStep(test::SliderCrankModel(Tube(0.15, stiffened), se, 0.15, L), 1e-5,
                                                 "midpoint", &steps, 1, false, 1, Integrator::kMidpoint);
    std::printf("[ info ] midpoint, %s slider-crank: at most %ld allocations in a step (%ld steps counted)\n",
                stiffened ? "stiffened" : "linear", crank, steps);
    EXPECT_EQ(crank, 0);
  }
  const Superelement se = Tube(0.25, true);
  long steps = 0;
  const long two =
      LargestAllocationsPerStep(Chain(se, 0.25), 1e-3, "midpoint", &steps, 2, false, 1, Integrator::kMidpoint);
  std::printf(
      "[ info ] midpoint, stiffened chain on 2 threads: at most %ld allocations in a step (%ld steps counted)\n", two,
      steps);
  EXPECT_EQ(two, 0);
  const long adaptive = LargestAllocationsPerStep(test::SliderCrankModel(Tube(0.15, true), se, 0.15, 0.25), 1e-5,
                                                  "midpoint", &steps, 1, true, 1, Integrator::kMidpoint);
  std::printf(
      "[ info ] midpoint, stiffened slider-crank, step: auto: at most %ld allocations in a step (%ld steps counted)\n",
      adaptive, steps);
  EXPECT_EQ(adaptive, 0);
  const long sprung =
      LargestAllocationsPerStep(SprungChain(se, 0.25), 1e-3, "springs", &steps, 1, false, 1, Integrator::kMidpoint);
  std::printf(
      "[ info ] midpoint, stiffened chain with 2 spring-dampers and a follower load: at most %ld allocations in a step "
      "(%ld steps counted)\n",
      sprung, steps);
  EXPECT_EQ(sprung, 0);
  const long loop =
      LargestAllocationsPerStep(PinnedChain(se, 0.25), 1e-3, "loop", &steps, 1, false, 1, Integrator::kMidpoint);
  std::printf(
      "[ info ] midpoint, stiffened chain closed by a cut joint: at most %ld allocations in a step (%ld steps "
      "counted)\n",
      loop, steps);
  EXPECT_EQ(loop, 0);
  const long constrained = LargestAllocationsPerStep(ConstrainedPendulum(test::BendingShapesRod(0.5), 0.5), 1e-3,
                                                     "constrained", &steps, 1, false, 1, Integrator::kMidpoint);
  std::printf(
      "[ info ] midpoint, pendulum of 2 interface-constrained rods: at most %ld allocations in a step (%ld steps "
      "counted)\n",
      constrained, steps);
  EXPECT_EQ(constrained, 0);
}
#endif

}  // namespace
}  // namespace femb
