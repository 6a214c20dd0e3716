// Results of a simulation: an HDF5 file with every node's motion, the modal coordinates and
// floating frames of every body and the energies per output step, and a CSV of the requested
// probes that always ends with kinetic_energy,elastic_energy,external_work. Layout:
// formats/SCENE_FORMAT.md. When the superelement files hold meshes and mode shapes,
// animation.xdmf + animation.h5 give the deformed meshes of every output step for ParaView:
// x(X) = x_j + R_j (X - X_j + u(X)), u = shapes * q_loc.
//
// Written during the run (Flush, every outputs.flush_every seconds) and at its end (Finish, also
// after a numerical failure or a stop): each file whole under a temporary name, then renamed, so
// that a reader, or a run killed at any moment, finds complete files holding every output step
// up to the last write. During the run the animation's frames go to part files written once
// each (animation.part-N.h5, referenced by animation.xdmf); Finish gathers them into
// animation.h5.
#pragma once

#include <algorithm>
#include <chrono>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "formats/hdf5_file.h"
#include "solver/scene/scene_builder.h"

namespace femb {

/// A run's results in memory, what results.h5 holds (formats/SCENE_FORMAT.md): a row per output
/// step. Empty matrices where the run records nothing (reactions not asked for, no cut joints).
struct RecordedResults {
  std::string scene, analysis, units;  ///< the scene file, the analysis' type, the unit system
  Eigen::VectorXd time;
  Eigen::VectorXd step_size;  ///< the step that reached each output step (dynamic; else empty)
  std::vector<std::string> probe_names;
  Eigen::MatrixXd probes;                                         ///< a column per probe name, full precision
  Eigen::VectorXd steps_time, steps_size;                         ///< every step taken (dynamic)
  long steps_taken = -1, rejected_by_error = 0, newton_cuts = 0;  ///< -1: not counted (static)
  std::vector<std::string> cut_joints;
  Eigen::VectorXd loop_violation;  ///< with cut joints: a length
  Eigen::MatrixXd loop_reaction;   ///< with reactions: 6 per cut joint
  std::vector<std::string> node_names;
  /// Per node: 3, 4, 3, 3 and 6 columns (world axes; quaternions w, x, y, z).
  Eigen::MatrixXd position, quaternion, velocity, angular_velocity, reaction;
  std::vector<std::string> joint_coordinate_labels;
  Eigen::MatrixXd joint_coordinates;
  Eigen::VectorXd kinetic, elastic, external_work;
  Eigen::MatrixXd linear_momentum, angular_momentum;  ///< 3 columns each (about the origin)
  struct Body {
    std::string name;
    std::vector<std::string> nodes;
    Eigen::MatrixXd modal_coordinates;
    Eigen::MatrixXd floating_frame;  ///< x (3), quaternion (4)
    Eigen::MatrixXd center_of_mass;
    Eigen::VectorXd max_von_mises;  ///< with stresses: per output step, and its mesh node and point
    std::vector<int> max_von_mises_node;
    Eigen::MatrixXd max_von_mises_point;
  };
  std::vector<Body> bodies;
};

/// Writes `results` as results.h5 (formats/SCENE_FORMAT.md) to `path` with the run's `status`,
/// under a temporary name and renamed.
void WriteResultsFile(const RecordedResults& results, const std::string& status, const std::string& path);
/// Writes `results`' probes as probes.csv (time, the probe columns, the energies; 10 significant
/// digits) to `path`, under a temporary name and renamed.
void WriteProbesCsv(const RecordedResults& results, const std::string& path);

class ResultsRecorder {
 public:
  /// Creates `directory` if needed; opens results.h5 (at Finish) and probes.csv (streamed). An
  /// empty `directory`: the results are kept in memory only (no animation).
  ResultsRecorder(const Scene& scene, const std::string& directory);
  /// Without Finish (an input error before or during the run): the temporary CSV is removed.
  ~ResultsRecorder();
  ResultsRecorder(const ResultsRecorder&) = delete;
  ResultsRecorder& operator=(const ResultsRecorder&) = delete;
  /// Records one output step. W: velocities over the unknowns (zero for static analyses);
  /// momentum: linear and angular (about the origin) momentum of all bodies (dynamic analyses).
  /// `reactions`: per node (force, moment; JointReactions), recorded when the scene asks for them.
  /// `accelerations` (dynamic analyses): over the unknowns, for the inertia load cases' stresses
  /// (static analyses: none, only gravity).
  void Record(double t, const SystemState& state, const Eigen::VectorXd& W, double kinetic, double elastic,
              double external_work, const Eigen::Vector3d& linear_momentum = Eigen::Vector3d::Zero(),
              const Eigen::Vector3d& angular_momentum = Eigen::Vector3d::Zero(),
              const std::vector<Eigen::Matrix<double, 6, 1>>* reactions = nullptr,
              const Eigen::VectorXd* accelerations = nullptr);
  /// The step that reached the last recorded state (dynamic analyses; 0 for the initial state):
  /// /step_size in results.h5.
  void RecordStepSize(double h) { step_size_.push_back(h); }
  /// Every step taken (dynamic analyses): the time it reached and its size, /steps/time and
  /// /steps/size in results.h5.
  void RecordStep(double t, double h) {
    all_steps_t_.push_back(t);
    all_steps_h_.push_back(h);
  }
  /// Steps taken and rejected over the run: attributes of results.h5.
  void StepCounts(long taken, long rejected_by_error, long newton_cuts) {
    steps_taken_ = taken, rejected_by_error_ = rejected_by_error, newton_cuts_ = newton_cuts;
  }
  /// Whether a write during the run is due: outputs.flush_every seconds of wall time since the
  /// last one, unless the writes (the next one predicted from the last, as results.h5 grows)
  /// would then have taken more than 2% of the wall time so far; or outputs.flush_every_steps
  /// output steps.
  bool FlushDue() const;
  /// Writes results.h5 (its `status` says the run goes on, e.g. "running: t = 0.5 of 2"),
  /// probes.csv and the animation's frames since the last write (a new part file) under their
  /// final names.
  void Flush(const std::string& status);
  /// Writes results.h5, probes.csv and animation.h5 in their final form. `status` is stored
  /// ("completed", the failure message, or where a signal stopped the run).
  void Finish(const std::string& status);
  /// Results kept in memory (no directory given), after Finish: writes the ParaView animation of
  /// the run (animation.xdmf and animation.h5, the same as a run into `directory` writes) from
  /// the frames kept, a few numbers per body each. May be called again (another directory).
  void WriteAnimation(const std::string& directory);
  /// What a restart needs of the results so far (femb-solve --restart), taken when the run's
  /// state is saved (DynamicStepReport::capture): the output steps, steps and animation frames
  /// recorded up to that state, and the probes' unwrapping of angles.
  struct Mark {
    long outputs = 0, steps = 0, frames = 0;
    double next_frame_time = 0.0;
    std::vector<Eigen::VectorXd> probe_last;
  };
  Mark TakeMark() const;
  /// Writes `mark` with where the animation's frames are (group /recorder of a checkpoint; after
  /// Flush or Finish, when every frame up to the mark is in a file).
  void WriteMark(h5::Writer& w, const Mark& mark) const;
  /// Continues the results already in the output folder from a checkpoint's /recorder group: the
  /// series of results.h5 and the rows of probes.csv up to its mark (later ones, written after
  /// the checkpoint's state, are dropped), and the animation's frames. One line (InputError)
  /// when the folder's files do not hold them or the scene's outputs differ from the run's.
  void Resume(const h5::Reader& checkpoint);
  /// The continued run's time t: a last recorded time that the run's end rounded to end_time (a
  /// fixed step's t_base + n h, within round-off) takes t, as the longer run records it.
  void ResumedAt(double t);
  /// Writes during the run so far: their number and their wall time in seconds.
  long flushes() const { return flushes_; }
  double flush_seconds() const { return flush_seconds_; }
  const std::string& csv_path() const { return csv_path_; }
  const std::string& h5_path() const { return h5_path_; }
  long steps() const { return long(time_.size()); }
  /// With outputs.stresses: per body with stresses, its largest von Mises stress over the run,
  /// when and where ("body 'bar': largest von Mises stress 45.7 MPa at t = 1, mesh node 12 at
  /// (0.05, 0.05, 0.026) in part axes").
  std::vector<std::string> StressSummary() const;
  /// The results recorded so far.
  RecordedResults Results() const;
  /// Closed loops: the largest violation of the cut joints' equations over the recorded steps
  /// (LoopViolation: a length); 0 without loops.
  double max_loop_violation() const { return max_loop_violation_; }

 private:
  // Record's stages. OutputStep: what one output step's fields and probes derive from its state,
  // made when first asked for; NodeRows: the node series' rows just appended; ProbeRow: the
  // probes' row being written and its next column.
  class OutputStep;
  struct NodeRows {
    double *pos, *quat, *vel, *ang;
  };
  struct ProbeRow {
    double* values;
    int column;
  };
  NodeRows RecordSeries(double t, const SystemState& state, const Eigen::VectorXd& W, double kinetic, double elastic,
                        double external_work, const Eigen::Vector3d& linear_momentum,
                        const Eigen::Vector3d& angular_momentum,
                        const std::vector<Eigen::Matrix<double, 6, 1>>* reactions);
  void RecordBodies(const SystemState& state);
  void RecordJoints(const SystemState& state);
  bool AnimationFrame(double t);
  void QueueFields(const SystemState& state, bool frame, OutputStep& step);
  void PutProbe(ProbeRow& row, double v);
  void WriteProbes(const SystemState& state, const NodeRows& nodes,
                   const std::vector<Eigen::Matrix<double, 6, 1>>* reactions, OutputStep& step, ProbeRow& row);
  void WritePointProbe(size_t probe, const SystemState& state, OutputStep& step, ProbeRow& row);
  void WriteNodeProbe(size_t probe, const SystemState& state, const NodeRows& nodes,
                      const std::vector<Eigen::Matrix<double, 6, 1>>* reactions, OutputStep& step, ProbeRow& row);
  void WriteJointProbe(size_t probe, int node, const SystemState& state, ProbeRow& row);
  /// The reaction at node k, component i (zero without `reactions`).
  static double Reaction(const std::vector<Eigen::Matrix<double, 6, 1>>* reactions, int k, int i) {
    return reactions ? (*reactions)[size_t(k)][i] : 0.0;
  }

  const Scene& scene_;
  const DofMap dofs_;          ///< the scene model's numbering (the model does not change while recording)
  const bool files_;           ///< results written to files (else kept in memory only)
  int animation_every_ = 1;    ///< one animation frame per this many output steps (spec, or auto)
  double frame_interval_ = 0;  ///< > 0: one animation frame per this much time (auto, with step: auto)
  double next_frame_time_ = 0;
  std::vector<double> step_size_, all_steps_t_, all_steps_h_;
  long steps_taken_ = -1, rejected_by_error_ = 0, newton_cuts_ = 0;
  std::string directory_, csv_path_, h5_path_, csv_tmp_;
  std::ofstream csv_;
  std::vector<double> time_, kinetic_, elastic_, work_, loop_violation_;
  double max_loop_violation_ = 0.0;
  // Rows of one width, one per output step (the per-step vectors these replaced cost ~170
  // allocations an output step: 18% of the 10-body slider-crank's run), in chunks of about 64 KB
  // that never move: a step's row costs no copy of the earlier ones (one flat vector copied and
  // zero-filled the whole series at each doubling; a profile put 4% of the samples there, the
  // wall time moved within noise).
  struct Rows {
    int width = 0;
    long count = 0;
    std::vector<std::unique_ptr<double[]>> chunks;
    double* Append();                ///< the new row, zero-filled
    Eigen::MatrixXd Matrix() const;  ///< count x width
    /// Appends the first n rows of m (its width checked; `what` names it in the error).
    void Load(const Eigen::MatrixXd& m, long n, const std::string& what);

   private:
    long ChunkRows() const { return std::max(1L, 8192L / std::max(width, 1)); }
  };
  Rows loop_reactions_;  ///< per output step, 6 per cut joint (with reactions)
  // probes.csv's probe columns in full precision: results.h5 /probes/names and /probes/values.
  std::vector<std::string> probe_columns_;
  Rows probe_values_;
  // Per probe: the cut joint whose coordinates a `joint` probe shows (its node has none of its
  // own), or -1; and their last values (angles unwrapped to be continuous).
  std::vector<int> probe_cut_;
  std::vector<Eigen::VectorXd> probe_last_;
  Rows momentum_;  // per step: linear (3), angular (3)
  Rows positions_, quaternions_, velocities_, angular_velocities_, joints_, reactions_;
  std::vector<Rows> modal_;   // per body, per step
  std::vector<Rows> frames_;  // per body, per step: x (3), quaternion (4), centre of mass (3)
  // An output step's per-body values, kept from step to step (storage reused).
  BodyConfiguration config_;
  std::vector<Eigen::VectorXd> q_loc_, q_stress_, factors_;
  std::vector<char> has_stress_coordinates_, has_factors_;
  std::vector<char> joint_node_;  ///< JointNode(k), per node
  // Per animation frame (every animation_every-th output step): its time.
  std::vector<double> frame_time_;
  // Stress recovery (outputs.stresses): per body with modal stresses, per output step the largest
  // von Mises stress and its mesh node.
  std::vector<std::vector<double>> max_von_mises_;
  std::vector<std::vector<int>> max_von_mises_node_;
  // The fields of an output step (the largest stresses; on animation frames the node fields:
  // positions, deformation, displacement, stresses) are made when written, on the machine's
  // cores (MakePending): Record keeps what they need, a few numbers per body.
  struct PendingOutput {
    long output = 0;                       ///< the output step's index
    long frame = -1;                       ///< its animation frame's index, or -1
    std::vector<Eigen::Vector3d> frame_x;  ///< per body, its floating frame (global, relative to origin)
    std::vector<Eigen::Matrix3d> frame_R;
    std::vector<Eigen::VectorXd> q_loc;     ///< per body with a mesh (frames)
    std::vector<Eigen::MatrixXf> sticks;    ///< per body without a mesh: its stick nodes' positions (frames)
    std::vector<Eigen::VectorXd> q_stress;  ///< per body with stresses: StressCoordinates
    std::vector<Eigen::VectorXd> factors;   ///< and its inertia load factors (empty: none)
  };
  std::vector<PendingOutput> pending_;
  /// Results kept in memory: the animation frames' jobs, made only when WriteAnimation asks.
  std::vector<PendingOutput> memory_frames_;
  bool writing_memory_frames_ = false;
  // A frame made and packed (compressed), waiting for its file.
  struct PackedFrame {
    std::vector<h5::PackedFloats> fields;
    bool stress = false;
  };
  std::vector<PackedFrame> packed_frames_;
  struct FieldWorkspace;  // one per thread (results_animation.cpp)
  /// Makes the pending output steps' fields (the largest stresses into max_von_mises_, the frames
  /// into packed_frames_) and forgets them.
  void MakePending();
  PackedFrame MakeFields(const PendingOutput& job, FieldWorkspace& ws);
  // Writing during the run (Flush).
  double flush_every_ = 10.0;
  long flush_every_steps_ = 0, outputs_since_flush_ = 0, flushes_ = 0;
  long outputs_at_last_flush_ = 0;
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now(), last_flush_ = started_;
  double last_flush_cost_ = 0.0, last_growing_cost_ = 0.0, flush_seconds_ = 0.0;
  // The animation's grid (every body's mesh or stick figure; built at the first frame written)
  // and where each frame is: frame_time_ holds every frame's time, pending_ and packed_frames_
  // the frames not yet written (from frames_written_ on).
  struct AnimationGrid {
    bool uniform = true;
    CellType cell_type = CellType::kLine2;  ///< of every cell (uniform)
    int per_cell = 0;                       ///< nodes per cell (uniform)
    long n_nodes = 0, n_cells = 0;
    Eigen::MatrixXi cells;     ///< uniform: n_cells x per_cell
    std::vector<int> flat;     ///< mixed: (XDMF type, [count,] nodes...) per cell
    Eigen::MatrixXd body;      ///< per cell, its body's index
    std::vector<long> offset;  ///< per body, its first node in the grid
    /// Per body, the mesh node (or stick node) at each of its grid nodes: solid and shell meshes
    /// in spatial (Morton) order, which neighbours' values compress better in; lines in order.
    std::vector<std::vector<int>> node_of;
    std::vector<int> node;  ///< per grid node, its node in its body's mesh (the field `node`)
  };
  std::unique_ptr<AnimationGrid> grid_;
  size_t frames_written_ = 0;
  std::vector<std::string> frame_file_;       ///< per written frame, the file (in directory_) holding it
  std::vector<char> frame_stress_fields_;     ///< per written frame, whether it has stress fields
  std::vector<std::string> animation_parts_;  ///< part files written during the run
  Eigen::MatrixXf x0_;                        ///< the first frame's stored positions (displacement = x - x0)
  const AnimationGrid& Grid();
  /// Writes the packed frames into `w` (the file `file` in directory_) and forgets them.
  void WriteFrames(h5::Writer& w, const std::string& file);
  void WriteMesh(h5::Writer& w);
  void WriteXdmf(const std::string& mesh_file);
  void WriteAnimationPart();
  void FinishAnimation();
  void WriteResults(const std::string& status);
  bool JointNode(int k) const;
};

}  // namespace femb
