#include "formats/hdf5_file.h"

#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <thread>

#include "formats/input_error.h"

namespace femb::h5 {
namespace {

// HDF5 prints its own error stacks by default; femb reports one line instead.
void SilenceHdf5() {
  static const bool once = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)once;
}

herr_t CloseAny(hid_t id) {
  switch (H5Iget_type(id)) {
    case H5I_FILE: return H5Fclose(id);
    case H5I_GROUP: return H5Gclose(id);
    case H5I_DATASET: return H5Dclose(id);
    case H5I_DATASPACE: return H5Sclose(id);
    case H5I_DATATYPE: return H5Tclose(id);
    case H5I_ATTR: return H5Aclose(id);
    case H5I_GENPROP_LST: return H5Pclose(id);
    default: return -1;
  }
}

Handle Own(hid_t id) { return Handle(id, CloseAny); }

}  // namespace

Handle& Handle::operator=(Handle&& o) noexcept {
  if (this != &o) {
    if (id_ >= 0 && closer_) closer_(id_);
    id_ = o.id_;
    closer_ = o.closer_;
    o.id_ = -1;
  }
  return *this;
}

Handle::~Handle() {
  if (id_ >= 0 && closer_) closer_(id_);
}

// ---------------------------------------------------------------------------------------------
Writer::Writer(const std::string& path, bool v110) : path_(path) {
  SilenceHdf5();
  Handle access = Own(H5Pcreate(H5P_FILE_ACCESS));
  if (v110) H5Pset_libver_bounds(access.id(), H5F_LIBVER_V110, H5F_LIBVER_V110);
  hid_t id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access.id());
  if (id < 0) throw InputError(path + ": cannot create HDF5 file (check the folder exists and is writable)");
  file_ = Own(id);
}

void Writer::CreateGroup(const std::string& group) {
  Handle g = Own(H5Gcreate2(file_.id(), group.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (g.id() < 0) throw InputError(path_ + ": cannot create group " + group);
}

void Writer::WriteData(const std::string& name, const std::vector<hsize_t>& shape, hid_t file_type,
                       hid_t memory_type, const void* data, bool compress) {
  Handle space = Own(shape.empty() ? H5Screate(H5S_SCALAR)
                                   : H5Screate_simple(int(shape.size()), shape.data(), nullptr));
  Handle create = Own(H5Pcreate(H5P_DATASET_CREATE));
  if (compress && shape.size() == 2 && shape[0] > 0 && shape[1] > 0 && H5Zfilter_avail(H5Z_FILTER_DEFLATE) > 0) {
    // Chunks of about 1 MB of rows: deflate level 1 (level 4 made the files 3% smaller at twice
    // the time).
    const hsize_t chunk[2] = {std::min<hsize_t>(shape[0], std::max<hsize_t>(1, (hsize_t(1) << 18) / shape[1])), shape[1]};
    if (H5Pset_chunk(create.id(), 2, chunk) < 0 || H5Pset_shuffle(create.id()) < 0 || H5Pset_deflate(create.id(), 1) < 0) {
      throw InputError(path_ + ": cannot set the compression of dataset " + name);
    }
  }
  Handle set = Own(H5Dcreate2(file_.id(), name.c_str(), file_type, space.id(), H5P_DEFAULT,
                              create.id(), H5P_DEFAULT));
  if (set.id() < 0 ||
      H5Dwrite(set.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    throw InputError(path_ + ": cannot write dataset " + name);
  }
}

void Writer::Matrix(const std::string& name, const Eigen::MatrixXd& value) {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> row_major = value;
  WriteDoubles(name, {hsize_t(value.rows()), hsize_t(value.cols())}, row_major.data());
}

void Writer::Vector(const std::string& name, const Eigen::VectorXd& value) {
  WriteDoubles(name, {hsize_t(value.size())}, value.data());
}

void Writer::FloatMatrix(const std::string& name, const Eigen::MatrixXf& value, float step) {
  Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> row_major = value;
  if (step > 0) row_major = (row_major / step).array().round() * step;
  WriteData(name, {hsize_t(value.rows()), hsize_t(value.cols())}, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, row_major.data(),
            true);
}

void Writer::CompressedFloatMatrices(std::vector<FloatData>& data, int threads) {
  // Each dataset one chunk, filtered here as HDF5's pipeline would (shuffle: the bytes of equal
  // significance together; then zlib at level 1) and written with H5Dwrite_chunk. A chunk that
  // does not shrink, or one of 4 GB or more, goes through HDF5's own pipeline.
  std::vector<std::vector<unsigned char>> packed(data.size());
  std::atomic<size_t> next{0};
  const auto work = [&] {
    std::vector<unsigned char> shuffled;
    for (size_t i = next++; i < data.size(); i = next++) {
      const auto& v = data[i].value;
      const size_t n = size_t(v.size()), bytes = n * sizeof(float);
      if (!data[i].compress || n == 0 || bytes >= (size_t(1) << 32)) continue;
      shuffled.resize(bytes);
      const unsigned char* raw = reinterpret_cast<const unsigned char*>(v.data());
      for (size_t k = 0; k < n; ++k) {
        for (size_t b = 0; b < sizeof(float); ++b) shuffled[b * n + k] = raw[k * sizeof(float) + b];
      }
      uLongf size = compressBound(uLong(bytes));
      packed[i].resize(size);
      if (compress2(packed[i].data(), &size, shuffled.data(), uLong(bytes), 1) != Z_OK || size >= bytes) {
        packed[i].clear();
      } else {
        packed[i].resize(size);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  for (size_t i = 0; i < data.size(); ++i) {
    const auto& v = data[i].value;
    if (packed[i].empty()) {
      WriteData(data[i].name, {hsize_t(v.rows()), hsize_t(v.cols())}, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, v.data(),
                data[i].compress);
      continue;
    }
    const hsize_t shape[2] = {hsize_t(v.rows()), hsize_t(v.cols())};
    Handle space = Own(H5Screate_simple(2, shape, nullptr));
    Handle create = Own(H5Pcreate(H5P_DATASET_CREATE));
    Handle set;
    if (H5Pset_chunk(create.id(), 2, shape) >= 0 && H5Pset_shuffle(create.id()) >= 0 && H5Pset_deflate(create.id(), 1) >= 0) {
      set = Own(H5Dcreate2(file_.id(), data[i].name.c_str(), H5T_IEEE_F32LE, space.id(), H5P_DEFAULT, create.id(),
                           H5P_DEFAULT));
    }
    const hsize_t origin[2] = {0, 0};
    if (set.id() < 0 || H5Dwrite_chunk(set.id(), H5P_DEFAULT, 0, origin, packed[i].size(), packed[i].data()) < 0) {
      throw InputError(path_ + ": cannot write dataset " + data[i].name);
    }
    std::vector<unsigned char>().swap(packed[i]);
  }
}

void Writer::Scalar(const std::string& name, double value) { WriteDoubles(name, {}, &value); }

void Writer::IntMatrix(const std::string& name, const Eigen::MatrixXi& value) {
  Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> row_major = value;
  WriteData(name, {hsize_t(value.rows()), hsize_t(value.cols())}, H5T_STD_I32LE, H5T_NATIVE_INT, row_major.data());
}

void Writer::IntVector(const std::string& name, const std::vector<int>& value) {
  WriteData(name, {hsize_t(value.size())}, H5T_STD_I32LE, H5T_NATIVE_INT, value.data());
}

void Writer::Strings(const std::string& name, const std::vector<std::string>& value) {
  Handle type = Own(H5Tcopy(H5T_C_S1));
  H5Tset_size(type.id(), H5T_VARIABLE);
  H5Tset_cset(type.id(), H5T_CSET_UTF8);
  hsize_t n = value.size();
  Handle space = Own(H5Screate_simple(1, &n, nullptr));
  Handle set = Own(H5Dcreate2(file_.id(), name.c_str(), type.id(), space.id(), H5P_DEFAULT,
                              H5P_DEFAULT, H5P_DEFAULT));
  std::vector<const char*> pointers;
  for (const auto& s : value) pointers.push_back(s.c_str());
  if (set.id() < 0 ||
      (n > 0 && H5Dwrite(set.id(), type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, pointers.data()) < 0)) {
    throw InputError(path_ + ": cannot write dataset " + name);
  }
}

void Writer::Attribute(const std::string& object, const std::string& name,
                       const std::string& value) {
  Handle type = Own(H5Tcopy(H5T_C_S1));
  H5Tset_size(type.id(), value.size() + 1);
  H5Tset_strpad(type.id(), H5T_STR_NULLTERM);
  H5Tset_cset(type.id(), H5T_CSET_UTF8);
  Handle space = Own(H5Screate(H5S_SCALAR));
  Handle attr = Own(H5Acreate_by_name(file_.id(), object.c_str(), name.c_str(), type.id(),
                                      space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (attr.id() < 0 || H5Awrite(attr.id(), type.id(), value.c_str()) < 0) {
    throw InputError(path_ + ": cannot write attribute " + object + "@" + name);
  }
}

void Writer::Attribute(const std::string& object, const std::string& name, long value) {
  Handle space = Own(H5Screate(H5S_SCALAR));
  Handle attr = Own(H5Acreate_by_name(file_.id(), object.c_str(), name.c_str(), H5T_STD_I64LE,
                                      space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (attr.id() < 0 || H5Awrite(attr.id(), H5T_NATIVE_LONG, &value) < 0) {
    throw InputError(path_ + ": cannot write attribute " + object + "@" + name);
  }
}

void Writer::CopyFrom(const std::string& source, const std::vector<std::string>& names) {
  const hid_t id = H5Fopen(source.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) throw InputError(source + ": cannot open HDF5 file to copy from");
  const Handle from = Own(id);
  for (const std::string& name : names) {
    if (H5Ocopy(from.id(), name.c_str(), file_.id(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT) < 0) {
      throw InputError(path_ + ": cannot copy " + name + " from " + source);
    }
  }
}

void Writer::Close() {
  if (file_.id() >= 0 && H5Fflush(file_.id(), H5F_SCOPE_GLOBAL) < 0) {
    throw InputError(path_ + ": cannot flush HDF5 file");
  }
  file_ = Handle();
}

// ---------------------------------------------------------------------------------------------
Reader::Reader(const std::string& path) : path_(path) {
  SilenceHdf5();
  if (FILE* f = std::fopen(path.c_str(), "rb")) {
    std::fclose(f);
  } else {
    throw InputError(path + ": cannot open file (" + std::strerror(errno) + ")");
  }
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    throw InputError(path + ": not an HDF5 file, or truncated (the header or superblock is unreadable)");
  }
  hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) throw InputError(path + ": cannot open HDF5 file (truncated or damaged)");
  file_ = Own(id);
}

void Reader::Fail(const std::string& what) const { throw InputError(path_ + ": " + what); }

bool Reader::Exists(const std::string& name) const {
  // Check each path component so that a missing parent group is not an HDF5 error.
  std::string partial;
  size_t start = 1;
  while (true) {
    size_t slash = name.find('/', start);
    partial = name.substr(0, slash);
    if (H5Lexists(file_.id(), partial.c_str(), H5P_DEFAULT) <= 0) return false;
    if (slash == std::string::npos) return true;
    start = slash + 1;
  }
}

std::vector<hsize_t> Reader::Shape(const std::string& name) const {
  if (!Exists(name)) Fail("missing dataset " + name);
  Handle set = Own(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT));
  if (set.id() < 0) Fail("cannot open dataset " + name);
  Handle space = Own(H5Dget_space(set.id()));
  int rank = H5Sget_simple_extent_ndims(space.id());
  if (rank < 0) Fail("cannot read the shape of dataset " + name);
  std::vector<hsize_t> shape(rank);
  H5Sget_simple_extent_dims(space.id(), shape.data(), nullptr);
  return shape;
}

std::vector<double> Reader::ReadDoubles(const std::string& name,
                                        std::vector<hsize_t>* shape) const {
  *shape = Shape(name);
  Handle set = Own(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT));
  size_t count = 1;
  for (hsize_t d : *shape) count *= d;
  std::vector<double> data(count);
  if (count > 0 && H5Dread(set.id(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                           data.data()) < 0) {
    Fail("cannot read dataset " + name + " (truncated file or not numeric)");
  }
  return data;
}

Eigen::MatrixXd Reader::Matrix(const std::string& name) const {
  std::vector<hsize_t> shape;
  std::vector<double> data = ReadDoubles(name, &shape);
  if (shape.size() != 2) Fail("dataset " + name + " must be 2-dimensional, got rank " + std::to_string(shape.size()));
  return Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      data.data(), Eigen::Index(shape[0]), Eigen::Index(shape[1]));
}

Eigen::VectorXd Reader::Vector(const std::string& name) const {
  std::vector<hsize_t> shape;
  std::vector<double> data = ReadDoubles(name, &shape);
  if (shape.size() != 1) Fail("dataset " + name + " must be 1-dimensional, got rank " + std::to_string(shape.size()));
  return Eigen::Map<Eigen::VectorXd>(data.data(), Eigen::Index(data.size()));
}

double Reader::Scalar(const std::string& name) const {
  std::vector<hsize_t> shape;
  std::vector<double> data = ReadDoubles(name, &shape);
  if (data.size() != 1) Fail("dataset " + name + " must hold one number");
  return data[0];
}

Eigen::MatrixXi Reader::IntMatrix(const std::string& name) const {
  std::vector<hsize_t> shape = Shape(name);
  if (shape.size() != 2) Fail("dataset " + name + " must be 2-dimensional");
  Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(shape[0], shape[1]);
  Handle set = Own(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT));
  if (m.size() > 0 &&
      H5Dread(set.id(), H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, m.data()) < 0) {
    Fail("cannot read dataset " + name);
  }
  return m;
}

Eigen::VectorXi Reader::IntVector(const std::string& name) const {
  std::vector<hsize_t> shape = Shape(name);
  if (shape.size() != 1) Fail("dataset " + name + " must be 1-dimensional");
  Eigen::VectorXi v(static_cast<Eigen::Index>(shape[0]));
  Handle set = Own(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT));
  if (v.size() > 0 && H5Dread(set.id(), H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0) {
    Fail("cannot read dataset " + name);
  }
  return v;
}

std::vector<std::string> Reader::Strings(const std::string& name) const {
  std::vector<hsize_t> shape = Shape(name);
  if (shape.size() != 1) Fail("dataset " + name + " must be a 1-dimensional list of strings");
  Handle set = Own(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT));
  Handle type = Own(H5Tcopy(H5T_C_S1));
  H5Tset_size(type.id(), H5T_VARIABLE);
  H5Tset_cset(type.id(), H5T_CSET_UTF8);
  std::vector<char*> pointers(shape[0], nullptr);
  if (shape[0] > 0 &&
      H5Dread(set.id(), type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, pointers.data()) < 0) {
    Fail("cannot read strings of dataset " + name);
  }
  std::vector<std::string> out;
  for (char* p : pointers) out.emplace_back(p ? p : "");
  if (shape[0] > 0) {
    Handle space = Own(H5Dget_space(set.id()));
    H5Dvlen_reclaim(type.id(), space.id(), H5P_DEFAULT, pointers.data());
  }
  return out;
}

bool Reader::HasAttribute(const std::string& object, const std::string& name) const {
  return Exists(object) && H5Aexists_by_name(file_.id(), object.c_str(), name.c_str(), H5P_DEFAULT) > 0;
}

std::string Reader::StringAttribute(const std::string& object, const std::string& name) const {
  if (H5Aexists_by_name(file_.id(), object.c_str(), name.c_str(), H5P_DEFAULT) <= 0) {
    Fail("missing attribute " + object + "@" + name);
  }
  Handle attr = Own(H5Aopen_by_name(file_.id(), object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT));
  Handle type = Own(H5Aget_type(attr.id()));
  if (H5Tget_class(type.id()) != H5T_STRING || H5Tis_variable_str(type.id()) > 0) {
    Fail("attribute " + object + "@" + name + " must be a fixed-length string");
  }
  std::string value(H5Tget_size(type.id()), '\0');
  // Read with the stored type: HDF5 does not convert between ASCII and UTF-8 strings.
  if (H5Aread(attr.id(), type.id(), value.data()) < 0) Fail("cannot read attribute " + object + "@" + name);
  value.resize(std::strlen(value.c_str()));
  return value;
}

long Reader::IntAttribute(const std::string& object, const std::string& name) const {
  if (H5Aexists_by_name(file_.id(), object.c_str(), name.c_str(), H5P_DEFAULT) <= 0) {
    Fail("missing attribute " + object + "@" + name);
  }
  Handle attr = Own(H5Aopen_by_name(file_.id(), object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT));
  long value = 0;
  if (H5Aread(attr.id(), H5T_NATIVE_LONG, &value) < 0) Fail("cannot read attribute " + object + "@" + name);
  return value;
}

}  // namespace femb::h5
