// The cut joints' constraint equations in the system: their assembly into the
// residual and the iteration matrix, the rank test that drops redundant equations and names a
// dead point, and the loops' violation and reactions. The equations of one joint are in
// solver/joints/loop_closure.h.
#include "solver/joints/loop_constraints.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "formats/input_error.h"
#include "solver/assembly/system.h"

namespace femb {

namespace {

// Body b's data at `state`, its floating frame solved from the last one; none when the frame
// does not converge (the body's own assembly reports that).
std::optional<BodyData> BodyDataAt(const SystemModel& model, const SystemState& state, int b) {
  const SuperelementBody& body = model.bodies[size_t(b)];
  const BodyConfiguration c = BodyConfigurationOf(model, state, b);
  const FrameSolution frame = SolveFrameFrom(body, c, state.frames[size_t(b)]);
  if (!frame.ok) return std::nullopt;
  return Evaluate(body, c, frame);
}

// Body b's data at `state`: the given one, or evaluated into `own`; null when its frame does not
// converge.
BodyData* BodyDataFor(const SystemModel& model, const SystemState& state, int b, const BodyDataAtState* data,
                      std::optional<BodyData>& own) {
  if (data && size_t(b) < data->size() && (*data)[size_t(b)]) return (*data)[size_t(b)];
  own = BodyDataAt(model, state, b);
  return own ? &*own : nullptr;
}

// The bodies' interface constraints (thesis 8.2 case 4): g = C q_int of each constrained body,
// its Jacobian G through the body's map (BodyMap: node Jacobians, modal coordinates) and
// d(G^T lambda)/dq, in the same blocks as the cut joints'.
void AddBodyConstraints(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                        Eigen::VectorXd* residual, Triplets* tangent, NodeForces* node_forces, Triplets* jacobian,
                        int blocks, const BodyDataAtState* data, SystemScratch* scratch) {
  // (With `data` and `scratch`, a time step allocates nothing here.)
  SystemScratch own;
  SystemScratch& s = scratch ? *scratch : own;
  Eigen::VectorXd &lambda = s.lambda, &g = s.g, &minus_f = s.minus_f;
  Eigen::MatrixXd &G = s.G, &H = s.H;
  std::vector<MapEntry>& map = s.map;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const SuperelementBody& body = model.bodies[b];
    const int r = body.n_constraints();
    if (r == 0) continue;
    std::optional<BodyData> evaluated;
    BodyData* d = BodyDataFor(model, state, int(b), data, evaluated);
    if (!d) continue;
    const int first = dofs.body_multiplier_first(int(b));
    lambda = state.lambda.segment(first - dofs.first_multiplier(), r);
    const bool hessian = tangent && (blocks & kLoopHessian) && !lambda.isZero(0.0);
    InterfaceConstraint(body, *d, &g, &G, hessian ? &lambda : nullptr, hessian ? &H : nullptr);
    minus_f.resize(body.n_coordinates());
    minus_f.noalias() = -G.transpose() * lambda;  // -G^T lambda on the body's coordinates
    if (node_forces) AddBodyNodeForces(model, int(b), minus_f, *node_forces);
    BodyMap(model, dofs, state, int(b), map);
    if (residual) {
      ScatterBody(map, &minus_f, nullptr, residual, nullptr);
      residual->segment(first, r) -= g;
    }
    for (Triplets* t : {tangent, jacobian}) {
      if (!t) continue;
      const bool rows = t == jacobian || (blocks & kLoopRows), columns = t == jacobian || (blocks & kLoopColumns);
      for (const MapEntry& e : map) {
        for (int i = 0; i < r; ++i) {
          const double v = e.coefficient * G(i, e.local);
          if (v == 0.0) continue;
          if (rows) t->emplace_back(first + i, e.coordinate, v);
          if (columns) t->emplace_back(e.coordinate, first + i, v);
        }
      }
    }
    if (hessian) ScatterBody(map, nullptr, &H, nullptr, tangent);
  }
}

}  // namespace

void AddLoopConstraints(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                        Eigen::VectorXd* residual, Triplets* tangent, NodeForces* node_forces, Triplets* jacobian,
                        int blocks, const BodyDataAtState* data, SystemScratch* scratch) {
  for (size_t c = 0; c < model.cut_joints.size(); ++c) {
    const CutJoint& cut = model.cut_joints[c];
    const NodeJoint& j = cut.joint;
    const int nodes[2] = {j.parent, j.child};
    const ConstraintBlock block =
        EvaluateConstraint(j, state.x[nodes[0]], state.R[nodes[0]], state.x[nodes[1]], state.R[nodes[1]]);
    const int first = dofs.multiplier_first(int(c)), m = int(cut.equations.size());
    ConstraintValues l_full = ConstraintValues::Zero(block.g.size());  // dropped equations: none
    for (int i = 0; i < m; ++i) l_full[cut.equations[size_t(i)]] = state.lambda[first - dofs.first_multiplier() + i];
    const Eigen::Matrix<double, 12, 1> f = block.G.transpose() * l_full;  // G^T lambda on (parent, child)
    for (int e = 0; e < 2; ++e) {
      const Eigen::Matrix<double, 6, 1> f_e = f.segment<6>(6 * e);
      if (node_forces) node_forces->Add(nodes[e], -f_e);
      if (residual) {
        for (const auto& [col, vec] : state.J[nodes[e]]) (*residual)[col] -= vec.dot(f_e);
      }
    }
    for (int i = 0; i < m; ++i) {
      const int eq = cut.equations[size_t(i)];
      if (residual) (*residual)[first + i] -= block.g[eq];
      for (Triplets* t : {tangent, jacobian}) {
        if (!t) continue;
        const bool rows = t == jacobian || (blocks & kLoopRows), columns = t == jacobian || (blocks & kLoopColumns);
        for (int e = 0; e < 2; ++e) {
          for (const auto& [col, vec] : state.J[nodes[e]]) {
            const double v = (block.G.block<1, 6>(eq, 6 * e) * vec)(0);
            if (v == 0.0) continue;
            if (rows) t->emplace_back(first + i, col, v);
            if (columns) t->emplace_back(col, first + i, v);
          }
        }
      }
    }
    if (!tangent || !(blocks & kLoopHessian) || l_full.isZero(0.0)) continue;
    // d(G^T lambda)/dq through the node Jacobians (their own derivative: the node forces above).
    const Eigen::Matrix<double, 12, 12> H =
        ConstraintHessian(j, state.x[nodes[0]], state.R[nodes[0]], state.x[nodes[1]], state.R[nodes[1]], l_full);
    for (int a = 0; a < 2; ++a) {
      for (int b = 0; b < 2; ++b) {
        const Eigen::Matrix<double, 6, 6> H_ab = H.block<6, 6>(6 * a, 6 * b);
        if (H_ab.isZero(0.0)) continue;
        for (const auto& [ci, vi] : state.J[nodes[a]]) {
          const Eigen::Matrix<double, 1, 6> row = vi.transpose() * H_ab;
          for (const auto& [cj, vj] : state.J[nodes[b]]) {
            const double v = (row * vj)(0);
            if (v != 0.0) tangent->emplace_back(ci, cj, v);
          }
        }
      }
    }
  }
  AddBodyConstraints(model, dofs, state, residual, tangent, node_forces, jacobian, blocks, data, scratch);
}

namespace {

// The rows of the cut joints' kept equations in the constraint Jacobian, over the coordinates
// solved for (`solved`) and, when `prescribed` is given, over the prescribed ones, each column
// scaled to unit size so that units do not matter; one assembly of the equations for both.
void ConstraintRows(const SystemModel& model, const DofMap& dofs, const SystemState& state, Eigen::MatrixXd& solved,
                    Eigen::MatrixXd* prescribed = nullptr) {
  Triplets entries;
  AddLoopConstraints(model, dofs, state, nullptr, nullptr, nullptr, &entries);
  const int m = dofs.n_multipliers(), first = dofs.first_multiplier();
  std::vector<int> column(size_t(dofs.n_dofs()), -1);
  int n_s = 0, n_p = 0;
  for (int j = 0; j < first; ++j) column[size_t(j)] = dofs.prescribed(j) ? n_p++ : n_s++;
  solved = Eigen::MatrixXd::Zero(m, n_s);
  if (prescribed) *prescribed = Eigen::MatrixXd::Zero(m, n_p);
  for (const Eigen::Triplet<double>& e : entries) {
    if (e.row() < first || e.col() >= first) continue;
    Eigen::MatrixXd* G = dofs.prescribed(e.col()) ? prescribed : &solved;
    if (G) (*G)(e.row() - first, column[size_t(e.col())]) += e.value();
  }
  for (Eigen::MatrixXd* G : {&solved, prescribed}) {
    if (!G) continue;
    for (Eigen::Index c = 0; c < G->cols(); ++c) {
      const double size = G->col(c).cwiseAbs().maxCoeff();
      if (size > 0) G->col(c) /= size;
    }
  }
}

// Per kept equation of the cut joints, in order: how independent it is of the ones before it that
// are (Gram-Schmidt on the rows of ConstraintRows over the coordinates solved for): the relative
// remainder, 1 for an equation orthogonal to the others, 0 for a repeated one; independent above
// `tolerance`.
std::vector<double> EquationRemainders(const Eigen::MatrixXd& G, double tolerance) {
  const Eigen::Index m = G.rows();
  std::vector<Eigen::VectorXd> basis;
  std::vector<double> remainder(size_t(m), 0.0);
  // A row at the round-off of the others is zero: normalized, it would look independent of
  // every row (a planar loop in a tilted plane: its out-of-plane translation's row was 3e-17 and
  // was kept instead of an in-plane one, leaving [M G^T; G 0] singular).
  const double largest = m > 0 && G.cols() > 0 ? G.rowwise().norm().maxCoeff() : 0.0;
  for (Eigen::Index i = 0; i < m; ++i) {
    const double size = G.row(i).norm();
    if (size <= tolerance * largest) continue;
    Eigen::VectorXd v = G.row(i).transpose() / size;
    for (int pass = 0; pass < 2; ++pass)
      for (const Eigen::VectorXd& q : basis) v -= q.dot(v) * q;
    remainder[size_t(i)] = v.norm();
    if (v.norm() > tolerance) basis.push_back(v / v.norm());
  }
  return remainder;
}

// A drive that a loop locks: an equation that is a combination y of the kept ones over the
// coordinates solved for (so it is dropped: the mechanism's free motion keeps it) but not the
// same combination over the prescribed coordinates moves it with the drive, which would open the
// loop (a block driven about one pin and held by a second one; both cranks of a four-bar driven).
// Dropped, such an equation would let the loop open without a word: refused instead, naming the
// cut joint, its equation and the driven nodes.
void RequireDrivesFree(const SystemModel& model, const DofMap& dofs, const Eigen::MatrixXd& G_s,
                       const Eigen::MatrixXd& G_p, const std::vector<double>& remainder) {
  if (G_p.cols() == 0) return;
  std::vector<Eigen::Index> kept;
  for (size_t i = 0; i < remainder.size(); ++i)
    if (remainder[i] > 1e-8) kept.push_back(Eigen::Index(i));
  Eigen::MatrixXd Ks(G_s.cols(), Eigen::Index(kept.size())), Kp(G_p.cols(), Eigen::Index(kept.size()));
  for (size_t k = 0; k < kept.size(); ++k) {
    Ks.col(Eigen::Index(k)) = G_s.row(kept[k]).transpose();
    Kp.col(Eigen::Index(k)) = G_p.row(kept[k]).transpose();
  }
  std::optional<Eigen::ColPivHouseholderQR<Eigen::MatrixXd>> qr;
  if (!kept.empty()) qr.emplace(Ks);  // (kept rows exist only over some solved coordinate)
  for (Eigen::Index i = 0; i < G_s.rows(); ++i) {
    if (remainder[size_t(i)] > 1e-8) continue;
    Eigen::VectorXd left = G_p.row(i).transpose();
    if (qr) left -= Kp * Eigen::VectorXd(qr->solve(G_s.row(i).transpose()));
    if (left.lpNorm<Eigen::Infinity>() <= 1e-8) continue;
    // Equation i: its cut joint and its place in the joint's set.
    size_t c = 0;
    while (c + 1 < model.cut_joints.size() &&
           i >= Eigen::Index(dofs.multiplier_first(int(c) + 1) - dofs.first_multiplier()))
      ++c;
    const CutJoint& cut = model.cut_joints[c];
    const int equation = cut.equations[size_t(i - (dofs.multiplier_first(int(c)) - dofs.first_multiplier()))];
    std::string driven;
    int column = 0;
    for (int j = 0; j < dofs.first_multiplier(); ++j) {
      if (!dofs.prescribed(j)) continue;
      if (std::abs(left[column++]) <= 1e-8) continue;
      for (const SystemModel::Prescribed& p : model.prescribed) {
        if (dofs.prescribed_index(p) != j) continue;
        const std::string name = "'" + model.node_names[size_t(p.node)] + "'";
        if (driven.find(name) == std::string::npos) driven += (driven.empty() ? "" : ", ") + name;
      }
    }
    throw InputError(cut.name + ": the loop it closes locks the drive of node " + driven + " (its " +
                     ConstraintName(cut.joint, equation) +
                     " moves with the drive and with no free coordinate): a driven loop needs a coordinate free "
                     "to follow the drive; remove the drive or this joint, or free a joint of the loop");
  }
}

}  // namespace

std::vector<std::string> DropRedundantEquations(SystemModel& model) {
  std::vector<std::string> notes(model.cut_joints.size());
  if (model.cut_joints.empty()) return notes;
  model.Number();  // with every equation of the cut joints
  const DofMap& dofs = model.dofs();
  const SystemState state = InitialState(model);
  Eigen::MatrixXd G_s, G_p;
  ConstraintRows(model, dofs, state, G_s, &G_p);
  const std::vector<double> remainder = EquationRemainders(G_s, 1e-8);
  RequireDrivesFree(model, dofs, G_s, G_p, remainder);
  const int first = dofs.first_multiplier();
  for (size_t c = 0; c < model.cut_joints.size(); ++c) {
    CutJoint& cut = model.cut_joints[c];
    std::vector<int> kept;
    std::string dropped;
    for (size_t i = 0; i < cut.equations.size(); ++i) {
      if (remainder[size_t(dofs.multiplier_first(int(c)) - first) + i] > 1e-8) {
        kept.push_back(cut.equations[i]);
      } else {
        dropped += (dropped.empty() ? "" : ", ") + ConstraintName(cut.joint, cut.equations[i]);
      }
    }
    notes[c] = dropped;
    cut.equations = kept;
  }
  model.Number();  // with the kept ones
  return notes;
}

std::string LoopSingularity(const SystemModel& model, const SystemState& state) {
  if (model.cut_joints.empty()) return "";
  const DofMap& dofs = model.dofs();
  Eigen::MatrixXd G;
  ConstraintRows(model, dofs, state, G);
  const std::vector<double> remainder = EquationRemainders(G, 1e-8);
  double least = 1.0;
  int worst = -1, equation = -1;
  for (size_t c = 0; c < model.cut_joints.size(); ++c) {
    for (size_t i = 0; i < model.cut_joints[c].equations.size(); ++i) {
      const double r = remainder[size_t(dofs.multiplier_first(int(c)) - dofs.first_multiplier()) + i];
      if (r < least) least = r, worst = int(c), equation = model.cut_joints[c].equations[i];
    }
  }
  if (worst < 0 || least > 0.05) return "";
  char buffer[80];
  std::snprintf(buffer, sizeof buffer, " is within %.2g of the span of the other constraints", least);
  return model.cut_joints[size_t(worst)].name + ": the loop it closes is at or near a singular configuration (a dead " +
         "point: its " + ConstraintName(model.cut_joints[size_t(worst)].joint, equation) + buffer + ")";
}

double LoopViolation(const SystemModel& model, const SystemState& state, int* worst, const BodyDataAtState* data,
                     SystemScratch* scratch) {
  const double L = ModelSize(model);
  double largest = 0.0;
  if (worst) *worst = -1;
  for (size_t c = 0; c < model.cut_joints.size(); ++c) {
    const NodeJoint& j = model.cut_joints[c].joint;
    const ConstraintBlock block =
        EvaluateConstraint(j, state.x[j.parent], state.R[j.parent], state.x[j.child], state.R[j.child]);
    for (int eq : model.cut_joints[c].equations) {
      const double v = std::abs(block.g[eq]) * (block.position[size_t(eq)] ? 1.0 : L);
      if (v > largest) {
        largest = v;
        if (worst) *worst = int(c);
      }
    }
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const SuperelementBody& body = model.bodies[b];
    if (body.n_constraints() == 0) continue;
    std::optional<BodyData> evaluated;
    BodyData* d = BodyDataFor(model, state, int(b), data, evaluated);
    SystemScratch own_scratch;  // (no allocation with `data` and `scratch`)
    Eigen::VectorXd& g = (scratch ? *scratch : own_scratch).g;
    if (d) InterfaceConstraint(body, *d, &g, nullptr, nullptr, nullptr);  // lengths
    const double v = d ? g.lpNorm<Eigen::Infinity>() : std::numeric_limits<double>::infinity();
    if (v > largest) {
      largest = v;
      if (worst) *worst = int(model.cut_joints.size() + b);
    }
  }
  return largest;
}

std::vector<Eigen::Matrix<double, 6, 1>> CutJointReactions(const SystemModel& model, const SystemState& state) {
  std::vector<Eigen::Matrix<double, 6, 1>> out;
  int first = 0;  // the joint's first multiplier in state.lambda
  for (const CutJoint& cut : model.cut_joints) {
    const NodeJoint& j = cut.joint;
    const ConstraintBlock block =
        EvaluateConstraint(j, state.x[j.parent], state.R[j.parent], state.x[j.child], state.R[j.child]);
    ConstraintValues l_full = ConstraintValues::Zero(block.g.size());
    for (size_t i = 0; i < cut.equations.size(); ++i) l_full[cut.equations[i]] = state.lambda[first + long(i)];
    first += int(cut.equations.size());
    out.push_back(-(block.G.rightCols<6>().transpose() * l_full));
  }
  return out;
}

bool LoopsClosed(const SystemModel& model, const SystemState& state, double tolerance, const BodyDataAtState* data,
                 SystemScratch* scratch) {
  return !model.has_constraints() ||
         LoopViolation(model, state, nullptr, data, scratch) <= tolerance * ModelSize(model);
}

}  // namespace femb
