// A part reduced by the femb-reduce program beside this benchmark, read back from its file.
//
// Why not the reducer library in-process: the reducer is built with EIGEN_USE_BLAS and the
// solver without (OpenBLAS called from two body threads at once made femb-solve 20% slower), so
// a program linking both would have Eigen's product templates compiled two ways under the same
// names, and which one runs in the solver is the linker's pick. A benchmark of the solver's hot
// path links the solver alone and so times the kernels femb-solve runs.
#pragma once

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "formats/superelement_file.h"

namespace femb::bench {

inline Superelement ReducedByTheTool(const char* argv0, const std::string& part_yaml) {
  namespace fs = std::filesystem;
  const fs::path tool = fs::absolute(fs::path(argv0)).parent_path() / "femb-reduce";
  char pattern[] = "/tmp/femb_bench_XXXXXX";
  if (!mkdtemp(pattern)) throw std::runtime_error("cannot make a temporary folder");
  const fs::path dir(pattern), part = dir / "part.yaml", file = dir / "part.h5";
  std::ofstream(part) << part_yaml;
  const std::string command = "'" + tool.string() + "' -q '" + part.string() + "' -o '" + file.string() + "'";
  const int status = std::system(command.c_str());
  if (status != 0) {
    fs::remove_all(dir);
    throw std::runtime_error(command + ": failed (" + std::to_string(status) + ")");
  }
  Superelement se = ReadSuperelementFile(file.string());
  fs::remove_all(dir);
  return se;
}

}  // namespace femb::bench
