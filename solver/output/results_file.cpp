// results.h5 and probes.csv: the recorded series gathered (ResultsRecorder::Results) and written
// whole.
#include <unistd.h>

#include <charconv>
#include <filesystem>
#include <fstream>

#include "formats/hdf5_file.h"
#include "formats/input_error.h"
#include "solver/output/results_recorder.h"

namespace femb {

RecordedResults ResultsRecorder::Results() const {
  using Vector = Eigen::Map<const Eigen::VectorXd>;
  const SystemModel& model = scene_.model;
  RecordedResults r;
  r.scene = scene_.spec.file;
  r.analysis = Name(scene_.spec.analysis.type);
  r.units = scene_.spec.units;
  r.time = Vector(time_.data(), long(time_.size()));
  if (step_size_.size() == time_.size()) r.step_size = Vector(step_size_.data(), long(step_size_.size()));
  r.probe_names = probe_columns_;
  r.probes = probe_values_.Matrix();
  r.steps_time = Vector(all_steps_t_.data(), long(all_steps_t_.size()));
  r.steps_size = Vector(all_steps_h_.data(), long(all_steps_h_.size()));
  r.steps_taken = steps_taken_, r.rejected_by_error = rejected_by_error_, r.newton_cuts = newton_cuts_;
  for (const CutJoint& cut : model.cut_joints) r.cut_joints.push_back(cut.name);
  r.loop_violation = Vector(loop_violation_.data(), long(loop_violation_.size()));
  if (loop_reactions_.count > 0) r.loop_reaction = loop_reactions_.Matrix();
  r.node_names = model.node_names;
  r.position = positions_.Matrix();
  r.quaternion = quaternions_.Matrix();
  r.velocity = velocities_.Matrix();
  r.angular_velocity = angular_velocities_.Matrix();
  if (reactions_.count > 0) r.reaction = reactions_.Matrix();
  const DofMap& dofs = model.dofs();
  for (int k = 0; k < model.n_nodes(); ++k) {
    if (!JointNode(k)) continue;
    for (int i = 0; i < dofs.node_count(k); ++i)
      r.joint_coordinate_labels.push_back(model.node_names[k] + "." + std::to_string(i));
  }
  r.joint_coordinates = joints_.Matrix();
  r.kinetic = Vector(kinetic_.data(), long(kinetic_.size()));
  r.elastic = Vector(elastic_.data(), long(elastic_.size()));
  r.external_work = Vector(work_.data(), long(work_.size()));
  const Eigen::MatrixXd momentum = momentum_.Matrix();
  r.linear_momentum = momentum.leftCols(3);
  r.angular_momentum = momentum.rightCols(3);
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    RecordedResults::Body& body = r.bodies.emplace_back();
    body.name = scene_.body_names[b];
    for (int k : model.body_nodes[b]) body.nodes.push_back(model.node_names[k]);
    body.modal_coordinates = modal_[b].Matrix();
    const Eigen::MatrixXd frame_and_com = frames_[b].Matrix();
    body.floating_frame = frame_and_com.leftCols(7);
    body.center_of_mass = frame_and_com.rightCols(3);
    if (b < max_von_mises_.size() && !max_von_mises_[b].empty()) {
      // The largest von Mises stress of the body per output step, its mesh node and where that
      // node is in part axes.
      const std::vector<double>& v = max_von_mises_[b];
      body.max_von_mises = Vector(v.data(), long(v.size()));
      body.max_von_mises_node = max_von_mises_node_[b];
      body.max_von_mises_point.resize(long(v.size()), 3);
      for (size_t s = 0; s < v.size(); ++s)
        body.max_von_mises_point.row(long(s)) = scene_.meshes[b]->nodes.row(max_von_mises_node_[b][s]);
    }
  }
  return r;
}

void ResultsRecorder::WriteResults(const std::string& status) { WriteResultsFile(Results(), status, h5_path_); }

void WriteResultsFile(const RecordedResults& r, const std::string& status, const std::string& path) {
  std::error_code ec;
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    h5::Writer w(tmp);
    w.Attribute("/", "format", "femb-results");
    w.Attribute("/", "format_version", "1.0");
    w.Attribute("/", "scene", r.scene);
    w.Attribute("/", "analysis", r.analysis);
    w.Attribute("/", "status", status);
    w.Attribute("/", "units", r.units);
    w.Vector("/time", r.time);
    if (!r.probe_names.empty()) {
      // probes.csv's columns in full precision (the CSV keeps 10 significant digits).
      w.CreateGroup("/probes");
      w.Strings("/probes/names", r.probe_names);
      w.Matrix("/probes/values", r.probes);
    }
    if (r.steps_taken >= 0) {
      w.Attribute("/", "steps", r.steps_taken);
      w.Attribute("/", "rejected_steps_error", r.rejected_by_error);
      w.Attribute("/", "rejected_steps_newton", r.newton_cuts);
    }
    if (r.step_size.size() == r.time.size()) w.Vector("/step_size", r.step_size);
    if (r.steps_time.size() > 0) {
      w.CreateGroup("/steps");
      w.Vector("/steps/time", r.steps_time);
      w.Vector("/steps/size", r.steps_size);
    }
    if (!r.cut_joints.empty()) {
      w.CreateGroup("/loops");
      w.Strings("/loops/cut_joints", r.cut_joints);
      w.Vector("/loops/violation", r.loop_violation);
      if (r.loop_reaction.rows() > 0) w.Matrix("/loops/reaction", r.loop_reaction);
    }
    w.CreateGroup("/nodes");
    w.Strings("/nodes/names", r.node_names);
    w.Matrix("/nodes/position", r.position);
    w.Matrix("/nodes/quaternion", r.quaternion);
    w.Matrix("/nodes/velocity", r.velocity);
    w.Matrix("/nodes/angular_velocity", r.angular_velocity);
    if (r.reaction.rows() > 0) w.Matrix("/nodes/reaction", r.reaction);
    w.Strings("/nodes/joint_coordinate_labels", r.joint_coordinate_labels);
    w.Matrix("/nodes/joint_coordinates", r.joint_coordinates);
    w.CreateGroup("/energy");
    w.Vector("/energy/kinetic", r.kinetic);
    w.Vector("/energy/elastic", r.elastic);
    w.Vector("/energy/external_work", r.external_work);
    w.Matrix("/energy/linear_momentum", r.linear_momentum);
    w.Matrix("/energy/angular_momentum", r.angular_momentum);
    w.CreateGroup("/bodies");
    for (const RecordedResults::Body& body : r.bodies) {
      const std::string g = "/bodies/" + body.name;
      w.CreateGroup(g);
      w.Matrix(g + "/modal_coordinates", body.modal_coordinates);
      w.Matrix(g + "/floating_frame", body.floating_frame);
      w.Matrix(g + "/center_of_mass", body.center_of_mass);
      w.Strings(g + "/nodes", body.nodes);
      if (body.max_von_mises.size() > 0) {
        w.Vector(g + "/max_von_mises", body.max_von_mises);
        w.IntVector(g + "/max_von_mises_node", body.max_von_mises_node);
        w.Matrix(g + "/max_von_mises_point", body.max_von_mises_point);
      }
    }
    w.Close();
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InputError(path + ": cannot rename into place (" + ec.message() + ")");
}

void WriteProbesCsv(const RecordedResults& r, const std::string& path) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp);
    if (!out) throw InputError(tmp + ": cannot write");
    out << "time";
    for (const std::string& name : r.probe_names) out << "," << name;
    out << ",kinetic_energy,elastic_energy,external_work\n";
    char buffer[32];
    const auto put = [&](double v) {
      const std::to_chars_result c = std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::general, 10);
      out.write(buffer, c.ptr - buffer);
    };
    for (long s = 0; s < r.time.size(); ++s) {
      put(r.time[s]);
      for (long c = 0; c < r.probes.cols(); ++c) {
        out.put(',');
        put(r.probes(s, c));
      }
      for (const Eigen::VectorXd* e : {&r.kinetic, &r.elastic, &r.external_work}) {
        out.put(',');
        put((*e)[s]);
      }
      out.put('\n');
    }
    if (!out) throw InputError(tmp + ": cannot write");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InputError(path + ": cannot rename into place (" + ec.message() + ")");
}

}  // namespace femb
