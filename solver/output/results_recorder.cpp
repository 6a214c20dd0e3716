#include "solver/output/results_recorder.h"

#include <unistd.h>

#include <Eigen/Geometry>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "formats/hdf5_file.h"
#include "formats/input_error.h"
#include "formats/part_file.h"

namespace femb {
namespace {

Eigen::Vector4d Quaternion(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  if (q.w() < 0) q.coeffs() *= -1;  // w >= 0: a continuous, unique representative
  return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
}

// A CSV number: printf's %.10g (std::to_chars with a precision is specified as printf), without
// a std::string or a locale per number.
void Put(std::ofstream& out, double v) {
  char buffer[32];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::general, 10);
  out.write(buffer, r.ptr - buffer);
}

}  // namespace

double* ResultsRecorder::Rows::Append() {
  const long per_chunk = ChunkRows(), slot = count % per_chunk;
  ++count;
  if (width == 0) return nullptr;
  if (slot == 0) chunks.push_back(std::unique_ptr<double[]>(new double[size_t(per_chunk) * size_t(width)]));
  double* const row = chunks.back().get() + slot * width;
  std::fill(row, row + width, 0.0);
  return row;
}

Eigen::MatrixXd ResultsRecorder::Rows::Matrix() const {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::MatrixXd out(count, width);
  const long per_chunk = ChunkRows();
  for (size_t c = 0; c < chunks.size(); ++c) {
    const long first = long(c) * per_chunk, rows = std::min(per_chunk, count - first);
    out.middleRows(first, rows) = Eigen::Map<const RowMajor>(chunks[c].get(), rows, width);
  }
  return out;
}

ResultsRecorder::ResultsRecorder(const Scene& scene, const std::string& directory)
    : scene_(scene), dofs_(scene.model.dofs()), files_(!directory.empty()), directory_(directory) {
  flush_every_ = scene.spec.flush_every;
  flush_every_steps_ = scene.spec.flush_every_steps;
  // Animation frames: as asked, or about kAutoFrames per run (the output steps the analysis will
  // take: load steps, or time steps over output_every).
  constexpr double kAutoFrames = 500;
  const SceneAnalysisSpec& a = scene.spec.analysis;
  const double outputs =
      a.type == AnalysisType::kDynamic ? a.end_time / (a.step * std::max(a.output_every, 1)) : double(a.steps);
  animation_every_ =
      scene.spec.animation_every > 0 ? scene.spec.animation_every : std::max(1, int(std::ceil(outputs / kAutoFrames)));
  // Error-controlled steps: how many there will be is not known; a frame per end_time / 500
  // (the first output at or after each such time), or every output step of output_step.
  if (a.type == AnalysisType::kDynamic && a.adaptive_step && scene.spec.animation_every == 0) {
    animation_every_ = 1;
    frame_interval_ = a.end_time / kAutoFrames;
    if (a.output_step > 0) frame_interval_ = std::max(frame_interval_, a.output_step);
  }
  // The series' widths (Rows).
  const SystemModel& model = scene.model;
  const int n = model.n_nodes();
  const size_t n_bodies = model.bodies.size();
  positions_.width = velocities_.width = angular_velocities_.width = 3 * n;
  quaternions_.width = 4 * n;
  reactions_.width = 6 * n;
  momentum_.width = 6;
  loop_reactions_.width = 6 * int(model.cut_joints.size());
  joint_node_.resize(size_t(n));
  for (int k = 0; k < n; ++k) {
    joint_node_[size_t(k)] = JointNode(k);
    if (joint_node_[size_t(k)]) joints_.width += dofs_.node_count(k);
  }
  modal_.resize(n_bodies);
  frames_.resize(n_bodies);
  for (size_t b = 0; b < n_bodies; ++b) {
    modal_[b].width = model.bodies[b].n_modes();
    frames_[b].width = 10;
  }
  q_loc_.resize(n_bodies);
  q_stress_.resize(n_bodies);
  factors_.resize(n_bodies);
  has_stress_coordinates_.assign(n_bodies, 0);
  has_factors_.assign(n_bodies, 0);
  if (files_) {
    std::error_code ec;
    std::filesystem::create_directories(directory, ec);
    if (ec) throw InputError(directory + ": cannot create output folder (" + ec.message() + ")");
    csv_path_ = (std::filesystem::path(directory) / "probes.csv").string();
    h5_path_ = (std::filesystem::path(directory) / "results.h5").string();
    csv_tmp_ = csv_path_ + ".tmp." + std::to_string(::getpid());
    csv_.open(csv_tmp_);
    if (!csv_) throw InputError(csv_tmp_ + ": cannot write");
    csv_ << "time";
  }
  static const char* xyz[3] = {"x", "y", "z"};
  static const char* wxyz[4] = {"w", "x", "y", "z"};
  // Every probe column: in probes.csv's header and results.h5's /probes/names.
  const auto column = [&](const std::string& name) {
    if (files_) csv_ << "," << name;
    probe_columns_.push_back(name);
  };
  for (const SceneProbeSpec& p : scene.spec.probes) {
    for (const ProbeQuantity q : p.quantities) {
      if (q == ProbeQuantity::kRotation) {
        for (const char* c : wxyz) column(p.name + "." + Name(q) + "." + c);
      } else if (q == ProbeQuantity::kStress) {
        // The stress point's von Mises stress and tensor (part axes).
        static const char* components[7] = {"von_mises", "xx", "yy", "zz", "yz", "xz", "xy"};
        for (const char* c : components) column(p.name + ".stress." + c);
      } else if (q == ProbeQuantity::kEffort) {
        // The generalized force of each prescribed coordinate of the node's joint.
        for (int c : scene.effort_coordinates[size_t(&p - scene.spec.probes.data())]) {
          column(p.name + ".effort." + std::to_string(scene.model.prescribed[size_t(c)].coordinate));
        }
      } else if (q == ProbeQuantity::kReaction) {
        static const char* components[6] = {"fx", "fy", "fz", "mx", "my", "mz"};
        for (const char* c : components) column(p.name + ".reaction." + c);
      } else if (q == ProbeQuantity::kJoint) {
        // The node's joint coordinates (revolute: angle; prismatic: travel; cylindrical: both).
        // To the ground or between nodes: the joint's coordinates (a revolute joint's angle
        // between two bodies, ...). Spherical joints have rotation increments, not coordinates
        // a probe could show.
        const int k = scene.node_index.at(p.node);
        int d = 0;
        for (const NodeJoint& j : scene.model.joints) {
          if (j.child == k) d = j.type == JointType::kSpherical ? 0 : j.n_coordinates();
        }
        // A node whose revolute, prismatic, cylindrical or universal joint was cut to close a
        // loop: that joint's coordinates, from the placements (CutJointCoordinates).
        for (size_t c = 0; d == 0 && c < scene.model.cut_joints.size(); ++c) {
          const NodeJoint& j = scene.model.cut_joints[c].joint;
          if (j.child != k || j.type == JointType::kRigid || j.type == JointType::kSpherical) {
            continue;
          }
          d = j.n_coordinates();
          probe_cut_.resize(scene.spec.probes.size(), -1);
          probe_cut_[size_t(&p - scene.spec.probes.data())] = int(c);
        }
        if (d == 0 || d >= 3) {
          throw InputError(p.where + ": probe '" + p.name + "': node '" + p.node +
                           "' has no revolute, prismatic, cylindrical or universal joint coordinate");
        }
        for (int i = 0; i < d; ++i) column(p.name + ".joint." + std::to_string(i));
      } else {
        for (const char* c : xyz) column(p.name + "." + Name(q) + "." + c);
      }
    }
  }
  if (files_) csv_ << ",kinetic_energy,elastic_energy,external_work\n";
  probe_values_.width = int(probe_columns_.size());
}

// What one output step's fields and probes derive from its state beyond the series, each made
// when first asked for: the node accelerations, and per body its stress coordinates, its frame's
// inertia load factors and the rates of its local coordinates. The velocities and accelerations
// over the unknowns are zero where the analysis has none (static).
class ResultsRecorder::OutputStep {
 public:
  OutputStep(ResultsRecorder& recorder, double t, const SystemState& state, const Eigen::VectorXd& W,
             const Eigen::VectorXd* accelerations)
      : r_(recorder),
        model_(recorder.scene_.model),
        t_(t),
        state_(state),
        zero_(Eigen::VectorXd::Zero(recorder.dofs_.n_dofs())),
        V_(W.size() == recorder.dofs_.n_dofs() ? W : zero_),
        A_(accelerations && accelerations->size() == recorder.dofs_.n_dofs() ? *accelerations : zero_),
        motion_(model_.bodies.size()) {}

  const std::vector<Eigen::Matrix<double, 6, 1>>& NodeAccelerations() {
    if (node_acc_.empty()) node_acc_ = femb::NodeAccelerations(model_, r_.dofs_, state_, V_, A_);
    return node_acc_;
  }
  const Eigen::VectorXd& StressCoordinates(size_t b) {
    if (!r_.has_stress_coordinates_[b]) r_.q_stress_[b] = model_.bodies[b].StressCoordinates(r_.q_loc_[b]);
    r_.has_stress_coordinates_[b] = 1;
    return r_.q_stress_[b];
  }
  // The inertia load factors of body b's frame (InertiaLoads) when its modal
  // stresses include the inertia load cases: d'Alembert with gravity (static analyses: gravity
  // as ramped by the analysis, no motion). Null without them.
  const Eigen::VectorXd* Inertia(size_t b) {
    const Scene& scene = r_.scene_;
    if (!scene.stresses[b] || scene.stresses[b]->inertia_modes.size() == 0) return nullptr;
    if (r_.has_factors_[b]) return &r_.factors_[b];
    const bool dynamic = scene.spec.analysis.type == AnalysisType::kDynamic;
    NodeAccelerations();
    double g = dynamic ? 1.0 : 0.0;
    if (!dynamic && model_.static_gravity_end > 0) g = std::min(t_ / model_.static_gravity_end, 1.0);
    const SuperelementBody& body = model_.bodies[b];
    InertiaLoadFactors load;
    BodyData data = Evaluate(body, BodyConfigurationOf(model_, state_, int(b)), state_.frames[b]);
    InertiaLoads(body, data, GatherBody(model_, r_.dofs_, state_, int(b), V_),
                 GatherBodyAcceleration(model_, r_.dofs_, int(b), node_acc_, A_), g * model_.gravity, load);
    r_.factors_[b] = load.a;
    r_.has_factors_[b] = 1;
    return &r_.factors_[b];
  }
  // Body b's frame motion and the rates of its local coordinates (LocalRates).
  const LocalMotion& MotionOf(int b) {
    if (!motion_[size_t(b)]) {
      const SuperelementBody& body = model_.bodies[size_t(b)];
      // The local coordinates at this frame are q_loc_ already: not solved for again.
      BodyData d;
      d.q = r_.q_loc_[size_t(b)];
      EvaluateSolved(body, BodyConfigurationOf(model_, state_, b), state_.frames[size_t(b)], d);
      const Eigen::VectorXd wdot = GatherBodyAcceleration(model_, r_.dofs_, b, NodeAccelerations(), A_);
      motion_[size_t(b)] = LocalRates(body, d, GatherBody(model_, r_.dofs_, state_, b, V_), &wdot);
    }
    return *motion_[size_t(b)];
  }

 private:
  ResultsRecorder& r_;
  const SystemModel& model_;
  const double t_;
  const SystemState& state_;
  const Eigen::VectorXd zero_;
  const Eigen::VectorXd& V_;
  const Eigen::VectorXd& A_;
  std::vector<Eigen::Matrix<double, 6, 1>> node_acc_;
  std::vector<std::optional<LocalMotion>> motion_;
};

void ResultsRecorder::Record(double t, const SystemState& state, const Eigen::VectorXd& W, double kinetic,
                             double elastic, double external_work, const Eigen::Vector3d& linear_momentum,
                             const Eigen::Vector3d& angular_momentum,
                             const std::vector<Eigen::Matrix<double, 6, 1>>* reactions,
                             const Eigen::VectorXd* accelerations) {
  const NodeRows nodes =
      RecordSeries(t, state, W, kinetic, elastic, external_work, linear_momentum, angular_momentum, reactions);
  RecordBodies(state);
  RecordJoints(state);
  const bool frame = AnimationFrame(t);
  OutputStep step(*this, t, state, W, accelerations);
  QueueFields(state, frame, step);
  if (files_) Put(csv_, t);
  double* const probe_row = probe_values_.Append();
  ProbeRow row{probe_row, 0};
  WriteProbes(state, nodes, reactions, step, row);
  PutProbe(row, kinetic);
  PutProbe(row, elastic);
  PutProbe(row, external_work);
  if (files_) csv_.put('\n');
}

ResultsRecorder::NodeRows ResultsRecorder::RecordSeries(double t, const SystemState& state, const Eigen::VectorXd& W,
                                                        double kinetic, double elastic, double external_work,
                                                        const Eigen::Vector3d& linear_momentum,
                                                        const Eigen::Vector3d& angular_momentum,
                                                        const std::vector<Eigen::Matrix<double, 6, 1>>* reactions) {
  const SystemModel& model = scene_.model;
  const int n = model.n_nodes();
  if (model.has_constraints()) {
    loop_violation_.push_back(LoopViolation(model, state));
    max_loop_violation_ = std::max(max_loop_violation_, loop_violation_.back());
  }
  // Every series appends its row in place (Rows): no allocation per output step once grown.
  NodeRows rows{positions_.Append(), quaternions_.Append(), velocities_.Append(), angular_velocities_.Append()};
  for (int k = 0; k < n; ++k) {
    Eigen::Vector3d::Map(rows.pos + 3 * k) = state.x[k] + scene_.origin;
    Eigen::Vector4d::Map(rows.quat + 4 * k) = Quaternion(state.R[k]);
    const Eigen::Matrix<double, 6, 1> v = NodeMotion(state, k, W);
    Eigen::Vector3d::Map(rows.vel + 3 * k) = v.head<3>();
    Eigen::Vector3d::Map(rows.ang + 3 * k) = v.tail<3>();
  }
  time_.push_back(t);
  ++outputs_since_flush_;
  kinetic_.push_back(kinetic);
  elastic_.push_back(elastic);
  work_.push_back(external_work);
  double* const momentum = momentum_.Append();
  Eigen::Vector3d::Map(momentum) = linear_momentum;
  Eigen::Vector3d::Map(momentum + 3) =
      angular_momentum + scene_.origin.cross(linear_momentum);  // about the global origin
  if (scene_.spec.reactions) {
    double* const r = reactions_.Append();
    for (int k = 0; k < n; ++k)
      for (int i = 0; i < 6; ++i) r[6 * k + i] = Reaction(reactions, k, i);
  }
  if (scene_.spec.reactions && !model.cut_joints.empty()) {
    const std::vector<Eigen::Matrix<double, 6, 1>> cut = CutJointReactions(model, state);
    double* const r = loop_reactions_.Append();
    for (size_t c = 0; c < cut.size(); ++c) Eigen::Matrix<double, 6, 1>::Map(r + 6 * c) = cut[c];
  }
  return rows;
}

// Per body: modal coordinates, floating frame and centre of mass; the local coordinates (kept for
// the mesh, the stresses and the probes of this output step).
void ResultsRecorder::RecordBodies(const SystemState& state) {
  const SystemModel& model = scene_.model;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const SuperelementBody& body = model.bodies[b];
    double* const modal = modal_[b].Append();
    for (int i = 0; i < modal_[b].width; ++i) modal[i] = state.eta[b][i];
    BodyConfigurationOf(model, state, int(b), config_);
    LocalCoordinates(body, config_, state.frames[b], q_loc_[b]);
    const Eigen::Vector3d com = CenterOfMass(body, q_loc_[b], state.frames[b]);
    double* const f = frames_[b].Append();
    Eigen::Vector3d::Map(f) = state.frames[b].x + scene_.origin;
    Eigen::Vector4d::Map(f + 3) = Quaternion(state.frames[b].R);
    Eigen::Vector3d::Map(f + 7) = com + scene_.origin;
    has_stress_coordinates_[b] = 0;
    has_factors_[b] = 0;
  }
}

// Joint coordinates: the coordinates of every node that has a joint (revolute angle, prismatic
// travel, ...), in node order.
void ResultsRecorder::RecordJoints(const SystemState& state) {
  double* const joint_values = joints_.Append();
  int joint_count = 0;
  for (int k = 0; k < scene_.model.n_nodes(); ++k) {
    if (!joint_node_[size_t(k)]) continue;
    if (joint_count + state.z[k].size() > joints_.width)
      throw std::logic_error("ResultsRecorder: joint coordinates changed in number");
    for (int i = 0; i < state.z[k].size(); ++i) joint_values[joint_count++] = state.z[k][i];
  }
}

// Whether the output step just recorded at t is an animation frame: every animation_every-th
// output step, or the first at or after each frame_interval. (Kept in memory, a frame is a few
// numbers per body until WriteAnimation makes it.)
bool ResultsRecorder::AnimationFrame(double t) {
  bool frame = (time_.size() - 1) % size_t(animation_every_) == 0;
  if (frame_interval_ > 0) {
    frame = t >= next_frame_time_ - 1e-9 * frame_interval_;
    if (frame) next_frame_time_ = (std::floor(t / frame_interval_ + 1e-9) + 1) * frame_interval_;
  }
  return frame;
}

// The stresses and the animation's node fields are made when written (MakePending), from what
// they need of this output step.
void ResultsRecorder::QueueFields(const SystemState& state, bool frame, OutputStep& step) {
  const bool frame_fields = frame && scene_.spec.animation;
  if (!scene_.spec.stresses && !frame_fields) return;
  const size_t n_bodies = scene_.model.bodies.size();
  PendingOutput job;
  job.output = long(time_.size()) - 1;
  job.frame = frame_fields ? long(frame_time_.size()) : -1;
  job.frame_x.resize(n_bodies), job.frame_R.resize(n_bodies), job.q_loc.resize(n_bodies), job.sticks.resize(n_bodies);
  job.q_stress.resize(n_bodies), job.factors.resize(n_bodies);
  if (scene_.spec.stresses) max_von_mises_.resize(n_bodies), max_von_mises_node_.resize(n_bodies);
  for (size_t b = 0; b < n_bodies; ++b) {
    job.frame_x[b] = state.frames[b].x, job.frame_R[b] = state.frames[b].R;
    if (frame_fields && scene_.meshes[b]) job.q_loc[b] = q_loc_[b];
    if (frame_fields && !scene_.meshes[b]) {
      // A stick figure: the positions of its nodes.
      const std::vector<int>& sticks = scene_.stick_nodes[b];
      job.sticks[b].resize(long(sticks.size()), 3);
      for (size_t i = 0; i < sticks.size(); ++i)
        job.sticks[b].row(long(i)) = (scene_.origin + state.x[sticks[i]]).transpose().cast<float>();
    }
    if (scene_.spec.stresses && scene_.stresses[b]) {
      job.q_stress[b] = step.StressCoordinates(b);
      if (const Eigen::VectorXd* a = step.Inertia(b)) job.factors[b] = *a;
      max_von_mises_[b].push_back(0.0);
      max_von_mises_node_[b].push_back(0);
    }
  }
  if (frame_fields) frame_time_.push_back(time_.back());
  pending_.push_back(std::move(job));
}

// One value of the probes' row: into probes.csv, and into results.h5's /probes/values while the
// row has room.
void ResultsRecorder::PutProbe(ProbeRow& row, double v) {
  if (files_) {
    csv_.put(',');
    Put(csv_, v);
  }
  if (row.column < probe_values_.width) row.values[row.column++] = v;
}

void ResultsRecorder::WriteProbes(const SystemState& state, const NodeRows& nodes,
                                  const std::vector<Eigen::Matrix<double, 6, 1>>* reactions, OutputStep& step,
                                  ProbeRow& row) {
  for (size_t pi = 0; pi < scene_.spec.probes.size(); ++pi) {
    if (!scene_.spec.probes[pi].body.empty()) {
      WritePointProbe(pi, state, step, row);
    } else {
      WriteNodeProbe(pi, state, nodes, reactions, step, row);
    }
  }
}

// A point probe's quantities: the stress at its stress point; the material point s = s0 + u from
// the frame origin in frame axes, u = shape q_loc (LocalRates for its velocity
// and acceleration).
void ResultsRecorder::WritePointProbe(size_t pi, const SystemState& state, OutputStep& step, ProbeRow& row) {
  const SceneProbeSpec& p = scene_.spec.probes[pi];
  const Scene::PointProbe& point = scene_.point_probes[pi];
  const auto put3 = [&](const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) PutProbe(row, v[i]);
  };
  for (const ProbeQuantity q : p.quantities) {
    if (q == ProbeQuantity::kStress) {
      const auto [b, at] = scene_.stress_probes[pi];
      const Eigen::Matrix<double, 6, 1> s =
          PointStress(*scene_.stresses[size_t(b)], at, step.StressCoordinates(size_t(b)), step.Inertia(size_t(b)));
      PutProbe(row, VonMises(s));
      for (int i = 0; i < 6; ++i) PutProbe(row, s[i]);
      continue;
    }
    const int b = point.body;
    const FrameSolution& body_frame = state.frames[size_t(b)];
    const Eigen::Vector3d u = point.shape * q_loc_[size_t(b)];
    const Eigen::Vector3d r = point.s0 + u;
    if (q == ProbeQuantity::kPosition) put3(scene_.origin + body_frame.x + body_frame.R * r);
    if (q == ProbeQuantity::kDeformation) put3(body_frame.R * u);
    if (q == ProbeQuantity::kVelocity) {
      const LocalMotion& m = step.MotionOf(b);
      put3(body_frame.R * (m.V + m.Omega.cross(r) + point.shape * m.qdot));
    }
    if (q == ProbeQuantity::kAcceleration) {
      const LocalMotion& m = step.MotionOf(b);
      const Eigen::Vector3d ud = point.shape * m.qdot, udd = point.shape * m.qddot;
      put3(body_frame.R * (m.Vdot + m.Omega.cross(m.V) + m.Omegadot.cross(r) + m.Omega.cross(m.Omega.cross(r)) +
                           2.0 * m.Omega.cross(ud) + udd));
    }
  }
}

// A node probe's quantities, from the node series just recorded where they hold them.
void ResultsRecorder::WriteNodeProbe(size_t pi, const SystemState& state, const NodeRows& nodes,
                                     const std::vector<Eigen::Matrix<double, 6, 1>>* reactions, OutputStep& step,
                                     ProbeRow& row) {
  const SystemModel& model = scene_.model;
  const SceneProbeSpec& p = scene_.spec.probes[pi];
  const int k = scene_.node_index.at(p.node);
  const auto put3 = [&](const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) PutProbe(row, v[i]);
  };
  for (const ProbeQuantity q : p.quantities) {
    if (q == ProbeQuantity::kPosition)
      for (int i = 0; i < 3; ++i) PutProbe(row, nodes.pos[3 * k + i]);
    if (q == ProbeQuantity::kRotation)
      for (int i = 0; i < 4; ++i) PutProbe(row, nodes.quat[4 * k + i]);
    if (q == ProbeQuantity::kVelocity)
      for (int i = 0; i < 3; ++i) PutProbe(row, nodes.vel[3 * k + i]);
    if (q == ProbeQuantity::kAngularVelocity)
      for (int i = 0; i < 3; ++i) PutProbe(row, nodes.ang[3 * k + i]);
    if (q == ProbeQuantity::kAcceleration) put3(step.NodeAccelerations()[size_t(k)].head<3>());
    if (q == ProbeQuantity::kAngularAcceleration) put3(step.NodeAccelerations()[size_t(k)].tail<3>());
    if (q == ProbeQuantity::kEffort) {
      // The generalized force of each prescribed coordinate: B^T of what the joint exerts on
      // the node (its reaction: force, moment about the node), B the coordinate's motion of the
      // node (NodeJoint: a revolute's moment about its axis, a prismatic's force along it).
      const NodeJoint& j = model.joints[size_t(dofs_.joint_of(k))];
      const ParentNode parent = ParentOf(state, j.parent);
      const JointMaps maps = ComputeJointMaps(j, parent.x, parent.R, state.x[k], state.z[k]);
      Eigen::Matrix<double, 6, 1> r;
      for (int i = 0; i < 6; ++i) r[i] = Reaction(reactions, k, i);
      for (int c : scene_.effort_coordinates[pi])
        PutProbe(row, maps.B.col(model.prescribed[size_t(c)].coordinate).dot(r));
    }
    if (q == ProbeQuantity::kJoint) WriteJointProbe(pi, k, state, row);
    if (q == ProbeQuantity::kReaction)
      for (int i = 0; i < 6; ++i) PutProbe(row, Reaction(reactions, k, i));
  }
}

// A joint probe: the node's joint coordinates, or those of the cut joint it shows (its node has
// none of its own), with angles continuous through +-pi.
void ResultsRecorder::WriteJointProbe(size_t pi, int k, const SystemState& state, ProbeRow& row) {
  const int c = pi < probe_cut_.size() ? probe_cut_[pi] : -1;
  if (c < 0) {
    for (int i = 0; i < state.z[k].size(); ++i) PutProbe(row, state.z[k][i]);
    return;
  }
  const NodeJoint& j = scene_.model.cut_joints[size_t(c)].joint;
  Eigen::VectorXd z = CutJointCoordinates(j, state.x[j.parent], state.R[j.parent], state.x[j.child], state.R[j.child]);
  probe_last_.resize(scene_.spec.probes.size());
  if (probe_last_[pi].size() == z.size()) {
    for (int i = 0; i < z.size(); ++i) {
      if (i != j.phi_index() && j.type != JointType::kUniversal) continue;
      z[i] += 2 * M_PI * std::round((probe_last_[pi][i] - z[i]) / (2 * M_PI));
    }
  }
  probe_last_[pi] = z;
  for (int i = 0; i < z.size(); ++i) PutProbe(row, z[i]);
}

std::vector<std::string> ResultsRecorder::StressSummary() const {
  std::vector<std::string> lines;
  for (size_t b = 0; b < max_von_mises_.size(); ++b) {
    const std::vector<double>& v = max_von_mises_[b];
    if (v.empty() || !scene_.meshes[b]) continue;
    const size_t s = size_t(std::max_element(v.begin(), v.end()) - v.begin());
    const int node = max_von_mises_node_[b][s];
    const Eigen::Vector3d X = scene_.meshes[b]->nodes.row(node).transpose();
    const bool excluded = b < scene_.stress_excluded.size() && !scene_.stress_excluded[b].empty();
    char buffer[300];
    std::snprintf(
        buffer, sizeof buffer,
        "body '%s': largest von Mises stress %.4g %s at t = %.6g, mesh node %d at (%.6g, %.6g, %.6g) in part axes%s",
        scene_.body_names[b].c_str(), v[s], UnitSystem(scene_.spec.units, "units").stress.c_str(), time_[s], node,
        X.x(), X.y(), X.z(), excluded ? " (outside outputs.stress_exclude)" : "");
    lines.push_back(buffer);
  }
  return lines;
}

bool ResultsRecorder::JointNode(int k) const {
  // A node with joint coordinates: dependent on a parent node (any joint), or on a revolute,
  // prismatic, cylindrical or universal joint to the ground. Free nodes, clamps and pins: no.
  for (const NodeJoint& j : scene_.model.joints) {
    if (j.child != k) continue;
    return j.parent != kGround || (j.type != JointType::kRigid && j.type != JointType::kSpherical);
  }
  return false;
}

ResultsRecorder::~ResultsRecorder() {
  if (!csv_.is_open()) return;
  csv_.close();
  std::error_code ec;
  std::filesystem::remove(csv_tmp_, ec);
}

bool ResultsRecorder::FlushDue() const {
  if (!files_) return false;
  if (flush_every_steps_ > 0 && outputs_since_flush_ >= flush_every_steps_) return true;
  if (outputs_since_flush_ == 0) return false;
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_flush_).count() < flush_every_) return false;
  // The writes' budget: all of them within 2% of the wall time so far, the next one predicted
  // from the last: probes.csv and results.h5 are rewritten whole (their cost grows with the
  // output steps), an animation part holds the frames since the last write.
  const double elapsed = std::chrono::duration<double>(now - started_).count();
  // The growth extrapolated from a write of at least a quarter of the output steps (a smaller
  // one's cost is mostly fixed: files created, datasets opened).
  const double n = double(time_.size()), n_last = double(std::max(outputs_at_last_flush_, 1L));
  const double grows = n_last >= 0.25 * n ? n / n_last : 1.0;
  const double next = last_growing_cost_ * grows + (last_flush_cost_ - last_growing_cost_);
  return flush_seconds_ + next <= 0.02 * elapsed;
}

void ResultsRecorder::Flush(const std::string& status) {
  const auto start = std::chrono::steady_clock::now();
  MakePending();
  if (!files_) return;
  const auto made = std::chrono::steady_clock::now();
  // probes.csv (the stream so far, copied whole to a temporary name and renamed) before
  // results.h5: killed between the two renames, probes.csv holds the newer steps and results.h5
  // those of the write before.
  csv_.flush();
  if (!csv_) throw InputError(csv_tmp_ + ": cannot write");
  const std::string copy = csv_path_ + ".tmp.copy." + std::to_string(::getpid());
  std::error_code ec;
  std::filesystem::copy_file(csv_tmp_, copy, std::filesystem::copy_options::overwrite_existing, ec);
  if (!ec) std::filesystem::rename(copy, csv_path_, ec);
  if (ec) throw InputError(csv_path_ + ": cannot write (" + ec.message() + ")");
  WriteResults(status);
  const auto grown = std::chrono::steady_clock::now();
  WriteAnimationPart();
  last_flush_ = std::chrono::steady_clock::now();
  last_flush_cost_ = std::chrono::duration<double>(last_flush_ - start).count();
  last_growing_cost_ = std::chrono::duration<double>(grown - made).count();
  outputs_at_last_flush_ = long(time_.size());
  flush_seconds_ += last_flush_cost_;
  ++flushes_;
  outputs_since_flush_ = 0;
}

void ResultsRecorder::Finish(const std::string& status) {
  MakePending();
  if (!files_) return;
  csv_.close();
  std::error_code ec;
  std::filesystem::rename(csv_tmp_, csv_path_, ec);
  if (ec) throw InputError(csv_path_ + ": cannot rename into place (" + ec.message() + ")");
  WriteResults(status);
  FinishAnimation();
}

}  // namespace femb
