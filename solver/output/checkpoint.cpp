#include "solver/output/checkpoint.h"

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "formats/hdf5_file.h"
#include "formats/input_error.h"
#include "solver/joints/joint_tree.h"

namespace femb {
namespace {

constexpr const char* kFormat = "femb-checkpoint";
constexpr const char* kVersion = "1.0";

// FNV-1a (64 bits) of a file's bytes: tells two superelement files apart.
std::uint64_t FileHash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::uint64_t h = 1469598103934665603ULL;
  char buffer[1 << 16];
  while (in) {
    in.read(buffer, sizeof buffer);
    for (std::streamsize i = 0; i < in.gcount(); ++i) h = (h ^ std::uint8_t(buffer[i])) * 1099511628211ULL;
  }
  return h;
}

// Per-item vectors of varying length (joint coordinates per node, modal coordinates per body)
// as one flat vector.
Eigen::VectorXd Flat(const std::vector<Eigen::VectorXd>& parts) {
  long n = 0;
  for (const Eigen::VectorXd& p : parts) n += p.size();
  Eigen::VectorXd out(n);
  n = 0;
  for (const Eigen::VectorXd& p : parts) out.segment(n, p.size()) = p, n += p.size();
  return out;
}

Eigen::MatrixXd Rows3(const std::vector<Eigen::Vector3d>& v) {
  Eigen::MatrixXd out(long(v.size()), 3);
  for (size_t i = 0; i < v.size(); ++i) out.row(long(i)) = v[i].transpose();
  return out;
}

Eigen::MatrixXd Rows9(const std::vector<Eigen::Matrix3d>& v) {
  Eigen::MatrixXd out(long(v.size()), 9);
  for (size_t i = 0; i < v.size(); ++i) out.row(long(i)) = Eigen::Map<const Eigen::Matrix<double, 1, 9>>(v[i].data());
  return out;
}

// Numbers (counts too: exact as doubles below 2^53) of the resume group, by name.
void WriteExactState(h5::Writer& w, const std::string& g, const DynamicState& s) {
  const SystemState& c = s.config;
  w.CreateGroup(g);
  w.Vector(g + "/joint_coordinates", Flat(c.z));
  w.Matrix(g + "/node_position", Rows3(c.x));
  w.Matrix(g + "/node_rotation", Rows9(c.R));
  w.Vector(g + "/modal_coordinates", Flat(c.eta));
  std::vector<Eigen::Vector3d> fx;
  std::vector<Eigen::Matrix3d> fR;
  std::vector<int> iterations;
  for (const FrameSolution& f : c.frames) fx.push_back(f.x), fR.push_back(f.R), iterations.push_back(f.iterations);
  w.Matrix(g + "/frame_position", Rows3(fx));
  w.Matrix(g + "/frame_rotation", Rows9(fR));
  w.IntVector(g + "/frame_iterations", iterations);
  w.Vector(g + "/multipliers", c.lambda);
  w.Vector(g + "/velocities", s.W);
  w.Vector(g + "/accelerations", s.Wdot);
  w.Vector(g + "/algorithmic_accelerations", s.a);
  w.Vector(g + "/external_forces", s.f_ext);
  w.Vector(g + "/drive_forces", s.f_drive);
  Eigen::MatrixXd node_w(long(s.node_w.size()), 6);
  for (size_t k = 0; k < s.node_w.size(); ++k) node_w.row(long(k)) = s.node_w[k].transpose();
  w.Matrix(g + "/node_velocities", node_w);
  w.Vector(g + "/numbers", (Eigen::VectorXd(4) << s.t, s.external_work, s.drive_work, s.h_last).finished());
  if (s.increments_kept > 0) {
    // Generalized-alpha's last increments (error-controlled steps), one row each, oldest first.
    constexpr long N = DynamicState::kIncrements;
    Eigen::MatrixXd increments(N, s.increments[N - 1].size());
    Eigen::VectorXd steps(N + 1);
    for (long i = 0; i < N; ++i) {
      increments.row(i) = s.increments[size_t(i)].transpose();
      steps[i] = s.increment_steps[size_t(i)];
    }
    steps[N] = double(s.increments_kept);
    w.Matrix(g + "/increments", increments);
    w.Vector(g + "/increment_steps", steps);
  }
}

void WriteResume(h5::Writer& w, const DynamicResume& r) {
  w.CreateGroup("/resume");
  WriteExactState(w, "/resume/state", r.state);
  const DynamicResult& x = r.result;
  w.Vector("/resume/numbers",
           (Eigen::VectorXd(32) << r.t_start, r.h, r.t_base, r.last_output, r.E0, r.energy_scale, r.first_cut_time,
            double(r.n_nominal), double(r.cuts), double(r.warned), r.travel, r.last_error, double(r.has_last_jerk),
            double(r.factorizations), double(r.matrices_computed), double(r.matrices_turned), double(x.steps),
            double(x.rejected_by_error), double(x.newton_cuts), x.smallest_step, x.largest_step, x.smallest_step_time,
            double(x.newton_iterations), double(x.factorizations), double(x.pattern_analyses), double(x.pivoted),
            double(x.body_matrices_computed), double(x.body_matrices_turned), r.planned_step, r.kept_step,
            double(r.proposal), double(r.settled))
               .finished());
  w.Strings("/resume/warnings", x.warnings);
  w.Vector("/resume/last_jerk", r.last_jerk);
  w.IntVector("/resume/factor_outer", r.factor.outer);
  w.IntVector("/resume/factor_inner", r.factor.inner);
  w.Vector("/resume/factor_pivot_values",
           Eigen::Map<const Eigen::VectorXd>(r.factor.pivot_values.data(), long(r.factor.pivot_values.size())));
  w.Vector("/resume/factor_counts",
           Eigen::Vector3d(double(r.factor.analysed), double(r.factor.full), double(r.factor.refactored)));
  Eigen::MatrixXd S_inv(long(r.frame_S_inv.size()), 36);
  for (size_t b = 0; b < r.frame_S_inv.size(); ++b)
    S_inv.row(long(b)) = Eigen::Map<const Eigen::Matrix<double, 1, 36>>(r.frame_S_inv[b].data());
  w.Matrix("/resume/frame_S_inv", S_inv);
  w.IntVector("/resume/has_frame_S_inv", std::vector<int>(r.has_frame_S_inv.begin(), r.has_frame_S_inv.end()));
  w.IntVector("/resume/kept_age", r.kept_age);
  for (size_t b = 0; b < r.kept_age.size(); ++b) {
    const std::string g = "/resume/kept_" + std::to_string(b);
    w.CreateGroup(g);
    w.Matrix(g + "/M", r.kept_M[b]);
    w.Matrix(g + "/C", r.kept_C[b]);
    w.Matrix(g + "/K", r.kept_K[b]);
  }
  w.IntVector("/resume/closure_fresh", std::vector<int>(r.closure_dc_fresh.begin(), r.closure_dc_fresh.end()));
  for (size_t b = 0; b < r.closure_dc.size(); ++b) {
    if (r.closure_dc_fresh[b]) w.Matrix("/resume/closure_dc_" + std::to_string(b), r.closure_dc[b]);
  }
}

}  // namespace

std::string ModelSignature(const Scene& scene) {
  const SystemModel& model = scene.model;
  const std::filesystem::path base = std::filesystem::path(scene.spec.file).parent_path();
  std::ostringstream out;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    out << "body " << scene.body_names[b] << " coordinates " << model.bodies[b].n_coordinates();
    if (b < scene.spec.bodies.size() && !scene.spec.bodies[b].superelement.empty()) {
      std::filesystem::path file(scene.spec.bodies[b].superelement);
      if (file.is_relative()) file = base / file;
      char hash[32];
      std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(FileHash(file.string())));
      out << " file " << file.filename().string() << " " << hash;
    }
    out << "\n";
  }
  const DofMap& dofs = model.dofs();
  for (int k = 0; k < model.n_nodes(); ++k)
    out << "node " << model.node_names[size_t(k)] << " " << dofs.node_count(k) << "\n";
  for (const NodeJoint& j : model.joints) out << "joint " << int(j.type) << " " << j.child << " " << j.parent << "\n";
  for (const CutJoint& c : model.cut_joints) out << "cut joint " << c.name << " " << c.equations.size() << "\n";
  out << "unknowns " << dofs.n_dofs() << "\n";
  return out.str();
}

void WriteCheckpoint(const std::string& directory, const Scene& scene, const std::string& signature,
                     const DynamicState& state, AnalysisType analysis, const DynamicResume* resume,
                     const std::function<void(h5::Writer&)>& extra) {
  const std::string path = (std::filesystem::path(directory) / "checkpoint.h5").string();
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    h5::Writer w(tmp);
    w.Attribute("/", "format", kFormat);
    w.Attribute("/", "format_version", kVersion);
    w.Attribute("/", "scene", scene.spec.file);
    w.Attribute("/", "analysis", std::string(Name(analysis)));
    w.Attribute("/", "model", signature);
    // A static state has no velocities: zero.
    DynamicState full;
    const DynamicState* s = &state;
    const long n = scene.model.dofs().n_dofs();
    if (state.W.size() != n || state.Wdot.size() != n || state.a.size() != n) {
      full = state;
      for (Eigen::VectorXd* v : {&full.W, &full.Wdot, &full.a})
        if (v->size() != n) v->setZero(n);
      s = &full;
    }
    WriteExactState(w, "/state", *s);
    if (resume) WriteResume(w, *resume);
    if (extra) extra(w);
    w.Close();
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InputError(path + ": cannot rename into place (" + ec.message() + ")");
}

namespace {

// The checkpoint of `directory`, checked: a femb checkpoint of a version this femb reads,
// written for `scene`'s model (else one line naming the first difference).
h5::Reader OpenCheckpoint(const std::string& directory, const Scene& scene, const std::string& signature) {
  const std::string path = (std::filesystem::path(directory) / "checkpoint.h5").string();
  if (!std::filesystem::exists(path)) {
    throw InputError(path + ": no checkpoint (a folder femb-solve wrote its results to holds one)");
  }
  h5::Reader r(path);
  if (!r.HasAttribute("/", "format") || r.StringAttribute("/", "format") != kFormat) {
    throw InputError(path + ": not a femb checkpoint (attribute format is not " + kFormat + ")");
  }
  const std::string version = r.StringAttribute("/", "format_version");
  if (version.substr(0, version.find('.')) != std::string(kVersion).substr(0, 1)) {
    throw InputError(path + ": checkpoint format_version " + version + ", this femb reads " + kVersion);
  }
  std::istringstream theirs(r.StringAttribute("/", "model")), ours(signature);
  std::string a, b;
  while (true) {
    const bool more_a = bool(std::getline(theirs, a)), more_b = bool(std::getline(ours, b));
    if (!more_a && !more_b) break;
    if (!more_a || !more_b || a != b) {
      throw InputError(path + ": written for another model: it has '" + (more_a ? a : "(nothing)") + "' where " +
                       scene.spec.file + " has '" + (more_b ? b : "(nothing)") + "'");
    }
  }
  return r;
}

// The state of group g, to the bit, with its node Jacobians; sizes checked against the model.
DynamicState ReadState(const h5::Reader& r, const std::string& g, const SystemModel& model) {
  const DofMap& dofs = model.dofs();
  DynamicState s;
  s.config = InitialState(model);
  SystemState& c = s.config;
  const auto need = [&](const std::string& name, long rows, long cols) {
    const std::vector<hsize_t> shape = r.Shape(g + name);
    const bool ok = cols < 0 ? shape.size() == 1 && long(shape[0]) == rows
                             : shape.size() == 2 && long(shape[0]) == rows && long(shape[1]) == cols;
    if (!ok) throw InputError(r.path() + ": dataset " + g + name + " does not have the model's size");
  };
  long nz = 0, neta = 0;
  for (const Eigen::VectorXd& z : c.z) nz += z.size();
  for (const Eigen::VectorXd& e : c.eta) neta += e.size();
  const long n_nodes = model.n_nodes(), n_bodies = long(model.bodies.size()), n = dofs.n_dofs();
  need("/joint_coordinates", nz, -1);
  need("/node_position", n_nodes, 3);
  need("/node_rotation", n_nodes, 9);
  need("/modal_coordinates", neta, -1);
  need("/frame_position", n_bodies, 3);
  need("/frame_rotation", n_bodies, 9);
  need("/frame_iterations", n_bodies, -1);
  need("/multipliers", dofs.n_multipliers(), -1);
  for (const char* v : {"/velocities", "/accelerations", "/algorithmic_accelerations"}) need(v, n, -1);
  need("/numbers", 4, -1);
  const Eigen::VectorXd z = r.Vector(g + "/joint_coordinates"), eta = r.Vector(g + "/modal_coordinates");
  const Eigen::MatrixXd x = r.Matrix(g + "/node_position"), R = r.Matrix(g + "/node_rotation");
  const Eigen::MatrixXd fx = r.Matrix(g + "/frame_position"), fR = r.Matrix(g + "/frame_rotation");
  const Eigen::VectorXi iterations = r.IntVector(g + "/frame_iterations");
  long at = 0;
  for (Eigen::VectorXd& zk : c.z) zk = z.segment(at, zk.size()), at += zk.size();
  at = 0;
  for (Eigen::VectorXd& e : c.eta) e = eta.segment(at, e.size()), at += e.size();
  const auto rotation = [](const Eigen::MatrixXd& m, long i) {
    const Eigen::Matrix<double, 1, 9> row = m.row(i);
    return Eigen::Matrix3d(Eigen::Map<const Eigen::Matrix3d>(row.data()));
  };
  for (long k = 0; k < n_nodes; ++k) c.x[size_t(k)] = x.row(k).transpose(), c.R[size_t(k)] = rotation(R, k);
  for (long b = 0; b < n_bodies; ++b) {
    FrameSolution& f = c.frames[size_t(b)];
    f.x = fx.row(b).transpose(), f.R = rotation(fR, b), f.iterations = iterations[b], f.ok = true;
  }
  c.lambda = r.Vector(g + "/multipliers");
  s.W = r.Vector(g + "/velocities");
  s.Wdot = r.Vector(g + "/accelerations");
  s.a = r.Vector(g + "/algorithmic_accelerations");
  s.f_ext = r.Vector(g + "/external_forces");
  s.f_drive = r.Vector(g + "/drive_forces");
  const Eigen::MatrixXd node_w = r.Matrix(g + "/node_velocities");
  if (node_w.cols() != 6 || (node_w.rows() != 0 && node_w.rows() != n_nodes)) {
    throw InputError(r.path() + ": dataset " + g + "/node_velocities does not have the model's size");
  }
  for (long k = 0; k < node_w.rows(); ++k) s.node_w.push_back(node_w.row(k).transpose());
  const Eigen::VectorXd numbers = r.Vector(g + "/numbers");
  s.t = numbers[0], s.external_work = numbers[1], s.drive_work = numbers[2], s.h_last = numbers[3];
  if (r.Exists(g + "/increments")) {
    constexpr long N = DynamicState::kIncrements;
    need("/increments", N, n);
    need("/increment_steps", N + 1, -1);
    const Eigen::MatrixXd increments = r.Matrix(g + "/increments");
    const Eigen::VectorXd steps = r.Vector(g + "/increment_steps");
    for (long i = 0; i < N; ++i) {
      s.increments[size_t(i)] = increments.row(i).transpose();
      s.increment_steps[size_t(i)] = steps[i];
    }
    s.increments_kept = std::clamp(int(steps[N]), 0, int(N));
  }
  UpdateKinematics(model, dofs, c);
  return s;
}

}  // namespace

DynamicState ReadCheckpoint(const std::string& directory, const Scene& scene, const std::string& signature,
                            AnalysisType* analysis) {
  const h5::Reader r = OpenCheckpoint(directory, scene, signature);
  if (analysis) {
    const std::string word = r.StringAttribute("/", "analysis");
    const std::optional<AnalysisType> type = KindOf<AnalysisType>(word);
    if (!type) throw InputError(r.path() + ": the analysis '" + word + "' is not one femb writes");
    *analysis = *type;
  }
  return ReadState(r, "/state", scene.model);
}

bool ReadResume(const std::string& directory, const Scene& scene, const std::string& signature, DynamicResume& resume) {
  const h5::Reader r = OpenCheckpoint(directory, scene, signature);
  if (!r.Exists("/resume")) return false;
  const SystemModel& model = scene.model;
  resume.state = ReadState(r, "/state", model);
  const Eigen::VectorXd x = r.Vector("/resume/numbers");
  if (x.size() != 28 && x.size() != 32)  // (28: a checkpoint without the step controller's plan)
    throw InputError(r.path() + ": dataset /resume/numbers has " + std::to_string(x.size()) + " values, not 32");
  resume.t_start = x[0], resume.h = x[1], resume.t_base = x[2], resume.last_output = x[3], resume.E0 = x[4];
  resume.energy_scale = x[5], resume.first_cut_time = x[6], resume.n_nominal = long(x[7]), resume.cuts = int(x[8]);
  resume.warned = x[9] != 0, resume.travel = x[10], resume.last_error = x[11], resume.has_last_jerk = x[12] != 0;
  resume.factorizations = long(x[13]), resume.matrices_computed = long(x[14]), resume.matrices_turned = long(x[15]);
  DynamicResult& result = resume.result;
  result.steps = long(x[16]), result.rejected_by_error = long(x[17]), result.newton_cuts = long(x[18]);
  result.smallest_step = x[19], result.largest_step = x[20], result.smallest_step_time = x[21];
  result.newton_iterations = long(x[22]), result.factorizations = long(x[23]), result.pattern_analyses = long(x[24]);
  result.pivoted = long(x[25]), result.body_matrices_computed = long(x[26]), result.body_matrices_turned = long(x[27]);
  if (x.size() == 32) {
    resume.planned_step = x[28], resume.kept_step = x[29], resume.proposal = x[30] != 0;
    resume.settled = int(x[31]);
  }
  result.warnings = r.Strings("/resume/warnings");
  resume.last_jerk = r.Vector("/resume/last_jerk");
  const Eigen::VectorXi outer = r.IntVector("/resume/factor_outer"), inner = r.IntVector("/resume/factor_inner");
  resume.factor.outer.assign(outer.data(), outer.data() + outer.size());
  resume.factor.inner.assign(inner.data(), inner.data() + inner.size());
  const Eigen::VectorXd pivots = r.Vector("/resume/factor_pivot_values");
  resume.factor.pivot_values.assign(pivots.data(), pivots.data() + pivots.size());
  const Eigen::VectorXd counts = r.Vector("/resume/factor_counts");
  if (counts.size() != 3) throw InputError(r.path() + ": dataset /resume/factor_counts must hold 3 values");
  resume.factor.analysed = long(counts[0]), resume.factor.full = long(counts[1]),
  resume.factor.refactored = long(counts[2]);
  const long n_bodies = long(model.bodies.size());
  const Eigen::MatrixXd S_inv = r.Matrix("/resume/frame_S_inv");
  const Eigen::VectorXi has = r.IntVector("/resume/has_frame_S_inv");
  if (S_inv.rows() != n_bodies || S_inv.cols() != 36 || has.size() != n_bodies) {
    throw InputError(r.path() + ": /resume/frame_S_inv does not have the model's size");
  }
  resume.frame_S_inv.resize(size_t(n_bodies));
  resume.has_frame_S_inv.resize(size_t(n_bodies));
  for (long b = 0; b < n_bodies; ++b) {
    const Eigen::Matrix<double, 1, 36> row = S_inv.row(b);
    resume.frame_S_inv[size_t(b)] = Eigen::Map<const Eigen::Matrix<double, 6, 6>>(row.data());
    resume.has_frame_S_inv[size_t(b)] = char(has[b] != 0);
  }
  const Eigen::VectorXi age = r.IntVector("/resume/kept_age");
  if (age.size() != 0 && age.size() != n_bodies)
    throw InputError(r.path() + ": /resume/kept_age does not have the model's size");
  resume.kept_age.assign(age.data(), age.data() + age.size());
  resume.kept_M.clear(), resume.kept_C.clear(), resume.kept_K.clear();
  for (long b = 0; b < age.size(); ++b) {
    const std::string g = "/resume/kept_" + std::to_string(b);
    resume.kept_M.push_back(r.Matrix(g + "/M"));
    resume.kept_C.push_back(r.Matrix(g + "/C"));
    resume.kept_K.push_back(r.Matrix(g + "/K"));
  }
  // The midpoint scheme's energy closures (absent from an older checkpoint: computed anew).
  resume.closure_dc.clear(), resume.closure_dc_fresh.clear();
  if (r.Exists("/resume/closure_fresh")) {
    const Eigen::VectorXi fresh = r.IntVector("/resume/closure_fresh");
    if (fresh.size() != 0 && fresh.size() != n_bodies)
      throw InputError(r.path() + ": /resume/closure_fresh does not have the model's size");
    for (long b = 0; b < fresh.size(); ++b) {
      const std::string name = "/resume/closure_dc_" + std::to_string(b);
      resume.closure_dc_fresh.push_back(char(fresh[b] != 0 && r.Exists(name)));
      resume.closure_dc.push_back(resume.closure_dc_fresh.back() ? r.Matrix(name) : Eigen::MatrixXd());
    }
    // Written with the last step's iteration count, the flags are from before the next step's
    // start decided on them: 4 or more (or -1, not converged) drops the derivatives.
    if (r.Exists("/resume/closure_last_iterations")) {
      const Eigen::VectorXi last = r.IntVector("/resume/closure_last_iterations");
      if (last.size() != 1 || last[0] < 0 || last[0] >= 4) {
        for (char& fresh_b : resume.closure_dc_fresh) fresh_b = 0;
      }
    }
  }
  return true;
}

}  // namespace femb
