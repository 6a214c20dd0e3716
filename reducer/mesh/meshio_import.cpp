#include "reducer/mesh/meshio_import.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "formats/input_error.h"

#ifndef FEMB_MESHIO_BRIDGE
#define FEMB_MESHIO_BRIDGE "formats/meshio_bridge.py"
#endif

extern char** environ;

namespace femb {

bool IsGmshFile(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".msh" || ext == ".geo" || ext == ".step" || ext == ".stp" || ext == ".brep";
}

namespace {

// The bridge script: $FEMB_MESHIO_BRIDGE, else beside the running program (the build and the
// install put it there), else ../share/femb/ from it, else the source tree this was built from.
std::string BridgePath() {
  const char* env = std::getenv("FEMB_MESHIO_BRIDGE");
  if (env && *env) return env;
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (const auto& candidate : {exe.parent_path() / "meshio_bridge.py",
                                  exe.parent_path().parent_path() / "share" / "femb" / "meshio_bridge.py"}) {
      if (std::filesystem::exists(candidate)) return candidate.string();
    }
  }
  return FEMB_MESHIO_BRIDGE;
}

// Runs argv[0] with `args` (no shell: any character in a file name is safe), its stderr into
// `err_path`; returns the exit status (-1 when it could not start).
int Run(const std::vector<std::string>& args, const std::string& err_path) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  pid_t pid = 0;
  const int started = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (started != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

ForeignMesh ReadWithMeshio(const std::string& path, const std::string& where, bool any_cells) {
  // Debian's python3 sees python3-meshio; FEMB_PYTHON names another interpreter that has meshio.
  const char* env = std::getenv("FEMB_PYTHON");
  const std::string python = env && *env ? env : "/usr/bin/python3";
  if (!std::filesystem::exists(python)) {
    throw InputError(where + ": reading " + path +
                     " needs Debian's python3 and meshio: apt-get install python3-meshio");
  }
  const std::string bridge = BridgePath();
  if (!std::filesystem::exists(bridge)) {
    throw InputError(where + ": reading " + path + " needs the meshio bridge, not found at " + bridge +
                     " (install it beside femb-reduce or set FEMB_MESHIO_BRIDGE)");
  }
  static int counter = 0;
  const std::string tmp = (std::filesystem::temp_directory_path() /
                           ("femb_mesh_" + std::to_string(::getpid()) + "_" + std::to_string(counter++)))
                              .string();
  const std::string err = tmp + ".err";
  std::vector<std::string> command = {python, bridge, path, tmp};
  if (any_cells) command.insert(command.begin() + 2, "--any-cells");
  const int status = Run(command, err);
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
    if (message.empty()) message = status < 0 ? "could not run " + python : "the meshio bridge failed";
    throw InputError(where + ": " + message);
  }
  std::ifstream in(tmp);
  ForeignMesh mesh;
  auto fail = [&](const std::string& what) {
    std::filesystem::remove(tmp);
    throw InputError(where + ": the meshio bridge wrote an unreadable mesh for " + path + " (" + what + ")");
  };
  std::string word, type;
  long version = 0, n = 0, m = 0, k = 0;
  if (!(in >> word >> version) || word != "femb-mesh" || version != 1) fail("not a femb-mesh 1 file");
  if (!(in >> word >> n) || word != "nodes" || n <= 0) fail("no node count");
  mesh.nodes.resize(n, 3);
  for (long i = 0; i < n; ++i)
    if (!(in >> mesh.nodes(i, 0) >> mesh.nodes(i, 1) >> mesh.nodes(i, 2))) fail("node " + std::to_string(i));
  if (!(in >> word >> m) || word != "ids" || m != n) fail("no node ids");
  mesh.ids.resize(size_t(n));
  for (long i = 0; i < n; ++i)
    if (!(in >> mesh.ids[size_t(i)])) fail("node id " + std::to_string(i));
  if (!(in >> word >> type >> m >> k) || word != "cells") fail("no cell block");
  const std::optional<CellType> cell_type = KindOf<CellType>(type);
  if (!cell_type) fail("cell type '" + type + "'");  // it once fell back to hex20 silently
  if (m <= 0 || k != CellNodeCount(*cell_type)) fail(type + " cells with " + std::to_string(k) + " nodes");
  mesh.cell_type = *cell_type;
  mesh.cells.resize(m, k);
  for (long e = 0; e < m; ++e)
    for (long a = 0; a < k; ++a)
      if (!(in >> mesh.cells(e, a)) || mesh.cells(e, a) < 0 || mesh.cells(e, a) >= n) fail("cell " + std::to_string(e));
  std::string name;
  long count;
  while (in >> word >> name >> count) {
    if (word != "set" || count < 0) fail("set '" + name + "'");
    std::vector<int>& set = mesh.node_sets[name];
    set.resize(count);
    for (long i = 0; i < count; ++i)
      if (!(in >> set[i]) || set[i] < 0 || set[i] >= n) fail("set '" + name + "'");
    std::sort(set.begin(), set.end());
  }
  if (!in.eof()) fail("trailing data");
  std::filesystem::remove(tmp);
  return mesh;
}

SolidMesh ImportWithMeshio(const std::string& path, const std::string& where) {
  ForeignMesh foreign = ReadWithMeshio(path, where, false);
  const std::optional<SolidType> type = SolidTypeOf(foreign.cell_type);
  if (!type) throw InputError(where + ": " + path + " has no volume elements");
  SolidMesh mesh;
  mesh.nodes = std::move(foreign.nodes);
  mesh.type = *type;
  mesh.cells = std::move(foreign.cells);
  mesh.node_sets = std::move(foreign.node_sets);
  return mesh;
}

}  // namespace femb
