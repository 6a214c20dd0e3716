// One run of a scene, from its spec to its results: what femb-solve does and what the Python
// module's Scene.run does, with the same defaults, checks and messages. The run reads what it
// starts from (a checkpoint to continue, another run's state) and checks it before anything is
// written, runs the analysis (static, dynamic or modes) and records its results: in memory, and
// into an output folder (results.h5, probes.csv, the animation, checkpoint.h5; written during the
// run and at its end) unless the run is asked to keep them in memory only.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <optional>
#include <string>

#include "formats/scene_file.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/output/results_recorder.h"
#include "solver/parallel.h"
#include "solver/scene/scene_builder.h"

namespace femb {

/// A force the caller writes (UserNodeForce), on a node named as in the scene.
struct UserForceSpec {
  std::string node;
  std::string other;  ///< a force between two nodes: the one its reaction acts on ("": none)
  UserNodeForce force;
};

/// A generalized force the caller writes (UserModalForce), on a body named as in the scene.
struct UserModalForceSpec {
  std::string body;
  UserModalForce force;
};

/// How a scene is run and where its words go.
struct SolveRunOptions {
  /// The output folder; empty: out/<scene name>, or none with `in_memory`.
  std::string output;
  /// Results in memory only: no folder, no files (a restart needs files: refused).
  bool in_memory = false;
  /// Continue the dynamic run whose results are in this folder from its checkpoint.
  std::string restart;
  /// Threads for the bodies' forces and matrices in dynamic analysis (same bits for any number).
  int threads = DefaultThreads();
  /// Progress lines (each without a program's prefix or newline); null: none.
  std::function<void(const std::string&)> progress;
  /// Warnings ("warning: ..."): said even when progress lines are not.
  std::function<void(const std::string&)> warning;
  /// Set (to a signal's number) to stop the run at the end of its step; null: never.
  const std::atomic<int>* stop = nullptr;
  /// Dynamic analyses: called after each step is taken and recorded, with the state it reached
  /// (the Python module's stepping under the caller's control waits here).
  std::function<void(const DynamicState&)> after_step;
  /// Forces the caller writes, added to the scene's loads.
  std::vector<UserForceSpec> user_forces;
  std::vector<UserModalForceSpec> user_modal_forces;
  /// When the run began (its reading time counts from here: the scene file was read before).
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
};

/// The exit codes of a run, as femb-solve returns them.
class SolveRun {
 public:
  /// Builds the scene (reads its superelement files). Bad input throws InputError.
  SolveRun(SceneSpec spec, SolveRunOptions options);
  SolveRun(const SolveRun&) = delete;
  SolveRun& operator=(const SolveRun&) = delete;

  /// Runs the analysis and writes its results; returns femb-solve's exit code: 0, 3 (numerical
  /// failure: error() says it), or 128 + the signal that stopped it. Bad input throws InputError
  /// before anything is written.
  int Run();
  /// After a run that did not complete: the line femb-solve writes to stderr (after its name).
  const std::string& error() const { return error_; }
  /// "completed", the failure's message, or where a signal stopped the run.
  const std::string& status() const { return status_; }
  const SceneSpec& spec() const { return spec_; }
  const Scene& scene() const { return scene_; }
  /// The results recorded (after Run).
  const ResultsRecorder& recorder() const { return *recorder_; }
  /// A run whose results were kept in memory (no output folder), after Run: writes its ParaView
  /// animation into `directory` (ResultsRecorder::WriteAnimation).
  void WriteAnimation(const std::string& directory) { recorder_->WriteAnimation(directory); }
  /// Steps taken (static: load steps) and Newton iterations over them.
  long steps() const { return step_count_; }
  long iterations() const { return total_iterations_; }
  /// modes analysis: the frequencies found (Hz).
  const Eigen::VectorXd& frequencies_hz() const { return frequencies_hz_; }

 private:
  bool is_static() const { return spec_.analysis.type == AnalysisType::kStatic; }
  bool quiet() const { return !options_.progress; }
  ResultsRecorder& recorder() { return *recorder_; }
  void Say(const char* format, ...) const __attribute__((format(printf, 2, 3)));
  void Warn(const std::string& line) const;
  std::string Kept() const;  ///< where a stopped or failed run's results are

  void ReadRestart();
  void ReadInitialState();
  void ResumeRecorder();
  void PrintSummary() const;
  void Take(const DynamicStepReport& report);
  const std::string& Signature();  ///< ModelSignature(scene_), made once when first needed
  void SaveCheckpoint(const DynamicState& state);
  void Flush(const DynamicState& state, bool force, const DynamicStepReport* report = nullptr);
  void Progress(double t, bool force);
  int RunModes();
  std::vector<Eigen::Matrix<double, 6, 1>> StaticReactions(double lambda, const SystemState& st,
                                                           const NodeForces* converged = nullptr) const;
  void RunStatic();
  DynamicOptions DynamicOptionsOf();
  DynamicState InitialDynamicState();
  void RunDynamic();
  void PrintDynamicCounts(const DynamicResult& r, const DynamicOptions& options) const;
  int Finish();

  SolveRunOptions options_;
  std::chrono::steady_clock::time_point wall_;
  const SceneSpec spec_;
  const Scene scene_;
  std::optional<DynamicResume> resume_;  ///< restart
  std::optional<DynamicState> from_;     ///< initial_state
  double t0_ = 0.0;                      ///< the time the run starts at
  std::optional<ResultsRecorder> recorder_;
  std::string signature_;  ///< Signature(): made on first use
  double read_seconds_ = 0.0;
  double run_write_seconds_ = 0.0;  // results and checkpoints written during the run (Flush)
  long step_count_ = 0, total_iterations_ = 0;
  long rejected_ = 0;  ///< steps rejected so far (step: auto)
  double last_print_ = -1.0;
  std::string status_ = "completed", error_;
  bool ok_ = true;
  bool no_checkpoint_ = false;  ///< a user function failed: no state to continue from
  int stopped_ = 0;             ///< the signal that stopped the analysis, or 0
  double stopped_at_ = 0.0;     ///< the time (static: load factor) it stopped at
  DynamicState final_state_;    ///< the state the analysis ended in (static: at rest)
  Eigen::VectorXd frequencies_hz_;
  // What a restart continues from (Take), with the results' mark and the counts there.
  std::optional<DynamicResume> saved_;
  ResultsRecorder::Mark mark_;
  long saved_steps_ = 0, saved_iterations_ = 0;
};

}  // namespace femb
