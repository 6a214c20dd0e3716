#include "reducer/fe/solid_ranks.h"

#include <metis.h>

#include <algorithm>
#include <memory>
#include <stdexcept>

#include "reducer/linalg/byte_buffer.h"
#include "reducer/linalg/interior_solver.h"
#include "reducer/linalg/shared_columns.h"

namespace femb {
namespace {

// The nodes two elements share when they share a face (METIS' ncommon), by SolidType: a
// triangle's 3 (TET4) or 6 (TET10), a quadrilateral's 4 (HEX8) or 8 (HEX20).
constexpr idx_t kFaceNodes[] = {3, 6, 4, 8};

}  // namespace

NodePartition PartitionMesh(const SolidMesh& mesh, int parts, std::vector<long>* cells_per_part) {
  NodePartition partition;
  partition.parts = parts;
  idx_t n_cells = idx_t(mesh.cells.rows()), n_nodes = idx_t(mesh.nodes.rows());
  partition.part.assign(size_t(n_nodes), 0);
  partition.cell_part.assign(size_t(n_cells), 0);
  std::vector<idx_t> cell_part(size_t(n_cells), 0);
  if (parts > 1) {
    const idx_t per = idx_t(mesh.cells.cols());
    std::vector<idx_t> start(size_t(n_cells) + 1), nodes(size_t(n_cells) * size_t(per));
    for (idx_t e = 0; e < n_cells; ++e) {
      start[size_t(e)] = e * per;
      for (idx_t a = 0; a < per; ++a) nodes[size_t(e * per + a)] = mesh.cells(e, a);
    }
    start.back() = n_cells * per;
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    options[METIS_OPTION_NUMBERING] = 0;
    idx_t common = kFaceNodes[int(mesh.type)], n_parts = parts, cut = 0;
    std::vector<idx_t> node_part(static_cast<size_t>(n_nodes));
    const int status = METIS_PartMeshDual(&n_cells, &n_nodes, start.data(), nodes.data(), nullptr, nullptr, &common,
                                          &n_parts, nullptr, options, &cut, cell_part.data(), node_part.data());
    if (status != METIS_OK) {
      throw std::runtime_error("METIS could not partition the mesh into " + std::to_string(parts) + " parts (status " +
                               std::to_string(status) + ")");
    }
    partition.part.assign(node_part.begin(), node_part.end());
    partition.cell_part.assign(cell_part.begin(), cell_part.end());
  }
  if (cells_per_part) {
    cells_per_part->assign(size_t(parts), 0);
    for (const idx_t p : cell_part) ++(*cells_per_part)[size_t(p)];
  }
  return partition;
}

std::string MeshBytes(const SolidMesh& mesh, const NodePartition& partition) {
  std::string out;
  const long header[5] = {long(mesh.nodes.rows()), long(mesh.cells.rows()), long(mesh.cells.cols()), long(mesh.type),
                          long(partition.parts)};
  AppendBytes(out, header, 5);
  AppendBytes(out, mesh.nodes.data(), size_t(mesh.nodes.size()));
  AppendBytes(out, mesh.cells.data(), size_t(mesh.cells.size()));
  AppendBytes(out, partition.part.data(), partition.part.size());
  AppendBytes(out, partition.cell_part.data(), partition.cell_part.size());
  const long sets = long(mesh.node_sets.size());
  AppendBytes(out, &sets, 1);
  for (const auto& [name, set] : mesh.node_sets) {
    const long sizes[2] = {long(name.size()), long(set.size())};
    AppendBytes(out, sizes, 2);
    AppendBytes(out, name.data(), name.size());
    AppendBytes(out, set.data(), set.size());
  }
  return out;
}

SolidMesh MeshFromBytes(const std::string& bytes, NodePartition* partition) {
  SolidMesh mesh;
  long header[5];
  const char* at = TakeBytes(bytes.data(), header, 5);
  mesh.nodes.resize(header[0], 3);
  mesh.cells.resize(header[1], header[2]);
  mesh.type = SolidType(header[3]);
  partition->parts = int(header[4]);
  partition->part.resize(size_t(header[0]));
  partition->cell_part.resize(size_t(header[1]));
  at = TakeBytes(at, mesh.nodes.data(), size_t(mesh.nodes.size()));
  at = TakeBytes(at, mesh.cells.data(), size_t(mesh.cells.size()));
  at = TakeBytes(at, partition->part.data(), partition->part.size());
  at = TakeBytes(at, partition->cell_part.data(), partition->cell_part.size());
  long sets = 0;
  at = TakeBytes(at, &sets, 1);
  for (long k = 0; k < sets; ++k) {
    long sizes[2];
    at = TakeBytes(at, sizes, 2);
    std::string name(size_t(sizes[0]), '\0');
    std::vector<int> set(static_cast<size_t>(sizes[1]));
    at = TakeBytes(at, name.data(), name.size());
    at = TakeBytes(at, set.data(), set.size());
    mesh.node_sets.emplace(std::move(name), std::move(set));
  }
  return mesh;
}

void CheckSamePartOnRanks(const PartSpec& part) {
  if (!SameOnRanks(part.text_hash)) {
    throw RankFailure(2,
                      "the MPI ranks were given different parts (part file or --set values): every rank reduces "
                      "the same part",
                      DistributedRank() == 0);
  }
}

FeModel BuildSolidModelOnRanks(const PartSpec& part, const ProgressFn& progress) {
  Stopwatch clock;
  const int ranks = DistributedRanks();
  auto mesh = std::make_shared<SolidMesh>();
  NodePartition partition;
  std::string bytes, parts = std::to_string(ranks) + " parts";
  if (DistributedRank() == 0) {
    *mesh = MeshSolidPart(part);
    std::vector<long> cells;
    partition = PartitionMesh(*mesh, ranks, &cells);
    parts += " of " + std::to_string(*std::min_element(cells.begin(), cells.end())) + " to " +
             std::to_string(*std::max_element(cells.begin(), cells.end())) + " elements";
    bytes = MeshBytes(*mesh, partition);
  }
  bytes = FromFirstRank(bytes);
  if (DistributedRank() != 0) *mesh = MeshFromBytes(bytes, &partition);
  bytes = std::string();
  CheckSamePartOnRanks(part);
  if (progress)
    progress("mesh", clock.Seconds(), MeshSummary(part, *mesh) + "; rank 0 made it and METIS cut it in " + parts);
  return BuildSolidModelOn(part, mesh, true, &partition, progress);
}

RankMesh RankMeshOf(const FeModel& model) {
  RankMesh mesh;
  if (model.columns.whole()) {
    mesh.nodes = model.nodes;
    mesh.cells = model.cells;
    mesh.node.resize(size_t(model.n_nodes()));
    for (size_t i = 0; i < mesh.node.size(); ++i) mesh.node[i] = int(i);
    return mesh;
  }
  std::vector<int> cells = model.rank_cells;
  if (cells.empty()) {
    const ColumnShare even = ShareOfColumns(model.n_elements());
    for (long c = even.first; c < even.first + even.count; ++c) cells.push_back(int(c));
  }
  std::vector<int> local(size_t(model.n_nodes()), -1);
  for (const int c : cells)
    for (long a = 0; a < model.cells.cols(); ++a) local[size_t(model.cells(c, a))] = 0;
  for (size_t i = 0; i < local.size(); ++i)
    if (local[i] == 0) {
      local[i] = int(mesh.node.size());
      mesh.node.push_back(int(i));
    }
  mesh.nodes.resize(long(mesh.node.size()), 3);
  for (size_t i = 0; i < mesh.node.size(); ++i) mesh.nodes.row(long(i)) = model.nodes.row(mesh.node[i]);
  mesh.cells.resize(long(cells.size()), model.cells.cols());
  for (size_t e = 0; e < cells.size(); ++e)
    for (long a = 0; a < model.cells.cols(); ++a) mesh.cells(long(e), a) = local[size_t(model.cells(cells[e], a))];
  mesh.share = {0, long(cells.size())};
  // The rows of mesh_map for the nodes' mesh DOFs (the columns of its transpose), on the model
  // DOFs they touch.
  const SparseMatrix Tt = model.mesh_map.transpose();
  // The rank that holds a model DOF: the last with a share starting at or before it (the shares
  // follow each other in rank order; an empty one holds nothing).
  std::vector<long> firsts;
  std::vector<int> ranks;
  const std::vector<ColumnShare> shares = RanksShares(model.columns);
  for (size_t r = 0; r < shares.size(); ++r)
    if (shares[r].count > 0) firsts.push_back(shares[r].first), ranks.push_back(int(r));
  const auto rank_of = [&](long row) {
    const long at = std::upper_bound(firsts.begin(), firsts.end(), row) - firsts.begin();
    return at > 0 ? ranks[size_t(at - 1)] : 0;
  };
  std::vector<Eigen::Triplet<double>> entries;
  mesh.owner.assign(mesh.node.size(), 0);
  for (size_t i = 0; i < mesh.node.size(); ++i) {
    for (int c = 0; c < 3; ++c)
      for (SparseMatrix::InnerIterator it(Tt, 3 * mesh.node[i] + c); it; ++it) {
        entries.emplace_back(int(3 * i) + c, int(it.row()), it.value());
        mesh.model_rows.push_back(int(it.row()));
      }
    if (SparseMatrix::InnerIterator first(Tt, 3 * mesh.node[i]); first) mesh.owner[i] = rank_of(first.row());
  }
  std::sort(mesh.model_rows.begin(), mesh.model_rows.end());
  mesh.model_rows.erase(std::unique(mesh.model_rows.begin(), mesh.model_rows.end()), mesh.model_rows.end());
  for (const int row : mesh.model_rows) mesh.row_owner.push_back(rank_of(row));
  for (Eigen::Triplet<double>& t : entries) {
    const long at = std::lower_bound(mesh.model_rows.begin(), mesh.model_rows.end(), t.col()) - mesh.model_rows.begin();
    t = Eigen::Triplet<double>(t.row(), int(at), t.value());
  }
  mesh.map.resize(3 * long(mesh.node.size()), long(mesh.model_rows.size()));
  mesh.map.setFromTriplets(entries.begin(), entries.end());
  return mesh;
}

Eigen::MatrixXd RankMeshFields(const FeModel& model, const RankMesh& mesh, const Eigen::MatrixXd& X) {
  if (model.columns.whole()) return model.mesh_map * X;
  return mesh.map * FetchRows(X, model.columns, mesh.model_rows);
}

}  // namespace femb
