// libFuzzer target: the superelement loader and the load-time checks on corrupted files. Each
// input is a list of mutations of a valid superelement ($FEMB_FUZZ_SEED_H5): a value of a dataset
// set to NaN, Inf, 0, a huge or a negative number; a matrix grown or shrunk by a row or a column;
// a count changed; a dataset or attribute deleted from the written file. Every outcome must be
// an InputError from the reader or the checks, or a superelement that passes the checks and on
// which a body's frame solve and elastic force are finite.
#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "formats/input_error.h"
#include "formats/superelement_checks.h"
#include "formats/superelement_file.h"
#include "solver/body/superelement_body.h"
#include "tests/fuzz/fuzz_input.h"

namespace {

femb::Superelement seed;
std::string path;

Eigen::MatrixXd& Pick(femb::Superelement& se, unsigned which, Eigen::MatrixXd& scratch) {
  switch (which) {
    case 0:
      return se.K;
    case 1:
      return se.M;
    case 2:
      return se.floating_frame.Phi_CB;
    default:
      return scratch;
  }
}

double Special(unsigned k, double old) {
  const double values[] = {std::nan(""), HUGE_VAL, -HUGE_VAL, 0.0, 1e308, -old, old * (1 + 1e-6), 1e-300};
  return values[k % 8];
}

void Mutate(femb::Superelement& se, femb::fuzz::Input& in) {
  Eigen::MatrixXd scratch;
  switch (in.Below(8)) {
    case 0: {  // one value of a matrix (K, M, Phi_CB, the inertia, the frame orientation)
      const unsigned which = in.Below(5);
      double* data = which == 3   ? se.mass_properties.inertia_com.data()
                     : which == 4 ? se.floating_frame.orientation.data()
                                  : Pick(se, which, scratch).data();
      const long size = which >= 3 ? 9 : long(Pick(se, which, scratch).size());
      if (size == 0) return;
      const unsigned i = in.Below(unsigned(size));
      data[i] = Special(in.Byte(), data[i]);
      return;
    }
    case 1: {  // a matrix grown or shrunk by a row or a column
      Eigen::MatrixXd& A = Pick(se, in.Below(3), scratch);
      const long dr = long(in.Below(3)) - 1, dc = long(in.Below(3)) - 1;
      A.conservativeResize(std::max(0L, A.rows() + dr), std::max(0L, A.cols() + dc));
      return;
    }
    case 2: {  // an interface's position or orientation
      if (se.interfaces.empty()) return;
      femb::InterfaceNode& node = se.interfaces[in.Below(unsigned(se.interfaces.size()))];
      const unsigned i = in.Below(12);
      if (i < 3)
        node.position[i] = Special(in.Byte(), node.position[i]);
      else
        node.orientation.data()[i - 3] = Special(in.Byte(), node.orientation.data()[i - 3]);
      return;
    }
    case 3:  // an interface removed or duplicated
      if (in.Byte() % 2 && !se.interfaces.empty())
        se.interfaces.pop_back();
      else if (!se.interfaces.empty())
        se.interfaces.push_back(se.interfaces.front());
      return;
    case 4:  // internal frequencies / modal derivative counts
      se.internal_frequencies_hz.conservativeResize(
          std::max(0L, long(se.internal_frequencies_hz.size()) + long(in.Below(3)) - 1));
      se.n_modal_derivatives = long(in.Below(5)) - 1;
      if (in.Byte() % 2) se.modal_derivative_pairs.emplace_back(int(in.Below(40)) - 5, int(in.Below(40)) - 5);
      return;
    case 5:
      se.floating_frame.origin[in.Below(3)] = Special(in.Byte(), 1.0);
      return;
    case 6:
      se.mass_properties.mass = Special(in.Byte(), se.mass_properties.mass);
      return;
    default:
      se.floating_frame.type = in.Byte() % 2 ? "" : "interface:nowhere";
      return;
  }
}

void DeleteSomething(unsigned which) {
  const char* datasets[] = {"/reduced/K",
                            "/reduced/M",
                            "/floating_frame/Phi_CB",
                            "/interfaces/names",
                            "/interfaces/positions",
                            "/mass_properties/mass",
                            "/reduced/internal_frequencies_hz",
                            "/floating_frame/origin"};
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  if (file < 0) return;
  if (which < 8) {
    H5Ldelete(file, datasets[which], H5P_DEFAULT);
  } else {
    H5Adelete(file, which == 8 ? "format_version_major" : "name");
  }
  H5Fclose(file);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const char* seed_path = std::getenv("FEMB_FUZZ_SEED_H5");
  if (!seed_path) std::abort();
  seed = femb::ReadSuperelementFile(seed_path);
  path = "/tmp/femb_superelement_fuzz_" + std::to_string(getpid()) + ".h5";
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  femb::fuzz::Input in(data, size);
  femb::Superelement se = seed;
  const unsigned mutations = in.Below(4) + 1;
  for (unsigned k = 0; k < mutations && !in.empty(); ++k) Mutate(se, in);
  try {
    femb::WriteSuperelementFile(se, path);
  } catch (const femb::InputError&) {
    return 0;
  }
  if (in.Byte() % 4 == 0) DeleteSomething(in.Below(10));
  try {
    femb::SuperelementReadOptions options;
    options.visualization = true;
    const femb::Superelement loaded = femb::ReadSuperelementFile(path, options);
    femb::RequireValidSuperelement(loaded, path);
    const femb::SuperelementBody body(loaded, femb::SuperelementOptions{}, Eigen::Matrix3d::Identity(),
                                      Eigen::Vector3d::Zero());
    const femb::BodyConfiguration c = InitialConfiguration(body);
    const femb::FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
    if (frame.ok) {
      Eigen::VectorXd f;
      Eigen::MatrixXd K;
      femb::BodyData data = Evaluate(body, c, frame);
      ElasticForce(body, data, &f, &K);
      if (!f.allFinite() || !K.allFinite()) std::abort();  // a file that passed the checks
    }
  } catch (const femb::InputError&) {
  }
  return 0;
}
