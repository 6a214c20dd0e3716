// libFuzzer target: the readers of imported FE matrices on arbitrary files. The first
// byte picks the reader (CalculiX .sti/.mas/.dof, Abaqus matrix-input .mtx pair, Matrix Market
// pair with its DOF CSV, a Matrix Market shapes file, an Abaqus deck with a coordinate-form
// .mtx pair, a Nastran DMIG file, or Ansys matrices with their mapping file); the rest is cut at 0x01 bytes into the
// files it reads, written under FEMB_FUZZ_DIR. Seed corpus: a beam part's exported matrices in
// each format (scripts/fuzz.sh). Bad input must end in an InputError; anything else (a crash,
// another exception, a hang, an allocation past the RSS limit) is a bug.
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "formats/input_error.h"
#include "formats/part_file.h"
#include "reducer/fe/matrix_files.h"

namespace {

std::string WorkFile(const std::string& name) {
  const char* dir = std::getenv("FEMB_FUZZ_DIR");
  return std::string(dir ? dir : ".") + "/matrix_fuzz_" + name;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const int reader = data[0] % 7;
  std::vector<std::string> parts(1);
  for (size_t i = 1; i < size; ++i) {
    if (data[i] == 0x01 && parts.size() < 3) {
      parts.emplace_back();
    } else {
      parts.back().push_back(char(data[i]));
    }
  }
  parts.resize(3);
  static const char* kNames[7][3] = {{"job.sti", "job.mas", "job.dof"},
                                     {"job_STIF1.mtx", "job_MASS1.mtx", "unused"},
                                     {"K.mtx", "M.mtx", "dofs.csv"},
                                     {"shapes.mtx", "unused", "unused"},
                                     {"deck.inp", "c_STIF1.mtx", "c_MASS1.mtx"},
                                     {"job.pch", "unused", "unused"},
                                     {"K.matrix", "M.matrix", "job.mapping"}};
  std::string paths[3];
  for (int k = 0; k < 3; ++k) {
    paths[k] = WorkFile(kNames[reader][k]);
    std::ofstream(paths[k], std::ios::binary) << parts[size_t(k)];
  }
  try {
    if (reader == 3) {
      // The row count as a part file would give it: from the input, bounded.
      (void)femb::ReadShapeMatrix(paths[0], long(parts[1].size() % 64) + 1);
    } else {
      femb::MatricesSpec spec;
      spec.format = reader == 0   ? femb::MatrixFormat::kCalculix
                    : reader == 2 ? femb::MatrixFormat::kMatrixMarket
                    : reader == 5 ? femb::MatrixFormat::kNastran
                    : reader == 6 ? femb::MatrixFormat::kAnsys
                                  : femb::MatrixFormat::kAbaqus;
      spec.stiffness = reader == 4 ? paths[1] : paths[0];
      spec.mass = reader == 4 ? paths[2] : reader == 5 ? paths[0] : paths[1];
      spec.dofs = reader == 0 || reader == 2 || reader == 6 ? paths[2] : "";
      if (reader == 4) spec.deck = paths[0];
      spec.where = "fuzz/part.yaml:1";
      (void)femb::ReadImportedMatrices(spec);
    }
  } catch (const femb::InputError&) {
  }
  return 0;
}
