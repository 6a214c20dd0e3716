#include "reducer/mesh/gmsh_mesher.h"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "formats/input_error.h"

namespace femb {
namespace {

// One gmsh session at a time, finalized on every path.
struct GmshSession {
  GmshSession() {
    gmsh::initialize();
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.NumThreads", 1);
  }
  ~GmshSession() { gmsh::finalize(); }
};

bool SolidTypeOfGmsh(int gmsh_type, SolidType* type) {
  switch (gmsh_type) {
    case 4:
      *type = SolidType::kTet4;
      return true;
    case 11:
      *type = SolidType::kTet10;
      return true;
    case 5:
      *type = SolidType::kHex8;
      return true;
    case 17:
      *type = SolidType::kHex20;
      return true;
    default:
      return false;
  }
}

// The geometry's volume: OpenCASCADE's mass of its volumes, or, for the built-in kernel (no
// mass query), its bounding box (an upper bound).
double GeometryVolume() {
  gmsh::vectorpair volumes;
  gmsh::model::getEntities(volumes, 3);
  double total = 0.0;
  try {
    for (const auto& [dim, tag] : volumes) {
      double mass = 0.0;
      gmsh::model::occ::getMass(dim, tag, mass);
      total += mass;
    }
    if (total > 0) return total;
  } catch (...) {
  }
  double x0, y0, z0, x1, y1, z1;
  gmsh::model::getBoundingBox(-1, -1, x0, y0, z0, x1, y1, z1);
  return std::max(x1 - x0, 0.0) * std::max(y1 - y0, 0.0) * std::max(z1 - z0, 0.0);
}

void RequireElementBudget(const MeshRequest& r) {
  const double h = r.element_size, volume = GeometryVolume();
  const double estimate = (r.hexahedra ? 1.0 : 6.0) * volume / (h * h * h);
  if (estimate <= double(r.max_elements)) return;
  char buffer[400];
  std::snprintf(buffer, sizeof buffer,
                "%s: mesh.size %.4g on a geometry of volume %.4g would give about %.3g elements, more than "
                "mesh.max_elements = %ld: use a larger mesh.size (%.4g gives about %ld) or raise mesh.max_elements",
                r.where.c_str(), h, volume, estimate, r.max_elements, h * std::cbrt(estimate / double(r.max_elements)),
                r.max_elements);
  throw ResourceLimitError(buffer);
}

using SurfaceEntities = std::map<std::string, std::vector<int>>;  // node set name -> surface tags

// The built-in cylinder or tube along z: its faces named bottom, top, outer and inner.
void AddCylinder(const MeshRequest& r, SurfaceEntities& surface_entities) {
  gmsh::model::add(Name(r.shape));
  int volume = gmsh::model::occ::addCylinder(0, 0, 0, 0, 0, r.length, r.radius);
  if (r.shape == SolidShape::kTube) {
    const int bore = gmsh::model::occ::addCylinder(0, 0, -0.1 * r.length, 0, 0, 1.2 * r.length, r.inner_radius);
    gmsh::vectorpair out;
    std::vector<gmsh::vectorpair> map;
    gmsh::model::occ::cut({{3, volume}}, {{3, bore}}, out, map);
    volume = out.at(0).second;
  }
  gmsh::model::occ::synchronize();
  gmsh::vectorpair faces;
  gmsh::model::getBoundary({{3, volume}}, faces, false, false, false);
  const double tol = 1e-4 * std::min(r.radius, r.length);
  for (const auto& [dim, tag] : faces) {
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(dim, tag, x0, y0, z0, x1, y1, z1);
    if (z1 - z0 < tol + 1e-3 * r.length) {
      surface_entities[0.5 * (z0 + z1) < 0.5 * r.length ? "bottom" : "top"].push_back(tag);
    } else {
      const double half_width = 0.5 * (x1 - x0);
      surface_entities[std::abs(half_width - r.radius) < std::abs(half_width - r.inner_radius) ? "outer" : "inner"]
          .push_back(tag);
    }
  }
}

// The built-in box or plate: its faces named xmin .. zmax; with `hexahedra` structured.
void AddBox(const MeshRequest& r, SurfaceEntities& surface_entities) {
  gmsh::model::add("box");
  const int volume = gmsh::model::occ::addBox(0, 0, 0, r.size.x(), r.size.y(), r.size.z());
  gmsh::model::occ::synchronize();
  gmsh::vectorpair faces;
  gmsh::model::getBoundary({{3, volume}}, faces, false, false, false);
  if (r.hexahedra) {
    // Structured: transfinite curves (nodes from the element size), recombined faces,
    // transfinite volume -> hexahedra.
    gmsh::vectorpair curves;
    gmsh::model::getBoundary({{3, volume}}, curves, false, false, true);
    for (const auto& [dim, tag] : curves) {
      if (dim != 1) continue;
      double x0, y0, z0, x1, y1, z1;
      gmsh::model::getBoundingBox(dim, tag, x0, y0, z0, x1, y1, z1);
      const double length = std::max({x1 - x0, y1 - y0, z1 - z0});
      const double h = r.element_size > 0 ? r.element_size : r.size.maxCoeff() / 10;
      gmsh::model::mesh::setTransfiniteCurve(tag, std::max(2, int(std::lround(length / h)) + 1));
    }
    for (const auto& [dim, tag] : faces) {
      gmsh::model::mesh::setTransfiniteSurface(tag);
      gmsh::model::mesh::setRecombine(2, tag);
    }
    gmsh::model::mesh::setTransfiniteVolume(volume);
    gmsh::option::setNumber("Mesh.SecondOrderIncomplete", 1);  // HEX20, not HEX27
  }
  for (const auto& [dim, tag] : faces) {
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(dim, tag, x0, y0, z0, x1, y1, z1);
    // OpenCASCADE pads bounding boxes (by ~1e-7 absolute, more than a thin plate's relative
    // tolerance): a face is flat in the direction of its smallest extent relative to the
    // box; min or max by where its middle lies.
    const Eigen::Vector3d lo(x0, y0, z0), hi(x1, y1, z1);
    const Eigen::Vector3d extent = (hi - lo).cwiseQuotient(r.size);
    int d = 0;
    extent.minCoeff(&d);
    const char* names[3][2] = {{"xmin", "xmax"}, {"ymin", "ymax"}, {"zmin", "zmax"}};
    surface_entities[names[d][0.5 * (lo[d] + hi[d]) > 0.5 * r.size[d]]].push_back(tag);
  }
}

// A geometry or mesh file: its named surface groups.
void OpenFile(const MeshRequest& r, SurfaceEntities& surface_entities) {
  if (r.hexahedra) throw InputError(r.where + ": hexahedral meshing is available for the built-in box only");
  gmsh::open(r.file);
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, 2);
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    if (name.empty()) name = std::to_string(tag);
    surface_entities[name] = entities;
  }
}

// The model's volume elements, meshed first when the model has none (a geometry rather than a
// mesh), within the element budget.
void VolumeElements(const MeshRequest& r, std::vector<int>& types, std::vector<std::vector<std::size_t>>& element_tags,
                    std::vector<std::vector<std::size_t>>& element_nodes) {
  gmsh::model::mesh::getElements(types, element_tags, element_nodes, 3);
  if (types.empty()) {
    if (r.element_size > 0) RequireElementBudget(r);
    if (r.element_size > 0) {
      gmsh::option::setNumber("Mesh.MeshSizeMax", r.element_size);
      gmsh::option::setNumber("Mesh.MeshSizeMin", 0.5 * r.element_size);
    }
    gmsh::model::mesh::generate(3);
    if (r.order == 2) gmsh::model::mesh::setOrder(2);
    gmsh::model::mesh::getElements(types, element_tags, element_nodes, 3);
  }
}

// The mesh's cells of its one volume element type (femb's numbering of the nodes: `index`).
void Cells(const MeshRequest& r, const std::vector<int>& types,
           const std::vector<std::vector<std::size_t>>& element_nodes,
           const std::unordered_map<std::size_t, int>& index, SolidMesh& mesh) {
  int chosen = -1;
  for (size_t t = 0; t < types.size(); ++t) {
    SolidType type;
    if (!SolidTypeOfGmsh(types[t], &type)) {
      throw InputError((r.where.empty() ? r.file : r.where) + ": gmsh element type " + std::to_string(types[t]) +
                       " is not supported (use tetrahedra or hexahedra of order 1 or 2)");
    }
    if (chosen >= 0) {
      throw InputError((r.where.empty() ? r.file : r.where) + ": mixed volume element types are not supported yet");
    }
    chosen = int(t);
    mesh.type = type;
  }
  if (chosen < 0) {
    throw InputError((r.where.empty() ? r.file : r.where) + ": the mesh has no volume elements");
  }
  const int per = SolidNodeCount(mesh.type);
  const auto& conn = element_nodes[chosen];
  mesh.cells.resize(long(conn.size() / per), per);
  for (size_t e = 0; e < conn.size() / per; ++e)
    for (int a = 0; a < per; ++a) mesh.cells(long(e), a) = index.at(conn[e * per + a]);
}

// The named node sets: the nodes of each set's surfaces, sorted, once each.
void NodeSets(const SurfaceEntities& surface_entities, const std::unordered_map<std::size_t, int>& index,
              SolidMesh& mesh) {
  for (const auto& [name, entities] : surface_entities) {
    std::vector<int>& set = mesh.node_sets[name];
    for (int tag : entities) {
      std::vector<std::size_t> tags;
      std::vector<double> c, p;
      gmsh::model::mesh::getNodes(tags, c, p, 2, tag, true, false);
      for (std::size_t t : tags) set.push_back(index.at(t));
    }
    std::sort(set.begin(), set.end());
    set.erase(std::unique(set.begin(), set.end()), set.end());
  }
}

}  // namespace

SolidMesh MeshWithGmsh(const MeshRequest& r) {
  GmshSession session;
  SolidMesh mesh;
  SurfaceEntities surface_entities;
  try {
    if (r.shape == SolidShape::kCylinder || r.shape == SolidShape::kTube) {
      AddCylinder(r, surface_entities);
    } else if (r.shape == SolidShape::kBox || r.shape == SolidShape::kPlate) {
      AddBox(r, surface_entities);
    } else {
      OpenFile(r, surface_entities);
    }
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> element_tags, element_nodes;
    VolumeElements(r, types, element_tags, element_nodes);
    std::vector<std::size_t> node_tags;
    std::vector<double> coords, params;
    gmsh::model::mesh::getNodes(node_tags, coords, params, -1, -1, false, false);
    std::unordered_map<std::size_t, int> index;
    mesh.nodes.resize(long(node_tags.size()), 3);
    for (size_t i = 0; i < node_tags.size(); ++i) {
      index[node_tags[i]] = int(i);
      mesh.nodes.row(long(i)) << coords[3 * i], coords[3 * i + 1], coords[3 * i + 2];
    }
    Cells(r, types, element_nodes, index, mesh);
    NodeSets(surface_entities, index, mesh);
  } catch (const InputError&) {
    throw;
  } catch (const ResourceLimitError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError((r.file.empty() ? r.where : r.file) + ": gmsh failed: " + e.what());
  } catch (const std::string& e) {  // the gmsh API throws its last error message as a string
    throw InputError((r.file.empty() ? r.where : r.file) + ": gmsh failed: " + e);
  } catch (...) {
    throw InputError((r.file.empty() ? r.where : r.file) + ": gmsh failed (unknown error)");
  }
  return mesh;
}

}  // namespace femb
