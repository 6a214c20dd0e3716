// The mesh of one instance of an Abaqus deck (reducer/mesh/abaqus_mesh.h).
#include "reducer/mesh/abaqus_mesh.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <unordered_map>

#include "formats/input_error.h"

namespace femb {
namespace {

struct CellKind {
  CellType type;
  int dimension;
  std::vector<int> from_abaqus;  // gmsh node k = Abaqus node from_abaqus[k]
};

std::vector<int> Identity(int n) {
  std::vector<int> v(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) v[size_t(i)] = i;
  return v;
}

// Abaqus' node order is VTK's for these cells; gmsh differs for tet10 and hex20 (as in
// formats/meshio_bridge.py). B32 and T3D3 are drawn through their end nodes.
std::optional<CellKind> KindOf(const std::string& type) {
  auto starts = [&](const char* p) { return type.rfind(p, 0) == 0; };
  if (starts("C3D10")) return CellKind{CellType::kTet10, 3, {0, 1, 2, 3, 4, 5, 6, 7, 9, 8}};
  if (starts("C3D4")) return CellKind{CellType::kTet4, 3, Identity(4)};
  if (starts("C3D20"))
    return CellKind{CellType::kHex20, 3, {0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 16, 9, 17, 10, 18, 19, 12, 15, 13, 14}};
  if (starts("C3D8") || starts("SC8")) return CellKind{CellType::kHex8, 3, Identity(8)};
  if (starts("STRI65") || starts("S6") || starts("M3D6")) return CellKind{CellType::kTri6, 2, Identity(6)};
  if (starts("S3") || starts("M3D3")) return CellKind{CellType::kTri3, 2, Identity(3)};
  if (starts("S8") || starts("M3D8")) return CellKind{CellType::kQuad8, 2, Identity(8)};
  if (starts("S4") || starts("M3D4")) return CellKind{CellType::kQuad4, 2, Identity(4)};
  if (starts("B32") || starts("T3D3")) return CellKind{CellType::kLine2, 1, {0, 2}};
  if (starts("B31") || starts("B33") || starts("T3D2")) return CellKind{CellType::kLine2, 1, {0, 1}};
  return std::nullopt;
}

}  // namespace

ForeignMesh ForeignMeshOf(const AbaqusMesh& mesh, const std::string& where) {
  ForeignMesh out;
  out.nodes = mesh.nodes;
  out.ids = mesh.labels;
  out.node_sets = mesh.node_sets;
  std::unordered_map<long, int> index;
  for (size_t s = 0; s < mesh.labels.size(); ++s) index[mesh.labels[s]] = int(s);
  int dimension = 0;
  std::vector<std::pair<CellKind, const AbaqusElement*>> drawn;
  for (const AbaqusElement& e : mesh.elements) {
    const std::optional<CellKind> kind = KindOf(e.type);
    if (!kind || kind->dimension < dimension) continue;
    if (kind->dimension > dimension) drawn.clear();
    dimension = kind->dimension;
    drawn.emplace_back(*kind, &e);
  }
  const std::string name = mesh.name.empty() ? "the deck" : "instance " + mesh.name;
  if (drawn.empty())
    throw InputError(where + ": " + name + " has no cells femb can draw (solid, shell or beam elements)");
  bool mixed = false;
  for (const auto& [kind, e] : drawn) mixed |= kind.type != drawn.front().first.type;
  if (mixed && dimension == 3)
    throw InputError(where + ": " + name + ": mixed volume element types are not supported yet");
  // A mix of surface cells is drawn as triangles through the corners.
  const CellType type = mixed ? CellType::kTri3 : drawn.front().first.type;
  std::vector<std::vector<int>> cells;
  for (const auto& [kind, e] : drawn) {
    std::vector<int> nodes;
    for (int a : kind.from_abaqus) nodes.push_back(index.at(e->nodes[size_t(a)]));
    if (!mixed) {
      cells.push_back(nodes);
    } else if (kind.type == CellType::kQuad4 || kind.type == CellType::kQuad8) {
      cells.push_back({nodes[0], nodes[1], nodes[2]});
      cells.push_back({nodes[0], nodes[2], nodes[3]});
    } else {
      cells.push_back({nodes[0], nodes[1], nodes[2]});
    }
  }
  out.cell_type = type;
  out.cells.resize(long(cells.size()), long(cells.front().size()));
  for (size_t e = 0; e < cells.size(); ++e)
    for (size_t a = 0; a < cells[e].size(); ++a) out.cells(long(e), long(a)) = cells[e][a];
  return out;
}

ForeignMesh ReadImportedGeometry(const std::string& path, const std::string& instance, const std::string& where) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext == ".inp" && (!instance.empty() || HasInstances(path))) {
    const AbaqusDeck deck = ReadAbaqusDeck(path);
    return ForeignMeshOf(deck.instances[size_t(PickInstance(deck, instance, where))], where);
  }
  if (!instance.empty())
    throw InputError(where + ": matrices.instance names an Abaqus instance, but " + path + " is not an Abaqus deck");
  return ReadWithMeshio(path, where, true);
}

}  // namespace femb
