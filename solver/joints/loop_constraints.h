// Closed loops in the system: the cut joints' constraint equations with Lagrange
// multipliers, assembled into the residual and the iteration matrix, and the same for the
// interface constraints of bodies whose basis moves fewer directions (thesis 8.2 case 4); the rank test that drops
// redundant equations and names a dead point; the loops' violation and reactions. The
// equations of one joint are in solver/joints/loop_closure.h.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "solver/assembly/system_model.h"
#include "solver/joints/joint_tree.h"

namespace femb {

/// The cut joints' constraint equations and the bodies' interface constraints
/// (InterfaceConstraint, solver/body/elastic_force.h) at `state` with its multipliers lambda: the residual's
/// coordinate rows get -G^T lambda and its multiplier rows -g (Newton's S delta = r then asks
/// G dq = -g), the node forces -G_node^T lambda (so AddJointGeometricStiffness adds the tree
/// joints' share of their stiffness). With `tangent`: G in the multipliers' rows, G^T in their
/// columns and d(G^T lambda)/dq through the node Jacobians -- those of the blocks in `blocks`
/// (the midpoint scheme takes them from different configurations). With `jacobian`: G and G^T.
/// With `data` (per body, its data already evaluated at `state`, e.g. by the assembly pass, or
/// null), the bodies' interface constraints take them instead of solving the body's frame and
/// evaluating it again; the step then allocates nothing for them.
enum LoopBlocks { kLoopRows = 1, kLoopColumns = 2, kLoopHessian = 4, kLoopAll = 7 };
using BodyDataAtState = std::vector<BodyData*>;
void AddLoopConstraints(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                        Eigen::VectorXd* residual, Triplets* tangent, NodeForces* node_forces,
                        Triplets* jacobian = nullptr, int blocks = kLoopAll, const BodyDataAtState* data = nullptr,
                        SystemScratch* scratch = nullptr);
/// The largest violation of the kept equations: positions in length units, rotations (dot
/// products) times the model's size L so that both are lengths, and the bodies' interface
/// constraints (lengths); 0 without any. `worst`: the cut joint with it, or cut_joints.size() + b
/// for body b's constraint (-1 without any).
double LoopViolation(const SystemModel& model, const SystemState& state, int* worst = nullptr,
                     const BodyDataAtState* data = nullptr, SystemScratch* scratch = nullptr);
/// Per cut joint, the force and moment (global axes, moment about the child node) that the
/// joint's parent node, or the ground, exerts on its child node through the joint: -G_c^T lambda,
/// G_c the child's columns of the kept equations. Along a dropped (redundant) direction the
/// mechanism's reactions are not unique and this one carries none.
std::vector<Eigen::Matrix<double, 6, 1>> CutJointReactions(const SystemModel& model, const SystemState& state);
/// Newton's test on the loops: no constraints, or LoopViolation <= tolerance times the model's
/// size (ModelSize), the same relative tolerance as the forces'.
bool LoopsClosed(const SystemModel& model, const SystemState& state, double tolerance,
                 const BodyDataAtState* data = nullptr, SystemScratch* scratch = nullptr);

/// Drops the cut joints' equations that repeat others at the initial state (an over-constrained
/// mechanism: a planar four-bar of spatial revolute joints has 3 of its 5 closure equations
/// satisfied by the plane itself). Row by row in order, each equation of the constraint
/// Jacobian on the coordinates solved for (columns scaled to unit size: any units) is kept when
/// it is independent of those kept before it (Gram-Schmidt, relative remainder above 1e-8).
/// Returns per cut joint what its dropped equations held ("" when none). The reactions of a
/// redundant loop are then one of many that balance it (statically indeterminate), as in any
/// multibody code. An equation that the coordinates solved for cannot move but the prescribed ones
/// do (a loop that locks its drive: no coordinate left to follow it) throws InputError naming the
/// cut joint, the equation and the driven nodes: dropped, it would let the loop open.
/// Numbers the model (SystemModel::Number) before and again after.
std::vector<std::string> DropRedundantEquations(SystemModel& model);

/// Closed loops at `state`: the cut joint whose kept equation is nearest to depending on the
/// others (its row of the constraint Jacobian within 0.05, relative, of the span of the rows
/// before it) -- the mechanism at or near a dead point, where Newton fails or the motion runs
/// away -- named with the equation; "" when none (or no loops).
std::string LoopSingularity(const SystemModel& model, const SystemState& state);

}  // namespace femb
