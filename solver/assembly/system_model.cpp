#include "solver/assembly/system_model.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "formats/input_error.h"
#include "solver/joints/joint_tree.h"
#include "solver/rotation.h"

namespace femb {

namespace {
// Calls f(v) for every number of the model's structure that its DofMap depends on
// (DofMap::Shape), in a fixed order.
template <class F>
void ForEachShapeNumber(const SystemModel& model, const F& f) {
  for (int v : {model.n_nodes(), int(model.joints.size()), int(model.bodies.size()), int(model.cut_joints.size()),
                int(model.prescribed.size())})
    f(v);
  for (const NodeJoint& j : model.joints) f(j.child), f(j.parent), f(j.n_coordinates());
  for (const SuperelementBody& body : model.bodies) f(body.n_modes()), f(body.n_constraints());
  for (const CutJoint& cut : model.cut_joints) f(int(cut.equations.size()));
  for (const auto& p : model.prescribed) f(p.node), f(p.coordinate);
}
}  // namespace

std::vector<int> DofMap::Shape(const SystemModel& model) {
  std::vector<int> shape;
  ForEachShapeNumber(model, [&](int v) { shape.push_back(v); });
  return shape;
}

bool DofMap::Matches(const SystemModel& model) const {
  // Without allocating: the loops' checks call it once per Newton iteration.
  size_t i = 0;
  bool same = true;
  ForEachShapeNumber(model, [&](int v) {
    same = same && i < shape_.size() && shape_[i] == v;
    ++i;
  });
  return same && i == shape_.size();
}

void SystemModel::Number() { dofs_ = std::make_shared<const DofMap>(*this); }

const DofMap& SystemModel::dofs() const {
  if (!dofs_) throw std::logic_error("SystemModel::dofs(): the model was not numbered (SystemModel::Number)");
  if (!dofs_->Matches(*this)) {
    throw std::logic_error(
        "SystemModel::dofs(): the model's structure changed since it was numbered "
        "(SystemModel::Number)");
  }
  return *dofs_;
}

DofMap::DofMap(const SystemModel& model) : shape_(Shape(model)) {
  const int n = model.n_nodes();
  joint_of_.assign(n, -1);
  for (size_t j = 0; j < model.joints.size(); ++j) {
    const int c = model.joints[j].child, p = model.joints[j].parent;
    if (c < 0 || c >= n || p < kGround || p >= n) {
      throw InputError("joint " + std::to_string(j) + " names a node that does not exist");
    }
    if (joint_of_[c] >= 0) {
      throw InputError("node '" + model.node_names[c] + "' has two parent joints");
    }
    joint_of_[c] = int(j);
  }
  // Parents before children; a node met again on its own parent chain closes a cycle.
  std::vector<int> state(n, 0);  // 0 new, 1 on the chain, 2 placed
  for (int k = 0; k < n; ++k) {
    std::vector<int> chain;
    int m = k;
    while (m >= 0 && state[m] == 0) {
      state[m] = 1;
      chain.push_back(m);
      m = joint_of_[m] >= 0 ? model.joints[joint_of_[m]].parent : -1;
    }
    if (m >= 0 && state[m] == 1) {
      std::string names;
      for (int c : chain) names += (names.empty() ? "" : " -> ") + model.node_names[c];
      throw InputError("joint dependency cycle through nodes " + names + " -> " + model.node_names[m]);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      state[*it] = 2;
      order_.push_back(*it);
    }
  }
  for (int k = 0; k < n; ++k) {
    node_first_.push_back(n_dofs_);
    node_count_.push_back(joint_of_[k] >= 0 ? model.joints[joint_of_[k]].n_coordinates() : 6);
    n_dofs_ += node_count_.back();
  }
  for (const SuperelementBody& body : model.bodies) {
    mode_dof_.push_back(n_dofs_);
    n_dofs_ += body.n_modes();
  }
  first_multiplier_ = n_dofs_;
  for (const CutJoint& cut : model.cut_joints) {
    multiplier_first_.push_back(n_dofs_);
    n_dofs_ += int(cut.equations.size());
  }
  for (const SuperelementBody& body : model.bodies) {
    body_multiplier_first_.push_back(body.n_constraints() > 0 ? n_dofs_ : -1);
    n_dofs_ += body.n_constraints();
  }
  prescribed_.assign(n_dofs_, false);
  for (const auto& p : model.prescribed) prescribed_[prescribed_index(p)] = true;
  for (int j = 0; j < n_dofs_; ++j) {
    if (!prescribed_[j]) solved_.push_back(j);
  }
}

void JointToGround(SystemModel& model, JointType type, int k, const Eigen::Vector3d& axis,
                   const Eigen::Vector3d& axis2) {
  const NodeJoint joint = MakeNodeJoint(type, k, kGround, axis, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(),
                                        model.node_x0[k], model.node_R0[k], axis2);
  for (NodeJoint& j : model.joints) {
    if (j.child == k && j.parent == kGround) {
      j = joint;  // a new support for the node
      return;
    }
  }
  model.joints.push_back(joint);
}

void Clamp(SystemModel& model, int k) { JointToGround(model, JointType::kRigid, k, Eigen::Vector3d::UnitZ()); }

void Pin(SystemModel& model, int k) { JointToGround(model, JointType::kSpherical, k, Eigen::Vector3d::UnitZ()); }

void RevoluteToGround(SystemModel& model, int k, const Eigen::Vector3d& axis) {
  JointToGround(model, JointType::kRevolute, k, axis);
}

void PrismaticToGround(SystemModel& model, int k, const Eigen::Vector3d& axis) {
  JointToGround(model, JointType::kPrismatic, k, axis);
}

void CylindricalToGround(SystemModel& model, int k, const Eigen::Vector3d& axis) {
  JointToGround(model, JointType::kCylindrical, k, axis);
}

bool FixedToGround(const SystemModel& model, int k) {
  for (const NodeJoint& j : model.joints) {
    if (j.child != k) continue;
    return j.n_coordinates() == 0 && (j.parent == kGround || FixedToGround(model, j.parent));
  }
  return false;  // free
}

int AddNode(SystemModel& model, const std::string& name, const Eigen::Vector3d& x, const Eigen::Matrix3d& R) {
  model.node_names.push_back(name);
  model.node_x0.push_back(x);
  model.node_R0.push_back(R);
  return model.n_nodes() - 1;
}

SystemState InitialState(const SystemModel& model) {
  const DofMap& dofs = model.dofs();
  SystemState s;
  s.x = model.node_x0;
  s.R = model.node_R0;
  for (int k = 0; k < model.n_nodes(); ++k) s.z.push_back(Eigen::VectorXd::Zero(dofs.node_count(k)));
  for (const SuperelementBody& body : model.bodies) {
    s.eta.push_back(Eigen::VectorXd::Zero(body.n_modes()));
    s.frames.push_back(body.InitialFrame());
  }
  s.lambda = Eigen::VectorXd::Zero(dofs.n_multipliers());
  UpdateKinematics(model, dofs, s);
  return s;
}

BodyConfiguration BodyConfigurationOf(const SystemModel& model, const SystemState& state, int b) {
  BodyConfiguration c;
  BodyConfigurationOf(model, state, b, c);
  return c;
}

void BodyConfigurationOf(const SystemModel& model, const SystemState& state, int b, BodyConfiguration& c) {
  const std::vector<int>& nodes = model.body_nodes[b];
  c.x.resize(nodes.size());
  c.R.resize(nodes.size());
  for (size_t a = 0; a < nodes.size(); ++a) {
    c.x[a] = state.x[nodes[a]];
    c.R[a] = state.R[nodes[a]];
  }
  c.eta = state.eta[b];
}

void ApplyIncrement(const SystemModel& model, const DofMap& dofs, const Eigen::VectorXd& delta, SystemState& state) {
  for (int k = 0; k < model.n_nodes(); ++k) {
    if (dofs.node_count(k) == 0) continue;
    const auto dz = delta.segment(dofs.node_first(k), dofs.node_count(k));
    state.z[k] += dz;
    const int j = dofs.joint_of(k);
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    if (j < 0) {
      d = dz;  // a free node's own spatial increments
      state.x[k] += d.head<3>();
    } else if (model.joints[j].type == JointType::kSpherical) {
      d.tail<3>() = dz;  // the child's own rotation; its position follows the parent
    }
    if (d.tail<3>().squaredNorm() > 0) state.R[k] = ExpSO3(Eigen::Vector3d(d.tail<3>())) * state.R[k];
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    state.eta[b] += delta.segment(dofs.mode_dof(int(b)), model.bodies[b].n_modes());
  }
  if (dofs.n_multipliers() > 0) state.lambda += delta.tail(dofs.n_multipliers());
  UpdateKinematics(model, dofs, state);
}

void ApplyPrescribed(const SystemModel& model, const DofMap& dofs, double t, SystemState& state, Eigen::VectorXd* W,
                     Eigen::VectorXd* Wdot, SystemScratch* scratch) {
  if (model.prescribed.empty()) return;
  SystemScratch own;
  Eigen::VectorXd& delta = (scratch ? *scratch : own).delta;
  delta.setZero(dofs.n_dofs());
  PrescribedIncrements(model, dofs, t, state, delta, W, Wdot);
  ApplyIncrement(model, dofs, delta, state);
}

void PrescribedIncrements(const SystemModel& model, const DofMap& dofs, double t, const SystemState& state,
                          Eigen::VectorXd& delta, Eigen::VectorXd* W, Eigen::VectorXd* Wdot) {
  for (const auto& p : model.prescribed) {
    const int j = dofs.prescribed_index(p);
    delta[j] = p.value(t) - state.z[p.node][p.coordinate];
    if (W) (*W)[j] = p.rate ? p.rate(t) : 0.0;
    if (Wdot) (*Wdot)[j] = p.acceleration ? p.acceleration(t) : 0.0;
  }
}

double BoundingDiagonal(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 2) return 0.0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
  for (const Eigen::Vector3d& x : points) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  return (hi - lo).norm();
}

double ModelSize(const SystemModel& model) {
  double size = BoundingDiagonal(model.node_x0);
  if (!(size > 0))
    for (const SuperelementBody& body : model.bodies) size = std::max(size, body.length());
  return size > 0 ? size : 1.0;
}

}  // namespace femb
