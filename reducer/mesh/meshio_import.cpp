#include "reducer/mesh/meshio_import.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "formats/input_error.h"

#ifndef FEMB_MESHIO_BRIDGE
#define FEMB_MESHIO_BRIDGE "formats/meshio_bridge.py"
#endif

namespace femb {

bool IsGmshFile(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".msh" || ext == ".geo" || ext == ".step" || ext == ".stp" || ext == ".brep";
}

SolidMesh ImportWithMeshio(const std::string& path, const std::string& where) {
  // Debian's python3 sees python3-meshio; FEMB_PYTHON names another interpreter that has meshio.
  const char* env = std::getenv("FEMB_PYTHON");
  const std::string python = env && *env ? env : "/usr/bin/python3";
  if (!std::filesystem::exists(python)) {
    throw InputError(where + ": reading " + path + " needs Debian's python3 and meshio: apt-get install python3-meshio");
  }
  const std::string tmp = (std::filesystem::temp_directory_path() / ("femb_mesh_" + std::to_string(::getpid()))).string();
  const std::string err = tmp + ".err";
  const std::string command = python + " '" + FEMB_MESHIO_BRIDGE + "' '" + path + "' '" + tmp + "' 2> '" + err + "'";
  const int status = std::system(command.c_str());
  std::string message;
  {
    // The bridge's own one-line message comes last (meshio may print before it).
    std::ifstream e(err);
    for (std::string line; std::getline(e, line);) {
      if (!line.empty()) message = line;
    }
  }
  std::filesystem::remove(err);
  if (status != 0) {
    std::filesystem::remove(tmp);
    if (message.empty()) message = "the meshio bridge failed";
    throw InputError(where + ": " + message);
  }
  std::ifstream in(tmp);
  SolidMesh mesh;
  std::string word, type;
  long n = 0, m = 0, k = 0;
  in >> word >> n;  // femb-mesh 1
  in >> word >> n;
  mesh.nodes.resize(n, 3);
  for (long i = 0; i < n; ++i) in >> mesh.nodes(i, 0) >> mesh.nodes(i, 1) >> mesh.nodes(i, 2);
  in >> word >> type >> m >> k;
  if (type == "tet4") mesh.type = SolidType::kTet4;
  else if (type == "tet10") mesh.type = SolidType::kTet10;
  else if (type == "hex8") mesh.type = SolidType::kHex8;
  else mesh.type = SolidType::kHex20;
  mesh.cells.resize(m, k);
  for (long e = 0; e < m; ++e)
    for (long a = 0; a < k; ++a) in >> mesh.cells(e, a);
  std::string name;
  long count;
  while (in >> word >> name >> count) {
    std::vector<int>& set = mesh.node_sets[name];
    set.resize(count);
    for (long i = 0; i < count; ++i) in >> set[i];
    std::sort(set.begin(), set.end());
  }
  std::filesystem::remove(tmp);
  if (!in.eof() && in.fail()) throw InputError(where + ": the meshio bridge wrote an unreadable mesh for " + path);
  return mesh;
}

}  // namespace femb
