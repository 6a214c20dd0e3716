// formats/hdf5_file: what the Writer stores is what the Reader (and HDF5's own C API, read here
// without femb) finds, to the bit; every kind of wrong request names the file and the object.
#include "formats/hdf5_file.h"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "formats/input_error.h"
#include "test_util.h"

namespace femb {
namespace {

namespace fs = std::filesystem;

std::string TempPath(const std::string& name) {
  return (fs::temp_directory_path() / ("femb_hdf5_test_" + std::to_string(::getpid()) + "_" + name)).string();
}

// A dataset's shape, type class and filters as HDF5 itself reports them (no femb code).
struct Stored {
  std::vector<hsize_t> shape;
  H5T_class_t type_class = H5T_NO_CLASS;
  size_t type_size = 0;
  H5D_layout_t layout = H5D_LAYOUT_ERROR;
  std::vector<H5Z_filter_t> filters;
};
Stored StoredAs(const std::string& path, const std::string& name) {
  Stored s;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t set = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(set);
  s.shape.resize(size_t(H5Sget_simple_extent_ndims(space)));
  H5Sget_simple_extent_dims(space, s.shape.data(), nullptr);
  const hid_t type = H5Dget_type(set);
  s.type_class = H5Tget_class(type);
  s.type_size = H5Tget_size(type);
  const hid_t plist = H5Dget_create_plist(set);
  s.layout = H5Pget_layout(plist);
  for (int i = 0; i < H5Pget_nfilters(plist); ++i) {
    unsigned flags = 0;
    size_t n = 0;
    unsigned config = 0;
    s.filters.push_back(H5Pget_filter2(plist, unsigned(i), &flags, &n, nullptr, 0, nullptr, &config));
  }
  H5Pclose(plist);
  H5Tclose(type);
  H5Sclose(space);
  H5Dclose(set);
  H5Fclose(file);
  return s;
}

// Every kind of dataset and attribute reads back as written: doubles and integers to the bit, in
// the row-major layout every other HDF5 reader sees (element (i, j) of a matrix at i * cols + j,
// read here with HDF5's own H5Dread).
TEST(Hdf5File, EveryKindReadsBackToTheBit) {
  const std::string path = TempPath("kinds.h5");
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1e3);
  Eigen::MatrixXd A(5, 3);
  for (Eigen::Index i = 0; i < A.size(); ++i) A.data()[i] = normal(rng);
  A(0, 0) = std::nextafter(1.0, 2.0);  // the last bit of the mantissa
  A(1, 2) = -0.0;
  const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(7, -1.0, 1e-300);
  Eigen::MatrixXi I(2, 4);
  I << 1, -2, 3, 2147483647, -2147483647, 0, 5, 6;
  const std::vector<int> iv{4, 0, -9};
  const std::vector<std::string> words{"A", "", "a longer name with spaces", "\xc3\xa9t\xc3\xa9"};
  {
    h5::Writer w(path);
    w.CreateGroup("/g");
    w.Matrix("/g/A", A);
    w.Vector("/v", v);
    w.IntMatrix("/g/I", I);
    w.IntVector("/iv", iv);
    w.Scalar("/s", M_PI);
    w.Strings("/names", words);
    w.Attribute("/", "title", std::string("femb test"));
    w.Attribute("/g", "count", 42L);
    w.Close();
  }
  h5::Reader r(path);
  EXPECT_TRUE(r.Exists("/g/A"));
  EXPECT_TRUE(r.Exists("/g"));
  EXPECT_FALSE(r.Exists("/g/B"));
  EXPECT_FALSE(r.Exists("/nothing/below"));
  const Eigen::MatrixXd A2 = r.Matrix("/g/A");
  ASSERT_EQ(A2.rows(), 5);
  ASSERT_EQ(A2.cols(), 3);
  for (Eigen::Index i = 0; i < A.size(); ++i) EXPECT_EQ(std::memcmp(&A.data()[i], &A2.data()[i], sizeof(double)), 0);
  EXPECT_TRUE(std::signbit(A2(1, 2)));
  EXPECT_EQ(r.Vector("/v"), v);
  EXPECT_EQ(r.IntMatrix("/g/I"), I);
  const Eigen::VectorXi iv2 = r.IntVector("/iv");
  EXPECT_EQ(std::vector<int>(iv2.data(), iv2.data() + iv2.size()), iv);
  EXPECT_EQ(r.Scalar("/s"), M_PI);
  EXPECT_EQ(r.Strings("/names"), words);
  EXPECT_EQ(r.StringAttribute("/", "title"), "femb test");
  EXPECT_TRUE(r.HasAttribute("/g", "count"));
  EXPECT_FALSE(r.HasAttribute("/g", "title"));
  EXPECT_EQ(r.IntAttribute("/g", "count"), 42);
  EXPECT_EQ(r.Shape("/g/A"), (std::vector<hsize_t>{5, 3}));
  EXPECT_EQ(r.Shape("/v"), (std::vector<hsize_t>{7}));
  EXPECT_TRUE(r.Shape("/s").empty());

  // The layout other readers see: row-major doubles and 32-bit integers.
  const Stored a = StoredAs(path, "/g/A");
  EXPECT_EQ(a.shape, (std::vector<hsize_t>{5, 3}));
  EXPECT_EQ(a.type_class, H5T_FLOAT);
  EXPECT_EQ(a.type_size, 8u);
  std::vector<double> raw(15);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t set = H5Dopen2(file, "/g/A", H5P_DEFAULT);
  ASSERT_GE(H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, raw.data()), 0);
  H5Dclose(set);
  H5Fclose(file);
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 3; ++j) EXPECT_EQ(raw[size_t(3 * i + j)], A(i, j));
  }
  const Stored ints = StoredAs(path, "/g/I");
  EXPECT_EQ(ints.type_class, H5T_INTEGER);
  EXPECT_EQ(ints.type_size, 4u);
  fs::remove(path);
}

// Single precision: chunked, shuffled and deflated (filters every HDF5 reader has), the values
// rounded to multiples of `step` when one is given, and so a smooth field compresses.
// Lists of strings are converted through a buffer sized to the list (hdf5_file.cpp): lists
// below, near and above the default 1 MiB of descriptors, with strings far longer than a
// descriptor, read back whole.
TEST(Hdf5File, StringListsOfEverySizeReadBack) {
  const std::string path = TempPath("strings.h5");
  std::vector<std::vector<std::string>> lists;
  for (const size_t n : {size_t(1), size_t(3000), size_t(40000), size_t(70000)}) {
    std::vector<std::string> list(n);
    for (size_t i = 0; i < n; ++i) list[i] = std::string(i % 700, char('a' + i % 26)) + std::to_string(i);
    lists.push_back(list);
  }
  {
    h5::Writer w(path);
    for (size_t k = 0; k < lists.size(); ++k) w.Strings("/list" + std::to_string(k), lists[k]);
    w.Close();
  }
  h5::Reader r(path);
  for (size_t k = 0; k < lists.size(); ++k) EXPECT_EQ(r.Strings("/list" + std::to_string(k)), lists[k]) << k;
}

TEST(Hdf5File, FloatMatrixIsRoundedAndCompressed) {
  const std::string path = TempPath("float.h5");
  const int rows = 4000;
  Eigen::MatrixXf F(rows, 3);
  for (int i = 0; i < rows; ++i) {
    const float s = float(i) / rows;
    F.row(i) << std::sin(6.0f * s), std::cos(6.0f * s), 0.1f * s;
  }
  const float step = std::ldexp(1.0f, -12);
  {
    h5::Writer w(path, /*v110=*/true);
    w.FloatMatrix("/exact", F);
    w.FloatMatrix("/rounded", F, step);
    w.Close();
  }
  h5::Reader r(path);
  EXPECT_EQ(r.FloatMatrix("/exact"), F);
  const Eigen::MatrixXf G = r.FloatMatrix("/rounded");
  ASSERT_EQ(G.rows(), rows);
  for (Eigen::Index i = 0; i < G.size(); ++i) {
    EXPECT_LE(std::abs(G.data()[i] - F.data()[i]), 0.5f * step);
    EXPECT_EQ(G.data()[i], std::round(G.data()[i] / step) * step);  // a multiple of the step
  }
  // The double-precision reader takes the same values.
  EXPECT_EQ(r.Matrix("/rounded"), G.cast<double>());
  const Stored s = StoredAs(path, "/rounded");
  EXPECT_EQ(s.type_class, H5T_FLOAT);
  EXPECT_EQ(s.type_size, 4u);
  EXPECT_EQ(s.layout, H5D_CHUNKED);
  EXPECT_EQ(s.filters, (std::vector<H5Z_filter_t>{H5Z_FILTER_SHUFFLE, H5Z_FILTER_DEFLATE}));
  // Stored in less than the raw 48 kB: the rounded field at most a third of it.
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t set = H5Dopen2(file, "/rounded", H5P_DEFAULT);
  const hsize_t stored = H5Dget_storage_size(set);
  H5Dclose(set);
  H5Fclose(file);
  EXPECT_LT(stored, hsize_t(rows * 3 * 4 / 3));
  fs::remove(path);
}

// CopyFrom takes datasets with their stored chunks and filters as they are (H5Ocopy).
TEST(Hdf5File, CopyFromKeepsDataAndFilters) {
  const std::string from = TempPath("from.h5"), to = TempPath("to.h5");
  Eigen::MatrixXf F = Eigen::MatrixXf::Random(300, 2);
  {
    h5::Writer w(from, true);
    w.FloatMatrix("/frame", F);
    w.Vector("/time", Eigen::VectorXd::LinSpaced(3, 0.0, 1.0));
    w.Close();
  }
  {
    h5::Writer w(to, true);
    w.CopyFrom(from, {"/frame", "/time"});
    w.Close();
  }
  h5::Reader r(to);
  EXPECT_EQ(r.FloatMatrix("/frame"), F);
  EXPECT_EQ(r.Vector("/time"), Eigen::VectorXd::LinSpaced(3, 0.0, 1.0));
  EXPECT_EQ(StoredAs(to, "/frame").filters, StoredAs(from, "/frame").filters);
  {
    h5::Writer w(TempPath("to2.h5"));
    const std::string message = test::ErrorOf([&] { w.CopyFrom(from, {"/absent"}); });
    EXPECT_NE(message.find("cannot copy /absent from " + from), std::string::npos) << message;
  }
  fs::remove(from);
  fs::remove(to);
  fs::remove(TempPath("to2.h5"));
}

// Each wrong request is one message naming the file and the object.
TEST(Hdf5File, WrongRequestsNameFileAndObject) {
  const std::string path = TempPath("wrong.h5");
  {
    h5::Writer w(path);
    w.Matrix("/A", Eigen::MatrixXd::Ones(2, 2));
    w.Vector("/v", Eigen::VectorXd::Ones(3));
    w.Strings("/names", {"x"});
    w.Attribute("/", "count", 3L);
    w.Close();
  }
  h5::Reader r(path);
  const auto expect = [&](const std::string& message, const std::string& what) {
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
  };
  expect(test::ErrorOf([&] { r.Matrix("/B"); }), "missing dataset /B");
  expect(test::ErrorOf([&] { r.Vector("/A"); }), "dataset /A must be 1-dimensional, got rank 2");
  expect(test::ErrorOf([&] { r.Matrix("/v"); }), "dataset /v must be 2-dimensional, got rank 1");
  expect(test::ErrorOf([&] { r.Scalar("/v"); }), "dataset /v must hold one number");
  expect(test::ErrorOf([&] { r.Matrix("/names"); }), "/names");
  expect(test::ErrorOf([&] { r.StringAttribute("/", "title"); }), "missing attribute /@title");
  expect(test::ErrorOf([&] { r.StringAttribute("/", "count"); }), "attribute /@count must be a fixed-length string");
  expect(test::ErrorOf([&] { r.IntAttribute("/A", "count"); }), "missing attribute /A@count");
  // Not a file, and not an HDF5 file.
  const std::string none = TempPath("none.h5");
  EXPECT_NE(test::ErrorOf([&] { h5::Reader bad(none); }).find(none), std::string::npos);
  const std::string text = TempPath("text.h5");
  {
    std::FILE* f = std::fopen(text.c_str(), "w");
    std::fputs("not hdf5\n", f);
    std::fclose(f);
  }
  EXPECT_NE(test::ErrorOf([&] { h5::Reader bad(text); }).find(text), std::string::npos);
  // A writer into a folder that does not exist.
  const std::string nowhere = TempPath("no_such_dir") + "/x.h5";
  EXPECT_NE(test::ErrorOf([&] { h5::Writer bad(nowhere); }).find(nowhere), std::string::npos);
  fs::remove(path);
  fs::remove(text);
}

}  // namespace
}  // namespace femb
