// The ParaView animation of ResultsRecorder (results_recorder.h): the grid of every body's mesh
// or stick figure, the frames written in part files during the run and gathered into
// animation.h5 at the end, and animation.xdmf that references them.
#include "solver/output/results_recorder.h"

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
#include "formats/vtk_cells.h"

namespace femb {
namespace {

// The power of two 2^(e - bits) for the largest magnitude |v| < 2^e: rounding a field to its
// multiples keeps `bits` significant bits of its largest value (0 for an all-zero field).
float Resolution(float largest, int bits) {
  if (!(largest > 0) || !std::isfinite(largest)) return 0.0f;
  return std::ldexp(1.0f, std::ilogb(largest) + 1 - bits);
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
    std::string cell_type;  // "line2", "tet10", ...
    Eigen::MatrixXi cells;  // VTK/XDMF node order, body-local node indices
  };
  std::vector<Block> blocks;
  std::vector<long> body_nodes(scene_.meshes.size(), 0);
  for (size_t b = 0; b < scene_.meshes.size(); ++b) {
    if (scene_.meshes[b]) {
      blocks.push_back({scene_.meshes[b]->cell_type, ToVtkOrder(scene_.meshes[b]->cell_type, scene_.meshes[b]->cells)});
      body_nodes[b] = scene_.meshes[b]->nodes.rows();
    } else {
      // Lines from the first node to the others; a body of one node: a line of length zero.
      const long m = long(scene_.stick_nodes[b].size());
      Eigen::MatrixXi lines = Eigen::MatrixXi::Zero(std::max(m - 1, 1L), 2);
      for (long i = 1; i < m; ++i) lines.row(i - 1) << 0, int(i);
      blocks.push_back({"line2", lines});
      body_nodes[b] = m;
    }
  }
  for (const Block& block : blocks) g.uniform &= block.cell_type == blocks.front().cell_type;
  for (size_t b = 0; b < blocks.size(); ++b) g.n_nodes += body_nodes[b], g.n_cells += blocks[b].cells.rows();
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
    g.cells = Eigen::Map<Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(g.flat.data(), g.n_cells, g.per_cell);
    g.flat.clear();
  }
  g.cell_type = g.uniform ? blocks.front().cell_type : "mixed";
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
}

void ResultsRecorder::WriteFrames(h5::Writer& w, const std::string& file) {
  const AnimationGrid& g = Grid();
  // Rounded where the bits carry nothing a picture shows, so that they compress (shuffle and
  // deflate): the positions, the displacement and the deformation to multiples of 2^-22 of the
  // largest coordinate so far (2.4e-7 m in a 1 m scene, where single precision resolves 6e-8;
  // within one write the displacement is then the exact difference of the stored positions),
  // the principal stresses to 2^-12 of the frame's largest (colour maps show 256 levels), the
  // von Mises stress as it is (results.h5's maximum is its largest to 1e-7). The positions and
  // the von Mises stress are stored uncompressed: deflate shrank them by 1.5x and 1.2x only, at
  // half the writing time of a solid cantilever's animation.
  for (const auto& frame : mesh_positions_) {
    for (const Eigen::MatrixXf& x : frame) geometry_largest_ = std::max(geometry_largest_, x.size() ? x.cwiseAbs().maxCoeff() : 0.0f);
  }
  const float geometry_step = Resolution(geometry_largest_, 22);
  const auto round = [](const Eigen::MatrixXf& v, float step) -> Eigen::MatrixXf {
    return step > 0 ? Eigen::MatrixXf((v / step).array().round() * step) : v;
  };
  // The frames' datasets compressed in batches of 32 frames on the machine's cores.
  const int threads = int(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
  std::vector<h5::Writer::FloatData> batch;
  const size_t pending = mesh_positions_.size();
  for (size_t p = 0; p < pending; ++p) {
    const size_t s = frames_written_ + p;
    Eigen::MatrixXf x(g.n_nodes, 3), d(g.n_nodes, 3);
    long offset = 0;
    for (size_t b = 0; b < mesh_positions_[p].size(); ++b) {
      x.middleRows(offset, mesh_positions_[p][b].rows()) = mesh_positions_[p][b];
      d.middleRows(offset, mesh_deformations_[p][b].rows()) = mesh_deformations_[p][b];
      offset += mesh_positions_[p][b].rows();
    }
    x = round(x, geometry_step);
    if (s == 0) x0_ = x;
    const std::string index = std::to_string(s);
    batch.push_back({"/x_" + index, x, false});
    batch.push_back({"/deformation_" + index, round(d, geometry_step)});
    batch.push_back({"/displacement_" + index, x - x0_});
    const bool stress = p < frame_stress_.size();
    if (stress) {
      Eigen::MatrixXf f(g.n_nodes, 4);
      offset = 0;
      for (size_t b = 0; b < frame_stress_[p].size(); ++b) {
        f.middleRows(offset, frame_stress_[p][b].rows()) = frame_stress_[p][b];
        offset += frame_stress_[p][b].rows();
      }
      batch.push_back({"/von_mises_" + index, f.leftCols(1), false});
      batch.push_back({"/principal_stress_" + index, round(f.rightCols(3), Resolution(f.rightCols(3).cwiseAbs().maxCoeff(), 12))});
    }
    frame_file_.push_back(file);
    frame_stress_fields_.push_back(stress);
    if (p % 32 == 31 || p + 1 == pending) {
      w.CompressedFloatMatrices(batch, threads);
      batch.clear();
    }
  }
  frames_written_ += pending;
  mesh_positions_.clear();
  mesh_deformations_.clear();
  frame_stress_.clear();
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
    if (g.cell_type == "line2") out << " NodesPerElement=\"2\"";
    out << ">\n     <DataItem Dimensions=\""
        << (g.uniform ? std::to_string(g.n_cells) + " " + std::to_string(g.per_cell) : std::to_string(g.flat.size()))
        << "\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">" << mesh_file << ":/cells</DataItem>\n    </Topology>\n"
        << "    <Geometry GeometryType=\"XYZ\">\n     <DataItem Dimensions=\"" << n_nodes
        << " 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << file << ":/x_" << s
        << "</DataItem>\n    </Geometry>\n"
        << "    <Attribute Name=\"body\" AttributeType=\"Scalar\" Center=\"Cell\">\n     <DataItem Dimensions=\""
        << g.n_cells << " 1\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << mesh_file << ":/body</DataItem>\n"
        << "    </Attribute>\n"
        << "    <Attribute Name=\"deformation\" AttributeType=\"Vector\" Center=\"Node\">\n     <DataItem Dimensions=\""
        << n_nodes << " 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << file << ":/deformation_" << s
        << "</DataItem>\n    </Attribute>\n"
        << "    <Attribute Name=\"displacement\" AttributeType=\"Vector\" Center=\"Node\">\n     <DataItem Dimensions=\""
        << n_nodes << " 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << file << ":/displacement_" << s
        << "</DataItem>\n    </Attribute>\n";
    if (frame_stress_fields_[s]) {
      out << "    <Attribute Name=\"von_mises\" AttributeType=\"Scalar\" Center=\"Node\">\n     <DataItem Dimensions=\""
          << n_nodes << " 1\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << file << ":/von_mises_" << s
          << "</DataItem>\n    </Attribute>\n"
          << "    <Attribute Name=\"principal_stress\" AttributeType=\"Vector\" Center=\"Node\">\n     <DataItem Dimensions=\""
          << n_nodes << " 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << file << ":/principal_stress_" << s
          << "</DataItem>\n    </Attribute>\n";
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
  if (!scene_.spec.animation || mesh_positions_.empty() || Grid().n_cells == 0) return;
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
        if (frame_stress_fields_[s]) names.insert(names.end(), {"/von_mises_" + index, "/principal_stress_" + index});
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

}  // namespace femb
