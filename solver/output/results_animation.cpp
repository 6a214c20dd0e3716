// The ParaView animation of ResultsRecorder (results_recorder.h): the grid of every body's mesh
// or stick figure, the frames written in part files during the run and gathered into
// animation.h5 at the end, and animation.xdmf that references them.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "formats/hdf5_file.h"
#include "formats/input_error.h"
#include "formats/superelement.h"
#include "formats/vtk_cells.h"
#include "solver/output/results_recorder.h"
#include "solver/parallel.h"

namespace femb {
namespace {

// The power of two 2^(e - bits) for the largest magnitude |v| < 2^e: rounding a field to its
// multiples keeps `bits` significant bits of its largest value (0 for an all-zero field).
float Resolution(float largest, int bits) {
  if (!(largest > 0) || !std::isfinite(largest)) return 0.0f;
  return std::ldexp(1.0f, std::ilogb(largest) + 1 - bits);
}
// The nodes in the order of their Morton code (the bits of the three coordinates, quantized to
// 2^21 steps of the mesh's bounding box, interleaved): a curve through space that keeps
// neighbours mostly next to each other, so that a field's consecutive values are alike.
std::vector<int> MortonOrder(const Eigen::MatrixXd& nodes) {
  const long n = nodes.rows();
  std::vector<int> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  if (n == 0) return order;
  const Eigen::RowVector3d low = nodes.colwise().minCoeff(), span = nodes.colwise().maxCoeff() - low;
  const auto spread = [](uint64_t v) {  // the 21 bits of v to every third bit
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  std::vector<uint64_t> code(static_cast<size_t>(n));
  for (long i = 0; i < n; ++i) {
    uint64_t c = 0;
    for (int k = 0; k < 3; ++k) {
      const double f = span[k] > 0 ? (nodes(i, k) - low[k]) / span[k] : 0.0;
      c |= spread(uint64_t(std::clamp(f, 0.0, 1.0) * double((1 << 21) - 1))) << k;
    }
    code[size_t(i)] = c;
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return code[size_t(a)] < code[size_t(b)]; });
  return order;
}
std::string Num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", v);
  return buffer;
}
}  // namespace

const ResultsRecorder::AnimationGrid& ResultsRecorder::Grid() {
  // One unstructured grid per frame holding every body (nodes concatenated, cell data 'body' =
  // body index): a temporal collection that ParaView and meshio read. Bodies with a mesh show
  // it; the others (rigid bodies, superelements reduced without their mesh) a stick figure of
  // lines from their first node to the others. One cell type: a uniform topology; several
  // (beams and solids, sticks): XDMF's Mixed topology.
  if (grid_) return *grid_;
  grid_ = std::make_unique<AnimationGrid>();
  AnimationGrid& g = *grid_;
  struct Block {
    CellType cell_type;
    Eigen::MatrixXi cells;  // VTK/XDMF node order, body-local node indices
  };
  std::vector<Block> blocks;
  std::vector<long> body_nodes(scene_.meshes.size(), 0);
  g.node_of.resize(scene_.meshes.size());
  for (size_t b = 0; b < scene_.meshes.size(); ++b) {
    if (scene_.meshes[b]) {
      const Visualization& mesh = *scene_.meshes[b];
      Eigen::MatrixXi cells = ToVtkOrder(mesh.cell_type, mesh.cells);
      std::vector<int>& order = g.node_of[b];
      if (mesh.cell_type == CellType::kLine2) {
        order.resize(size_t(mesh.nodes.rows()));
        std::iota(order.begin(), order.end(), 0);
      } else {
        order = MortonOrder(mesh.nodes);
        std::vector<int> rank(order.size());
        for (size_t j = 0; j < order.size(); ++j) rank[size_t(order[j])] = int(j);
        for (Eigen::Index i = 0; i < cells.size(); ++i) cells.data()[i] = rank[size_t(cells.data()[i])];
      }
      blocks.push_back({mesh.cell_type, cells});
      body_nodes[b] = mesh.nodes.rows();
    } else {
      // Lines from the first node to the others; a body of one node: a line of length zero.
      const long m = long(scene_.stick_nodes[b].size());
      Eigen::MatrixXi lines = Eigen::MatrixXi::Zero(std::max(m - 1, 1L), 2);
      for (long i = 1; i < m; ++i) lines.row(i - 1) << 0, int(i);
      blocks.push_back({CellType::kLine2, lines});
      body_nodes[b] = m;
      g.node_of[b].resize(size_t(m));
      std::iota(g.node_of[b].begin(), g.node_of[b].end(), 0);
    }
  }
  for (size_t b = 0; b < blocks.size(); ++b) {
    g.offset.push_back(g.n_nodes);
    g.node.insert(g.node.end(), g.node_of[b].begin(), g.node_of[b].end());
    g.n_nodes += body_nodes[b];
  }
  for (const Block& block : blocks) g.uniform &= block.cell_type == blocks.front().cell_type;
  for (size_t b = 0; b < blocks.size(); ++b) g.n_cells += blocks[b].cells.rows();
  if (g.n_nodes == 0 || g.n_cells == 0) return g;
  // Topology: uniform, n_cells x per_cell; mixed, one flat list of (XDMF type, [count,] nodes...).
  g.per_cell = g.uniform ? int(blocks.front().cells.cols()) : 0;
  g.body.resize(g.n_cells, 1);
  long node_offset = 0, cell_offset = 0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const Block& block = blocks[b];
    const int code = XdmfMixedCode(block.cell_type);
    for (long c = 0; c < block.cells.rows(); ++c) {
      if (!g.uniform) {
        g.flat.push_back(code);
        if (code == 2) g.flat.push_back(int(block.cells.cols()));  // polyline: its node count
      }
      for (long i = 0; i < block.cells.cols(); ++i) g.flat.push_back(block.cells(c, i) + int(node_offset));
    }
    g.body.middleRows(cell_offset, block.cells.rows()).setConstant(double(b));
    node_offset += body_nodes[b];
    cell_offset += block.cells.rows();
  }
  if (g.uniform) {
    g.cells = Eigen::Map<Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(g.flat.data(), g.n_cells,
                                                                                              g.per_cell);
    g.flat.clear();
  }
  g.cell_type = blocks.front().cell_type;
  return g;
}

void ResultsRecorder::WriteMesh(h5::Writer& w) {
  const AnimationGrid& g = Grid();
  if (g.uniform) {
    w.IntMatrix("/cells", g.cells);
  } else {
    w.IntVector("/cells", g.flat);
  }
  w.Matrix("/body", g.body);
  w.IntVector("/node", g.node);
}

namespace {
// The animation's stress fields (outputs.stresses; the principal ones with outputs.principal_stresses).
std::vector<const char*> StressFields(bool principal) {
  if (principal) return {"von_mises", "max_principal", "min_principal"};
  return {"von_mises"};
}
}  // namespace

// A thread's storage for MakeFields, kept from frame to frame.
struct ResultsRecorder::FieldWorkspace {
  Eigen::MatrixXf x, d, displacement, stress;  // grid fields, column-major (a column a chunk)
  Eigen::VectorXd u, von_mises;
  Eigen::MatrixXd tensor;
  Eigen::VectorXf scratch;
};

ResultsRecorder::PackedFrame ResultsRecorder::MakeFields(const PendingOutput& job, FieldWorkspace& ws) {
  const bool fields = job.frame >= 0, stresses = scene_.spec.stresses;
  const AnimationGrid* g = fields ? grid_.get() : nullptr;
  PackedFrame out;
  out.stress = fields && stresses;
  if (fields) {
    ws.x.resize(g->n_nodes, 3), ws.d.resize(g->n_nodes, 3);
    // von Mises, and with outputs.principal_stresses the largest and smallest principal stress
    if (out.stress) ws.stress.setZero(g->n_nodes, scene_.spec.principal_stresses ? 3 : 1);
  }
  for (size_t b = 0; b < scene_.meshes.size(); ++b) {
    const long offset = fields ? g->offset[b] : 0;
    const std::vector<int>* order = fields ? &g->node_of[b] : nullptr;
    const auto& mesh = scene_.meshes[b];
    if (fields && mesh) {
      // x = x_j + R_j (X - X_j + Phi q_loc); the deformation field is the elastic part R_j Phi
      // q_loc in global axes (what ParaView should colour by: no rigid motion of the body in it).
      ws.u.noalias() = mesh->shapes * job.q_loc[b];
      const Eigen::Matrix3d& R = job.frame_R[b];
      const Eigen::Vector3d frame_origin = scene_.origin + job.frame_x[b];
      for (size_t j = 0; j < order->size(); ++j) {
        const int i = (*order)[j];
        const Eigen::Vector3d X = mesh->nodes.row(i).transpose() - scene_.mesh_origin[b];
        const Eigen::Vector3d ui = R * ws.u.segment<3>(long(mesh->dofs_per_node) * i);
        ws.x.row(offset + long(j)) = (frame_origin + R * X + ui).transpose().cast<float>();
        ws.d.row(offset + long(j)) = ui.transpose().cast<float>();
      }
    } else if (fields) {
      ws.x.middleRows(offset, job.sticks[b].rows()) = job.sticks[b];
      ws.d.middleRows(offset, job.sticks[b].rows()).setZero();  // no deformation field
    }
    if (!stresses || !scene_.stresses[b]) continue;
    const long n_mesh = mesh ? long(mesh->nodes.rows()) : long(scene_.stick_nodes[b].size());
    NodeStresses(*scene_.stresses[b], job.q_stress[b], n_mesh, &ws.tensor, &ws.von_mises,
                 job.factors[b].size() > 0 ? &job.factors[b] : nullptr, &ws.scratch);
    // The largest von Mises stress, without the nodes outputs.stress_exclude leaves out.
    const std::vector<char>& excluded = scene_.stress_excluded[b];
    Eigen::Index worst = 0;
    double largest = -1.0;
    for (Eigen::Index i = 0; i < ws.von_mises.size(); ++i) {
      if (!excluded.empty() && excluded[size_t(i)]) continue;
      if (ws.von_mises[i] > largest) largest = ws.von_mises[i], worst = i;
    }
    max_von_mises_[b][size_t(job.output)] = std::max(largest, 0.0);
    max_von_mises_node_[b][size_t(job.output)] = int(worst);
    if (!fields) continue;
    for (size_t j = 0; j < order->size(); ++j) {
      const int i = (*order)[j];
      ws.stress(offset + long(j), 0) = float(ws.von_mises[i]);
      if (!scene_.spec.principal_stresses) continue;
      const Eigen::Vector2d p = ExtremePrincipalStresses(ws.tensor.row(i).transpose());
      ws.stress(offset + long(j), 1) = float(p[0]), ws.stress(offset + long(j), 2) = float(p[1]);
    }
  }
  if (!fields) return out;
  // Rounded where the bits carry nothing a picture shows, so that they compress (shuffle and
  // deflate): the positions, the displacement and the deformation to multiples of 2^-22 of the
  // frame's largest coordinate (2.4e-7 m in a 1 m scene, where single precision resolves 6e-8;
  // the displacement is then the exact difference of the stored positions), the von Mises stress
  // to 2^-21 of the frame's largest (results.h5 holds the largest in double precision), the
  // principal stresses to 2^-12 of the frame's largest (colour maps show 256 levels).
  const auto round = [](auto&& v, float step) {
    if (step > 0) v = (v / step).array().round() * step;
  };
  const float geometry = Resolution(ws.x.size() ? ws.x.cwiseAbs().maxCoeff() : 0.0f, 22);
  round(ws.x, geometry);
  round(ws.d, geometry);
  if (job.frame == 0) x0_ = ws.x;  // (frame 0 is made alone, before the others)
  ws.displacement = ws.x - x0_;
  const std::string index = std::to_string(job.frame);
  const auto pack = [&](const std::string& name, const float* data, long cols) {
    out.fields.push_back(h5::PackFloats(name + index, data, g->n_nodes, cols));
  };
  pack("/x_", ws.x.data(), 3);
  pack("/deformation_", ws.d.data(), 3);
  pack("/displacement_", ws.displacement.data(), 3);
  if (out.stress) {
    round(ws.stress.col(0), Resolution(ws.stress.col(0).maxCoeff(), 21));
    pack("/von_mises_", ws.stress.col(0).data(), 1);
    if (scene_.spec.principal_stresses) {
      round(ws.stress.rightCols(2), Resolution(ws.stress.rightCols(2).cwiseAbs().maxCoeff(), 12));
      pack("/max_principal_", ws.stress.col(1).data(), 1);
      pack("/min_principal_", ws.stress.col(2).data(), 1);
    }
  }
  return out;
}

void ResultsRecorder::MakePending() {
  if (!files_ && !writing_memory_frames_) {
    // Results kept in memory: the frames wait for WriteAnimation; only the stresses are made.
    for (PendingOutput& job : pending_) {
      if (job.frame < 0) continue;
      memory_frames_.push_back(job);
      job.frame = -1;
    }
    if (!scene_.spec.stresses) pending_.clear();
  }
  if (pending_.empty()) return;
  if (scene_.spec.animation) Grid();  // (built here, read by the threads)
  // Each output step made by one thread, the steps spread over the machine's cores; frame 0
  // first, alone (the others' displacement is from its positions).
  std::vector<PackedFrame> made(pending_.size());
  size_t first = 0;
  FieldWorkspace ws;
  if (pending_.front().frame == 0) made[first++] = MakeFields(pending_.front(), ws);
  const int threads = std::clamp(DefaultThreads(), 1, 8);  // the processors this process may use
  std::atomic<size_t> next{first};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&](FieldWorkspace& own) {
    try {
      for (size_t i = next++; i < pending_.size(); i = next++) made[i] = MakeFields(pending_[i], own);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = pending_.size();
    }
  };
  std::vector<FieldWorkspace> spaces(size_t(threads - 1));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, std::ref(spaces[size_t(t - 1)]));
  work(ws);
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  for (size_t i = 0; i < pending_.size(); ++i) {
    if (pending_[i].frame >= 0 && Grid().n_cells > 0) packed_frames_.push_back(std::move(made[i]));
  }
  pending_.clear();
}

void ResultsRecorder::WriteFrames(h5::Writer& w, const std::string& file) {
  for (PackedFrame& frame : packed_frames_) {
    for (const h5::PackedFloats& field : frame.fields) w.Packed(field);
    frame_file_.push_back(file);
    frame_stress_fields_.push_back(frame.stress);
  }
  frames_written_ += packed_frames_.size();
  packed_frames_.clear();
}

void ResultsRecorder::WriteXdmf(const std::string& mesh_file) {
  const AnimationGrid& g = Grid();
  const std::string topology = g.uniform ? XdmfTopology(g.cell_type) : "Mixed";
  const std::string xdmf = (std::filesystem::path(directory_) / "animation.xdmf").string();
  const std::string tmp = xdmf + ".tmp." + std::to_string(::getpid());
  std::ofstream out(tmp);
  out << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
      << "  <Grid Name=\"" << scene_.spec.name << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  const long n_nodes = g.n_nodes;
  for (size_t s = 0; s < frames_written_; ++s) {
    const std::string& file = frame_file_[s];
    out << "   <Grid Name=\"step " << s << "\" GridType=\"Uniform\">\n"
        << "    <Time Value=\"" << Num(frame_time_[s]) << "\"/>\n"
        << "    <Topology TopologyType=\"" << topology << "\" NumberOfElements=\"" << g.n_cells << "\"";
    if (g.uniform && g.cell_type == CellType::kLine2) out << " NodesPerElement=\"2\"";
    out << ">\n     <DataItem Dimensions=\""
        << (g.uniform ? std::to_string(g.n_cells) + " " + std::to_string(g.per_cell) : std::to_string(g.flat.size()))
        << "\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">" << mesh_file
        << ":/cells</DataItem>\n    </Topology>\n"
        << "    <Geometry GeometryType=\"XYZ\">\n     <DataItem Dimensions=\"" << n_nodes
        << " 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << file << ":/x_" << s
        << "</DataItem>\n    </Geometry>\n"
        << "    <Attribute Name=\"body\" AttributeType=\"Scalar\" Center=\"Cell\">\n     <DataItem Dimensions=\""
        << g.n_cells << " 1\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << mesh_file
        << ":/body</DataItem>\n"
        << "    </Attribute>\n"
        << "    <Attribute Name=\"node\" AttributeType=\"Scalar\" Center=\"Node\">\n     <DataItem Dimensions=\""
        << n_nodes << " 1\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">" << mesh_file << ":/node</DataItem>\n"
        << "    </Attribute>\n"
        << "    <Attribute Name=\"deformation\" AttributeType=\"Vector\" Center=\"Node\">\n     <DataItem Dimensions=\""
        << n_nodes << " 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << file << ":/deformation_" << s
        << "</DataItem>\n    </Attribute>\n"
        << "    <Attribute Name=\"displacement\" AttributeType=\"Vector\" Center=\"Node\">\n     <DataItem "
           "Dimensions=\""
        << n_nodes << " 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << file << ":/displacement_" << s
        << "</DataItem>\n    </Attribute>\n";
    if (frame_stress_fields_[s]) {
      for (const char* field : StressFields(scene_.spec.principal_stresses)) {
        out << "    <Attribute Name=\"" << field
            << "\" AttributeType=\"Scalar\" Center=\"Node\">\n     <DataItem Dimensions=\"" << n_nodes
            << " 1\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << file << ":/" << field << "_" << s
            << "</DataItem>\n    </Attribute>\n";
      }
    }
    out << "   </Grid>\n";
  }
  out << "  </Grid>\n </Domain>\n</Xdmf>\n";
  out.close();
  if (!out) throw InputError(tmp + ": cannot write");
  std::error_code ec;
  std::filesystem::rename(tmp, xdmf, ec);
  if (ec) throw InputError(xdmf + ": cannot rename into place (" + ec.message() + ")");
}

void ResultsRecorder::WriteAnimationPart() {
  if (!scene_.spec.animation || packed_frames_.empty() || Grid().n_cells == 0) return;
  const std::filesystem::path dir(directory_);
  char name[64];
  std::snprintf(name, sizeof name, "animation.part-%04zu.h5", animation_parts_.size());
  const std::string path = (dir / name).string(), tmp = path + ".tmp." + std::to_string(::getpid());
  // The mesh goes with the first frame: into the first part, or into animation.h5 with the frames
  // of a run continued (--restart) after its end.
  const bool first = frames_written_ == 0;
  {
    h5::Writer w(tmp, /*v110=*/true);
    if (first) WriteMesh(w);
    WriteFrames(w, name);
    w.Close();
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InputError(path + ": cannot rename into place (" + ec.message() + ")");
  if (first) std::filesystem::remove(dir / "animation.h5", ec);  // an earlier run's
  animation_parts_.push_back(name);
  WriteXdmf(frame_file_.front());
}

void ResultsRecorder::FinishAnimation() {
  if (!scene_.spec.animation || frame_time_.empty() || Grid().n_cells == 0) return;
  // animation.h5: the mesh, the frames of the part files written during the run (copied as they
  // are stored) and the frames since.
  const std::filesystem::path dir(directory_);
  const std::string h5 = (dir / "animation.h5").string(), tmp = h5 + ".tmp." + std::to_string(::getpid());
  {
    h5::Writer w(tmp, /*v110=*/true);
    WriteMesh(w);
    // The files holding written frames: the parts, and animation.h5 of a run continued after
    // its end (copied into its successor under a temporary name).
    std::vector<std::string> sources;
    for (const std::string& file : frame_file_)
      if (std::find(sources.begin(), sources.end(), file) == sources.end()) sources.push_back(file);
    for (const std::string& part : sources) {
      std::vector<std::string> names;
      for (size_t s = 0; s < frames_written_; ++s) {
        if (frame_file_[s] != part) continue;
        const std::string index = std::to_string(s);
        for (const char* field : {"/x_", "/deformation_", "/displacement_"}) names.push_back(field + index);
        if (frame_stress_fields_[s]) {
          for (const char* field : StressFields(scene_.spec.principal_stresses))
            names.push_back("/" + std::string(field) + "_" + index);
        }
      }
      w.CopyFrom((dir / part).string(), names);
    }
    WriteFrames(w, "animation.h5");
    w.Close();
  }
  std::error_code ec;
  std::filesystem::rename(tmp, h5, ec);
  if (ec) throw InputError(h5 + ": cannot rename into place (" + ec.message() + ")");
  std::fill(frame_file_.begin(), frame_file_.end(), "animation.h5");
  animation_parts_.clear();
  WriteXdmf("animation.h5");
  // The part files, now in animation.h5 (and an earlier run's left by a kill).
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string file = entry.path().filename().string();
    if (file.rfind("animation.part-", 0) == 0) std::filesystem::remove(entry.path(), ec);
  }
}

void ResultsRecorder::WriteAnimation(const std::string& directory) {
  if (files_) throw std::logic_error("ResultsRecorder::WriteAnimation: the run wrote its own animation");
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) throw InputError(directory + ": cannot create output folder (" + ec.message() + ")");
  directory_ = directory;
  frames_written_ = 0;
  frame_file_.clear(), frame_stress_fields_.clear(), packed_frames_.clear(), animation_parts_.clear();
  pending_ = memory_frames_;
  writing_memory_frames_ = true;
  try {
    MakePending();
  } catch (...) {
    writing_memory_frames_ = false;
    throw;
  }
  writing_memory_frames_ = false;
  FinishAnimation();
}

}  // namespace femb
