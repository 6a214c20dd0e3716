// What femb-solve --restart needs of ResultsRecorder (results_recorder.h): the mark of the
// results at a saved state, written into the checkpoint, and the results read back up to it.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "formats/hdf5_file.h"
#include "formats/input_error.h"
#include "solver/output/results_recorder.h"

namespace femb {

void ResultsRecorder::Rows::Load(const Eigen::MatrixXd& m, long n, const std::string& what) {
  if (m.rows() < n || (n > 0 && m.cols() != width)) {
    throw InputError(what + ": " + std::to_string(m.rows()) + " x " + std::to_string(m.cols()) +
                     " values, expected at least " + std::to_string(n) + " x " + std::to_string(width) +
                     " (the scene's outputs differ from the run's?)");
  }
  for (long i = 0; i < n; ++i) {
    double* const row = Append();
    for (int j = 0; j < width; ++j) row[j] = m(i, j);
  }
}

ResultsRecorder::Mark ResultsRecorder::TakeMark() const {
  Mark m;
  m.outputs = long(time_.size());
  m.steps = long(all_steps_t_.size());
  m.frames = long(frame_time_.size());
  m.next_frame_time = next_frame_time_;
  m.probe_last = probe_last_;
  return m;
}

void ResultsRecorder::WriteMark(h5::Writer& w, const Mark& mark) const {
  if (mark.frames > long(frames_written_)) throw std::logic_error("ResultsRecorder::WriteMark: frames not yet written");
  w.CreateGroup("/recorder");
  w.Vector("/recorder/numbers",
           Eigen::Vector4d(double(mark.outputs), double(mark.steps), double(mark.frames), mark.next_frame_time));
  // The probes' last values (angles unwrapped from them): their lengths, then the values.
  std::vector<int> lengths;
  std::vector<double> values;
  for (const Eigen::VectorXd& v : mark.probe_last) {
    lengths.push_back(int(v.size()));
    values.insert(values.end(), v.data(), v.data() + v.size());
  }
  w.IntVector("/recorder/probe_last_lengths", lengths);
  w.Vector("/recorder/probe_last", Eigen::Map<const Eigen::VectorXd>(values.data(), long(values.size())));
  // The animation: the frames' times, files (by index into the file names) and stress fields.
  std::vector<std::string> files;
  std::vector<int> file_of, stress;
  for (long s = 0; s < mark.frames; ++s) {
    const auto it = std::find(files.begin(), files.end(), frame_file_[size_t(s)]);
    file_of.push_back(int(it - files.begin()));
    if (it == files.end()) files.push_back(frame_file_[size_t(s)]);
    stress.push_back(frame_stress_fields_[size_t(s)]);
  }
  w.Vector("/recorder/frame_time", Eigen::Map<const Eigen::VectorXd>(frame_time_.data(), mark.frames));
  w.Strings("/recorder/frame_files", files);
  w.IntVector("/recorder/frame_file", file_of);
  w.IntVector("/recorder/frame_stress", stress);
  w.Strings("/recorder/animation_parts", animation_parts_);
  w.Matrix("/recorder/x0", x0_.cast<double>());
}

void ResultsRecorder::Resume(const h5::Reader& checkpoint) {
  const Eigen::VectorXd numbers = checkpoint.Vector("/recorder/numbers");
  if (numbers.size() != 4) throw InputError(checkpoint.path() + ": /recorder/numbers must hold 4 values");
  const long n = long(numbers[0]), n_steps = long(numbers[1]), n_frames = long(numbers[2]);
  next_frame_time_ = numbers[3];
  const Eigen::VectorXi lengths = checkpoint.IntVector("/recorder/probe_last_lengths");
  const Eigen::VectorXd last = checkpoint.Vector("/recorder/probe_last");
  probe_last_.clear();
  for (long i = 0, at = 0; i < lengths.size(); at += lengths[i], ++i) {
    if (at + lengths[i] > last.size()) throw InputError(checkpoint.path() + ": /recorder/probe_last is too short");
    probe_last_.push_back(last.segment(at, lengths[i]));
  }
  // results.h5's series up to the mark.
  const h5::Reader r(h5_path_);
  const std::string where = h5_path_ + ": ";
  const Eigen::VectorXd t = r.Vector("/time");
  if (t.size() < n) {
    throw InputError(where + "holds " + std::to_string(t.size()) + " output steps, fewer than the checkpoint's " +
                     std::to_string(n));
  }
  const auto head = [n](const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + n); };
  time_ = head(t);
  kinetic_ = head(r.Vector("/energy/kinetic"));
  elastic_ = head(r.Vector("/energy/elastic"));
  work_ = head(r.Vector("/energy/external_work"));
  if (r.Exists("/step_size")) step_size_ = head(r.Vector("/step_size"));
  if (n_steps > 0) {
    const Eigen::VectorXd st = r.Vector("/steps/time"), sh = r.Vector("/steps/size");
    if (st.size() < n_steps || sh.size() < n_steps)
      throw InputError(where + "/steps holds fewer steps than the checkpoint");
    all_steps_t_.assign(st.data(), st.data() + n_steps);
    all_steps_h_.assign(sh.data(), sh.data() + n_steps);
  }
  const SystemModel& model = scene_.model;
  if (!model.cut_joints.empty()) {
    loop_violation_ = head(r.Vector("/loops/violation"));
    for (double v : loop_violation_) max_loop_violation_ = std::max(max_loop_violation_, v);
    if (loop_reactions_.width > 0 && scene_.spec.reactions)
      loop_reactions_.Load(r.Matrix("/loops/reaction"), n, where + "/loops/reaction");
  }
  if (probe_values_.width > 0) {
    if (r.Strings("/probes/names") != probe_columns_) throw InputError(where + "its probes differ from the scene's");
    probe_values_.Load(r.Matrix("/probes/values"), n, where + "/probes/values");
  } else if (r.Exists("/probes/names")) {
    throw InputError(where + "its probes differ from the scene's");
  }
  positions_.Load(r.Matrix("/nodes/position"), n, where + "/nodes/position");
  quaternions_.Load(r.Matrix("/nodes/quaternion"), n, where + "/nodes/quaternion");
  velocities_.Load(r.Matrix("/nodes/velocity"), n, where + "/nodes/velocity");
  angular_velocities_.Load(r.Matrix("/nodes/angular_velocity"), n, where + "/nodes/angular_velocity");
  if (scene_.spec.reactions) reactions_.Load(r.Matrix("/nodes/reaction"), n, where + "/nodes/reaction");
  joints_.Load(r.Matrix("/nodes/joint_coordinates"), n, where + "/nodes/joint_coordinates");
  Eigen::MatrixXd momentum(t.size(), 6);
  momentum << r.Matrix("/energy/linear_momentum"), r.Matrix("/energy/angular_momentum");
  momentum_.Load(momentum, n, where + "/energy");
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const std::string g = "/bodies/" + scene_.body_names[b];
    modal_[b].Load(r.Matrix(g + "/modal_coordinates"), n, where + g + "/modal_coordinates");
    const Eigen::MatrixXd frame = r.Matrix(g + "/floating_frame"), com = r.Matrix(g + "/center_of_mass");
    Eigen::MatrixXd both(frame.rows(), 10);
    if (com.rows() != frame.rows() || frame.cols() != 7 || com.cols() != 3)
      throw InputError(where + g + ": floating frame and centre of mass do not match");
    both << frame, com;
    frames_[b].Load(both, n, where + g + "/floating_frame");
    if (scene_.spec.stresses && scene_.stresses[b] && r.Exists(g + "/max_von_mises")) {
      max_von_mises_.resize(model.bodies.size());
      max_von_mises_node_.resize(model.bodies.size());
      max_von_mises_[b] = head(r.Vector(g + "/max_von_mises"));
      const Eigen::VectorXi node = r.IntVector(g + "/max_von_mises_node");
      max_von_mises_node_[b].assign(node.data(), node.data() + n);
    }
  }
  // probes.csv's rows up to the mark, after the header this recorder wrote.
  std::ifstream in(csv_path_);
  std::string line;
  std::getline(in, line);
  if (!in) throw InputError(csv_path_ + ": cannot read");
  std::string header = "time";
  for (const std::string& c : probe_columns_) header += "," + c;
  header += ",kinetic_energy,elastic_energy,external_work";
  if (line != header) throw InputError(csv_path_ + ": its columns differ from the scene's probes");
  for (long i = 0; i < n; ++i) {
    if (!std::getline(in, line))
      throw InputError(csv_path_ + ": holds fewer rows than the checkpoint's " + std::to_string(n));
    csv_ << line << '\n';
  }
  // The animation's frames so far, in the files the checkpoint names.
  const Eigen::VectorXd frame_time = checkpoint.Vector("/recorder/frame_time");
  const std::vector<std::string> files = checkpoint.Strings("/recorder/frame_files");
  const Eigen::VectorXi file_of = checkpoint.IntVector("/recorder/frame_file"),
                        stress = checkpoint.IntVector("/recorder/frame_stress");
  if (frame_time.size() != n_frames || file_of.size() != n_frames || stress.size() != n_frames) {
    throw InputError(checkpoint.path() + ": /recorder's frames do not match");
  }
  for (long s = 0; s < n_frames; ++s) {
    if (file_of[s] < 0 || size_t(file_of[s]) >= files.size())
      throw InputError(checkpoint.path() + ": /recorder/frame_file out of range");
    frame_time_.push_back(frame_time[s]);
    frame_file_.push_back(files[size_t(file_of[s])]);
    frame_stress_fields_.push_back(char(stress[s] != 0));
  }
  frames_written_ = size_t(n_frames);
  animation_parts_ = checkpoint.Strings("/recorder/animation_parts");
  x0_ = checkpoint.Matrix("/recorder/x0").cast<float>();
  outputs_since_flush_ = 0;
}

void ResultsRecorder::ResumedAt(double t) {
  const auto take = [t](std::vector<double>& v) {
    if (!v.empty() && v.back() != t && std::abs(v.back() - t) <= 1e-12 * std::max(std::abs(t), 1.0)) v.back() = t;
  };
  take(time_);
  take(all_steps_t_);
  if (frames_written_ == frame_time_.size()) take(frame_time_);
}

}  // namespace femb
