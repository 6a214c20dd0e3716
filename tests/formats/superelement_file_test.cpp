// Superelement HDF5 file: round trip, atomic write, and one clear error per kind of bad file.
#include "formats/superelement_file.h"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <Eigen/Geometry>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <thread>

#include "formats/hdf5_file.h"
#include "test_util.h"

namespace femb {
namespace {

namespace fs = std::filesystem;

Superelement Sample() {
  Superelement se = test::Reduce(test::StraightBeamYaml(
      0.3, 6, "{shape: circle, diameter: 0.006}", "{E: 2.0e11, nu: 0.3, rho: 7870}", "[{name: A}, {name: B}]",
      "reduction: {internal_modes: 3, full_modes: 4, floating_frame: cardona}\n"));
  se.interfaces[1].orientation = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  return se;
}

std::string TempPath(const std::string& name) {
  return (fs::temp_directory_path() / ("femb_test_" + std::to_string(::getpid()) + "_" + name)).string();
}

TEST(SuperelementFile, RoundTripKeepsEverything) {
  const Superelement a = Sample();
  const std::string path = TempPath("roundtrip.h5");
  WriteSuperelementFile(a, path);
  const Superelement b = ReadSuperelementFile(path);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.units.system, b.units.system);
  EXPECT_EQ(a.units.stress, b.units.stress);
  ASSERT_EQ(a.interfaces.size(), b.interfaces.size());
  for (size_t k = 0; k < a.interfaces.size(); ++k) {
    EXPECT_EQ(a.interfaces[k].name, b.interfaces[k].name);
    EXPECT_EQ(a.interfaces[k].position, b.interfaces[k].position);
    EXPECT_EQ(a.interfaces[k].orientation, b.interfaces[k].orientation);
  }
  EXPECT_EQ(a.K, b.K);  // bit-exact: doubles are stored as IEEE binary64
  EXPECT_EQ(a.M, b.M);
  EXPECT_EQ(a.internal_frequencies_hz, b.internal_frequencies_hz);
  EXPECT_EQ(a.full_free_free_frequencies_hz, b.full_free_free_frequencies_hz);
  EXPECT_EQ(a.floating_frame.type, b.floating_frame.type);
  EXPECT_EQ(a.floating_frame.origin, b.floating_frame.origin);
  EXPECT_EQ(a.floating_frame.Phi_CB, b.floating_frame.Phi_CB);
  EXPECT_EQ(a.floating_frame.cardona_weights, b.floating_frame.cardona_weights);
  EXPECT_EQ(a.mass_properties.mass, b.mass_properties.mass);
  EXPECT_EQ(a.mass_properties.center_of_mass, b.mass_properties.center_of_mass);
  EXPECT_EQ(a.mass_properties.inertia_com, b.mass_properties.inertia_com);
  EXPECT_EQ(a.n_full_dofs, b.n_full_dofs);
  ASSERT_TRUE(b.visualization.has_value());
  EXPECT_EQ(a.visualization->nodes, b.visualization->nodes);
  EXPECT_EQ(a.visualization->cells, b.visualization->cells);
  EXPECT_EQ(a.visualization->shapes, b.visualization->shapes);
  EXPECT_EQ(a.provenance.input_hash, b.provenance.input_hash);
  EXPECT_EQ(a.provenance.stage_seconds.size(), b.provenance.stage_seconds.size());
  // Without visualization on request.
  SuperelementReadOptions light;
  light.visualization = false;
  EXPECT_FALSE(ReadSuperelementFile(path, light).visualization.has_value());
  fs::remove(path);
}

// The animation's compressed frames (h5::PackFloats on two threads: a column a chunk, shuffled
// and deflated; h5::Writer::Packed writes the chunks as they are) read back exactly through
// HDF5's own filter pipeline, as FloatMatrix's: a smooth field shrinks, random bits that do not
// compress are stored unfiltered, a column longer than 2^20 rows is split into equal chunks
// (the last one padded), and an empty matrix is written too.
TEST(Hdf5Writer, PackedFramesReadBackExactly) {
  const std::string path = TempPath("compressed.h5");
  Eigen::MatrixXf smooth(5000, 3), noise(700, 3), empty(0, 3);
  Eigen::MatrixXf tall(1300000, 1);
  for (int i = 0; i < smooth.rows(); ++i)
    smooth.row(i) << std::round(1e4f * std::sin(1e-3f * i)) / 1024.0f, 0.5f, float(i % 7);
  // Random bits in every byte (finite numbers: exponent field 1..254).
  std::mt19937 random(5);
  for (Eigen::Index i = 0; i < noise.size(); ++i) {
    const uint32_t u = random(), bits = (u & 0x807fffffu) | ((1u + (u >> 7) % 254u) << 23);
    std::memcpy(noise.data() + i, &bits, sizeof bits);
  }
  for (int i = 0; i < tall.rows(); ++i) tall(i, 0) = float(i % 1000) / 8.0f;
  // Between the two: numbers in [1, 2) with random mantissas, whose sign and exponent bytes
  // deflate and whose low mantissa bytes are stored as they are, in one stream.
  Eigen::MatrixXf mixed(4000, 2);
  for (Eigen::Index i = 0; i < mixed.size(); ++i) {
    const uint32_t bits = 0x3f800000u | (uint32_t(random()) & 0x007fffffu);
    std::memcpy(mixed.data() + i, &bits, sizeof bits);
  }
  std::vector<h5::PackedFloats> packed(5);
  packed[4] = h5::PackFloats("/mixed", mixed.data(), mixed.rows(), mixed.cols());
  for (const auto& c : packed[4].chunks) EXPECT_FALSE(c.raw);
  EXPECT_LT(packed[4].stored_bytes(), mixed.size() * sizeof(float) * 0.8);
  std::thread other([&] { packed[1] = h5::PackFloats("/noise", noise.data(), noise.rows(), noise.cols()); });
  packed[0] = h5::PackFloats("/smooth", smooth.data(), smooth.rows(), smooth.cols());
  packed[2] = h5::PackFloats("/empty", empty.data(), empty.rows(), empty.cols());
  packed[3] = h5::PackFloats("/tall", tall.data(), tall.rows(), tall.cols());
  other.join();
  EXPECT_EQ(packed[0].chunks.size(), 3u);
  for (const auto& c : packed[1].chunks) EXPECT_TRUE(c.raw);
  EXPECT_EQ(packed[3].chunks.size(), 2u);
  EXPECT_EQ(packed[3].chunk_rows, 650000u);
  {
    h5::Writer w(path, /*v110=*/true);
    for (const auto& p : packed) w.Packed(p);
    w.FloatMatrix("/plain", smooth);
    w.Close();
  }
  h5::Reader r(path);
  EXPECT_EQ(r.Matrix("/smooth"), smooth.cast<double>());
  EXPECT_EQ(r.Matrix("/noise"), noise.cast<double>());
  EXPECT_EQ(r.Matrix("/tall"), tall.cast<double>());
  EXPECT_EQ(r.Matrix("/mixed"), mixed.cast<double>());
  EXPECT_EQ(r.Matrix("/plain"), smooth.cast<double>());
  EXPECT_EQ(r.Shape("/empty"), (std::vector<hsize_t>{0, 3}));
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t set = H5Dopen2(file, "/smooth", H5P_DEFAULT);
  EXPECT_LT(H5Dget_storage_size(set), smooth.size() * sizeof(float) / 3);
  EXPECT_EQ(H5Dget_storage_size(set), packed[0].stored_bytes());
  H5Dclose(set);
  H5Fclose(file);
  fs::remove(path);
}

TEST(SuperelementFile, FailedWriteLeavesNoFile) {
  const std::string dir = TempPath("no_such_dir");
  const std::string message = test::ThrownMessage([&] { WriteSuperelementFile(Sample(), dir + "/out.h5"); });
  EXPECT_NE(message.find("cannot create HDF5 file"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir));
}

TEST(SuperelementFile, WriteReplacesAtomicallyAndLeavesNoTemporary) {
  const std::string path = TempPath("atomic.h5");
  WriteSuperelementFile(Sample(), path);
  WriteSuperelementFile(Sample(), path);
  for (const auto& entry : fs::directory_iterator(fs::path(path).parent_path())) {
    EXPECT_EQ(entry.path().string().find(path + ".tmp"), std::string::npos) << entry.path();
  }
  fs::remove(path);
}

TEST(SuperelementFile, MissingFile) {
  EXPECT_NE(test::ThrownMessage([] {
              ReadSuperelementFile("/nonexistent/x.h5");
            }).find("/nonexistent/x.h5: cannot open file"),
            std::string::npos);
}

TEST(SuperelementFile, TruncatedFile) {
  const std::string path = TempPath("truncated.h5");
  WriteSuperelementFile(Sample(), path);
  const auto size = fs::file_size(path);
  fs::resize_file(path, size / 2);
  const std::string message = test::ThrownMessage([&] { ReadSuperelementFile(path); });
  EXPECT_EQ(message.find(path + ": "), 0u) << message;
  EXPECT_NE(message.find("truncated"), std::string::npos) << message;
  fs::remove(path);
}

TEST(SuperelementFile, NotHdf5) {
  const std::string path = TempPath("text.h5");
  std::ofstream(path) << "hello";
  EXPECT_NE(test::ThrownMessage([&] { ReadSuperelementFile(path); }).find("not an HDF5 file"), std::string::npos);
  fs::remove(path);
}

// Edits a written file with the raw HDF5 API.
void Edit(const std::string& path, const std::function<void(hid_t)>& edit) {
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  edit(f);
  H5Fclose(f);
}

TEST(SuperelementFile, OtherMajorVersionIsRefused) {
  const std::string path = TempPath("v2.h5");
  WriteSuperelementFile(Sample(), path);
  Edit(path, [](hid_t f) {
    hid_t a = H5Aopen_by_name(f, "/", "format_version_major", H5P_DEFAULT, H5P_DEFAULT);
    long two = 2;
    H5Awrite(a, H5T_NATIVE_LONG, &two);
    H5Aclose(a);
  });
  const std::string message = test::ThrownMessage([&] { ReadSuperelementFile(path); });
  EXPECT_NE(message.find("is not supported by this femb (reads major version 1)"), std::string::npos) << message;
  fs::remove(path);
}

TEST(SuperelementFile, MissingDatasetIsNamed) {
  const std::string path = TempPath("missing.h5");
  WriteSuperelementFile(Sample(), path);
  Edit(path, [](hid_t f) { H5Ldelete(f, "/reduced/M", H5P_DEFAULT); });
  const std::string message = test::ThrownMessage([&] { ReadSuperelementFile(path); });
  EXPECT_EQ(message, path + ": missing dataset /reduced/M");
  fs::remove(path);
}

TEST(SuperelementFile, InconsistentShapesAreNamed) {
  const std::string path = TempPath("shape.h5");
  Superelement se = Sample();
  se.floating_frame.Phi_CB = Eigen::MatrixXd::Zero(6, 3);
  WriteSuperelementFile(se, path);
  const std::string message = test::ThrownMessage([&] { ReadSuperelementFile(path); });
  EXPECT_NE(message.find("dataset /floating_frame/Phi_CB has shape (6 x 3), expected (6 x 15)"), std::string::npos)
      << message;
  fs::remove(path);
}

}  // namespace
}  // namespace femb
