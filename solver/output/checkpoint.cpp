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
  for (int k = 0; k < model.n_nodes(); ++k) out << "node " << model.node_names[size_t(k)] << " " << dofs.node_count(k) << "\n";
  for (const NodeJoint& j : model.joints) out << "joint " << int(j.type) << " " << j.child << " " << j.parent << "\n";
  for (const CutJoint& c : model.cut_joints) out << "cut joint " << c.name << " " << c.equations.size() << "\n";
  out << "unknowns " << dofs.n_dofs() << "\n";
  return out.str();
}

void WriteCheckpoint(const std::string& directory, const Scene& scene, const std::string& signature,
                     const DynamicState& state, const std::string& analysis) {
  const std::string path = (std::filesystem::path(directory) / "checkpoint.h5").string();
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  const SystemState& c = state.config;
  {
    h5::Writer w(tmp);
    w.Attribute("/", "format", kFormat);
    w.Attribute("/", "format_version", kVersion);
    w.Attribute("/", "scene", scene.spec.file);
    w.Attribute("/", "analysis", analysis);
    w.Attribute("/", "model", signature);
    w.Scalar("/time", state.t);
    w.Vector("/joint_coordinates", Flat(c.z));
    w.Matrix("/node_position", Rows3(c.x));
    w.Matrix("/node_rotation", Rows9(c.R));
    w.Vector("/modal_coordinates", Flat(c.eta));
    std::vector<Eigen::Vector3d> fx;
    std::vector<Eigen::Matrix3d> fR;
    for (const FrameSolution& f : c.frames) fx.push_back(f.x), fR.push_back(f.R);
    w.Matrix("/frame_position", Rows3(fx));
    w.Matrix("/frame_rotation", Rows9(fR));
    w.Vector("/multipliers", c.lambda);
    const long n = scene.model.dofs().n_dofs();
    const auto or_zero = [n](const Eigen::VectorXd& v) { return v.size() == n ? v : Eigen::VectorXd(Eigen::VectorXd::Zero(n)); };
    w.Vector("/velocities", or_zero(state.W));
    w.Vector("/accelerations", or_zero(state.Wdot));
    w.Vector("/algorithmic_accelerations", or_zero(state.a));
    w.Scalar("/external_work", state.external_work);
    w.Scalar("/drive_work", state.drive_work);
    w.Scalar("/step", state.h_last);
    w.Close();
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InputError(path + ": cannot rename into place (" + ec.message() + ")");
}

DynamicState ReadCheckpoint(const std::string& directory, const Scene& scene, std::string* analysis) {
  const std::string path = (std::filesystem::path(directory) / "checkpoint.h5").string();
  if (!std::filesystem::exists(path)) {
    throw InputError(path + ": no checkpoint (a folder femb-solve wrote its results to holds one)");
  }
  const h5::Reader r(path);
  if (!r.HasAttribute("/", "format") || r.StringAttribute("/", "format") != kFormat) {
    throw InputError(path + ": not a femb checkpoint (attribute format is not " + kFormat + ")");
  }
  const std::string version = r.StringAttribute("/", "format_version");
  if (version.substr(0, version.find('.')) != std::string(kVersion).substr(0, 1)) {
    throw InputError(path + ": checkpoint format_version " + version + ", this femb reads " + kVersion);
  }
  // The same model: the first line that differs.
  std::istringstream theirs(r.StringAttribute("/", "model")), ours(ModelSignature(scene));
  std::string a, b;
  while (true) {
    const bool more_a = bool(std::getline(theirs, a)), more_b = bool(std::getline(ours, b));
    if (!more_a && !more_b) break;
    if (!more_a || !more_b || a != b) {
      throw InputError(path + ": written for another model: it has '" + (more_a ? a : "(nothing)") + "' where " +
                       scene.spec.file + " has '" + (more_b ? b : "(nothing)") + "'");
    }
  }
  const SystemModel& model = scene.model;
  const DofMap& dofs = model.dofs();
  DynamicState s;
  s.config = InitialState(model);
  SystemState& c = s.config;
  const auto need = [&](const std::string& name, long rows, long cols) {
    const std::vector<hsize_t> shape = r.Shape(name);
    const bool ok = cols == 0 ? shape.size() == 1 && long(shape[0]) == rows
                              : shape.size() == 2 && long(shape[0]) == rows && long(shape[1]) == cols;
    if (!ok) throw InputError(path + ": dataset " + name + " does not have the model's size");
  };
  long nz = 0, neta = 0;
  for (const Eigen::VectorXd& z : c.z) nz += z.size();
  for (const Eigen::VectorXd& e : c.eta) neta += e.size();
  const long n_nodes = model.n_nodes(), n_bodies = long(model.bodies.size()), n = dofs.n_dofs();
  need("/joint_coordinates", nz, 0);
  need("/node_position", n_nodes, 3);
  need("/node_rotation", n_nodes, 9);
  need("/modal_coordinates", neta, 0);
  need("/frame_position", n_bodies, 3);
  need("/frame_rotation", n_bodies, 9);
  need("/velocities", n, 0);
  const Eigen::VectorXd z = r.Vector("/joint_coordinates"), eta = r.Vector("/modal_coordinates");
  const Eigen::MatrixXd x = r.Matrix("/node_position"), R = r.Matrix("/node_rotation");
  const Eigen::MatrixXd fx = r.Matrix("/frame_position"), fR = r.Matrix("/frame_rotation");
  long at = 0;
  for (Eigen::VectorXd& zk : c.z) zk = z.segment(at, zk.size()), at += zk.size();
  at = 0;
  for (Eigen::VectorXd& e : c.eta) e = eta.segment(at, e.size()), at += e.size();
  for (long k = 0; k < n_nodes; ++k) {
    c.x[size_t(k)] = x.row(k).transpose();
    c.R[size_t(k)] = Eigen::Map<const Eigen::Matrix3d>(Eigen::Matrix<double, 1, 9>(R.row(k)).data());
  }
  for (long b = 0; b < n_bodies; ++b) {
    c.frames[size_t(b)].x = fx.row(b).transpose();
    c.frames[size_t(b)].R = Eigen::Map<const Eigen::Matrix3d>(Eigen::Matrix<double, 1, 9>(fR.row(b)).data());
    c.frames[size_t(b)].ok = true;
  }
  c.lambda = r.Vector("/multipliers");
  if (c.lambda.size() != dofs.n_multipliers()) throw InputError(path + ": dataset /multipliers does not have the model's size");
  s.W = r.Vector("/velocities");
  s.Wdot = r.Vector("/accelerations");
  s.a = r.Vector("/algorithmic_accelerations");
  if (s.Wdot.size() != n || s.a.size() != n) throw InputError(path + ": accelerations do not have the model's size");
  s.t = r.Scalar("/time");
  s.external_work = r.Scalar("/external_work");
  s.drive_work = r.Scalar("/drive_work");
  s.h_last = r.Scalar("/step");
  UpdateKinematics(model, dofs, c);
  if (analysis) *analysis = r.StringAttribute("/", "analysis");
  return s;
}

}  // namespace femb
