#include "formats/hdf5_file.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>

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
    case H5I_FILE:
      return H5Fclose(id);
    case H5I_GROUP:
      return H5Gclose(id);
    case H5I_DATASET:
      return H5Dclose(id);
    case H5I_DATASPACE:
      return H5Sclose(id);
    case H5I_DATATYPE:
      return H5Tclose(id);
    case H5I_ATTR:
      return H5Aclose(id);
    case H5I_GENPROP_LST:
      return H5Pclose(id);
    default:
      return -1;
  }
}

Handle Own(hid_t id) { return Handle(id, CloseAny); }

// A transfer property list whose type-conversion buffer holds `elements` elements of a variable-
// length string (HDF5 1.10 otherwise allocates and zeroes its default of 1 MiB at every
// converting read or write: 0.3-0.5 ms each, most of a small results file's write).
Handle StringTransfer(hsize_t elements) {
  Handle list = Own(H5Pcreate(H5P_DATASET_XFER));
  const size_t bytes = std::max<size_t>(size_t(elements) * 2 * sizeof(hvl_t), 4096);
  if (list.id() >= 0 && bytes < (size_t(1) << 20)) H5Pset_buffer(list.id(), bytes, nullptr, nullptr);
  return list;
}

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

void Writer::WriteData(const std::string& name, const std::vector<hsize_t>& shape, hid_t file_type, hid_t memory_type,
                       const void* data, bool compress) {
  Handle space =
      Own(shape.empty() ? H5Screate(H5S_SCALAR) : H5Screate_simple(int(shape.size()), shape.data(), nullptr));
  Handle create = Own(H5Pcreate(H5P_DATASET_CREATE));
  if (compress && shape.size() == 2 && shape[0] > 0 && shape[1] > 0 && H5Zfilter_avail(H5Z_FILTER_DEFLATE) > 0) {
    // Chunks of about 1 MB of rows: deflate level 1 (level 4 made the files 3% smaller at twice
    // the time).
    const hsize_t chunk[2] = {std::min<hsize_t>(shape[0], std::max<hsize_t>(1, (hsize_t(1) << 18) / shape[1])),
                              shape[1]};
    if (H5Pset_chunk(create.id(), 2, chunk) < 0 || H5Pset_shuffle(create.id()) < 0 ||
        H5Pset_deflate(create.id(), 1) < 0) {
      throw InputError(path_ + ": cannot set the compression of dataset " + name);
    }
  }
  Handle set = Own(H5Dcreate2(file_.id(), name.c_str(), file_type, space.id(), H5P_DEFAULT, create.id(), H5P_DEFAULT));
  if (set.id() < 0 || H5Dwrite(set.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
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

namespace {

// Shannon entropy of the bytes [begin, end) in bits per byte: what Huffman coding of them alone
// would approach (8: nothing to gain).
// Estimated from at most 4096 bytes spread evenly over the range (enough to tell a plane of
// nearly random bytes; counted into four tables, as a run of equal bytes into one would wait on
// each increment).
double ByteEntropy(const unsigned char* begin, const unsigned char* end) {
  const size_t size = size_t(end - begin), stride = std::max<size_t>(1, size / 4096);
  std::array<std::array<uint32_t, 256>, 4> count{};
  size_t n = 0;
  for (size_t i = 0; i < size; i += stride, ++n) ++count[n & 3][begin[i]];
  double h = 0.0;
  for (int v = 0; v < 256; ++v) {
    const uint32_t c = count[0][v] + count[1][v] + count[2][v] + count[3][v];
    if (c > 0) h -= double(c) / double(n) * std::log2(double(c) / double(n));
  }
  return h;
}

// One zlib stream (what HDF5's deflate filter reads) of `data`, made of `planes` equal byte
// planes (shuffled floats: the sign and exponent bytes, then the mantissa's): each plane its own
// deflate blocks, stored where its bytes are nearly random (entropy above 7.3 bits a byte, which
// deflate shrinks by less than 10% at the most of its time: the low mantissa bytes of a rounded
// field), else Huffman-coded with runs of equal bytes (zlib's Z_RLE strategy at level 1: on a
// solid cantilever's animation 3% smaller than level 1's full string matching at 1.4x its
// speed; Huffman codes alone were 25% larger). Returns the stream's size (0: zlib failed).
// `out` must hold DeflateBound(data.size(), planes) bytes.
size_t DeflateBound(size_t bytes, size_t planes) { return compressBound(uLong(bytes)) + 64 * planes; }
size_t DeflatePlanes(const std::vector<unsigned char>& data, size_t planes, unsigned char* out) {
  z_stream z{};
  if (deflateInit(&z, 1) != Z_OK) return 0;
  const size_t capacity = DeflateBound(data.size(), planes);
  z.next_out = out;
  z.avail_out = uInt(capacity);
  const size_t plane = data.size() / planes;
  bool ok = true;
  for (size_t k = 0; k < planes && ok; ++k) {
    const unsigned char* begin = data.data() + k * plane;
    const int level = ByteEntropy(begin, begin + plane) > 7.3 ? 0 : 1;
    ok = deflateParams(&z, level, Z_RLE) == Z_OK;
    z.next_in = const_cast<unsigned char*>(begin);
    z.avail_in = uInt(plane);
    ok = ok && deflate(&z, k + 1 == planes ? Z_FINISH : Z_BLOCK) == (k + 1 == planes ? Z_STREAM_END : Z_OK);
  }
  const size_t size = ok ? capacity - z.avail_out : 0;
  deflateEnd(&z);
  return size;
}

}  // namespace

size_t PackedFloats::stored_bytes() const {
  size_t n = 0;
  for (const Chunk& c : chunks) n += c.bytes.size();
  return n;
}

PackedFloats PackFloats(std::string name, const float* data, long rows, long cols) {
  PackedFloats p;
  p.name = std::move(name);
  p.rows = hsize_t(std::max(rows, 0L)), p.cols = hsize_t(std::max(cols, 0L));
  if (p.rows == 0 || p.cols == 0) return p;
  // Chunks of equal length, each at most 2^20 rows (4 MB; HDF5's limit is 4 GB).
  const hsize_t limit = hsize_t(1) << 20, per_column = (p.rows + limit - 1) / limit;
  p.chunk_rows = (p.rows + per_column - 1) / per_column;
  const size_t bytes = size_t(p.chunk_rows) * sizeof(float);
  std::vector<unsigned char> shuffled(bytes);
  const std::unique_ptr<unsigned char[]> deflated(new unsigned char[DeflateBound(bytes, sizeof(float))]);
  for (hsize_t c = 0; c < p.cols; ++c) {
    for (hsize_t r0 = 0; r0 < p.rows; r0 += p.chunk_rows) {
      // The chunk's values, the last one zero-padded to the chunk's length (HDF5 stores whole
      // chunks), shuffled as HDF5's shuffle filter does.
      const size_t n = size_t(std::min(p.chunk_rows, p.rows - r0)), m = size_t(p.chunk_rows);
      const unsigned char* raw = reinterpret_cast<const unsigned char*>(data + c * p.rows + r0);
      for (size_t k = 0; k < n; ++k) {
        for (size_t b = 0; b < sizeof(float); ++b) shuffled[b * m + k] = raw[k * sizeof(float) + b];
      }
      for (size_t b = 0; b < sizeof(float); ++b)
        std::fill(shuffled.begin() + long(b * m + n), shuffled.begin() + long((b + 1) * m), 0);
      PackedFloats::Chunk chunk;
      chunk.row = r0, chunk.col = c;
      const size_t size = DeflatePlanes(shuffled, sizeof(float), deflated.get());
      if (size > 0 && size < bytes) {
        chunk.bytes.assign(deflated.get(), deflated.get() + size);
      } else {
        chunk.raw = true;
        chunk.bytes.assign(m * sizeof(float), 0);
        std::memcpy(chunk.bytes.data(), raw, n * sizeof(float));
      }
      p.chunks.push_back(std::move(chunk));
    }
  }
  return p;
}

void Writer::Packed(const PackedFloats& data) {
  const hsize_t shape[2] = {data.rows, data.cols};
  Handle space = Own(H5Screate_simple(2, shape, nullptr));
  Handle create = Own(H5Pcreate(H5P_DATASET_CREATE));
  Handle set;
  const hsize_t chunk[2] = {data.chunk_rows, 1};
  if (data.rows == 0 || data.cols == 0) {
    set = Own(
        H5Dcreate2(file_.id(), data.name.c_str(), H5T_IEEE_F32LE, space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  } else if (H5Pset_chunk(create.id(), 2, chunk) >= 0 && H5Pset_shuffle(create.id()) >= 0 &&
             H5Pset_deflate(create.id(), 1) >= 0) {
    set = Own(
        H5Dcreate2(file_.id(), data.name.c_str(), H5T_IEEE_F32LE, space.id(), H5P_DEFAULT, create.id(), H5P_DEFAULT));
  }
  if (set.id() < 0) throw InputError(path_ + ": cannot write dataset " + data.name);
  for (const PackedFloats::Chunk& c : data.chunks) {
    // Filter mask: bit i set skips filter i (0 shuffle, 1 deflate) when the chunk is read.
    const hsize_t origin[2] = {c.row, c.col};
    if (H5Dwrite_chunk(set.id(), H5P_DEFAULT, c.raw ? 0x3u : 0u, origin, c.bytes.size(), c.bytes.data()) < 0) {
      throw InputError(path_ + ": cannot write dataset " + data.name);
    }
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
  Handle set = Own(H5Dcreate2(file_.id(), name.c_str(), type.id(), space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  std::vector<const char*> pointers;
  for (const auto& s : value) pointers.push_back(s.c_str());
  Handle transfer = StringTransfer(n);
  if (set.id() < 0 || (n > 0 && H5Dwrite(set.id(), type.id(), H5S_ALL, H5S_ALL, transfer.id(), pointers.data()) < 0)) {
    throw InputError(path_ + ": cannot write dataset " + name);
  }
}

void Writer::Attribute(const std::string& object, const std::string& name, const std::string& value) {
  Handle type = Own(H5Tcopy(H5T_C_S1));
  H5Tset_size(type.id(), value.size() + 1);
  H5Tset_strpad(type.id(), H5T_STR_NULLTERM);
  H5Tset_cset(type.id(), H5T_CSET_UTF8);
  Handle space = Own(H5Screate(H5S_SCALAR));
  Handle attr = Own(H5Acreate_by_name(file_.id(), object.c_str(), name.c_str(), type.id(), space.id(), H5P_DEFAULT,
                                      H5P_DEFAULT, H5P_DEFAULT));
  if (attr.id() < 0 || H5Awrite(attr.id(), type.id(), value.c_str()) < 0) {
    throw InputError(path_ + ": cannot write attribute " + object + "@" + name);
  }
}

void Writer::Attribute(const std::string& object, const std::string& name, long value) {
  Handle space = Own(H5Screate(H5S_SCALAR));
  Handle attr = Own(H5Acreate_by_name(file_.id(), object.c_str(), name.c_str(), H5T_STD_I64LE, space.id(), H5P_DEFAULT,
                                      H5P_DEFAULT, H5P_DEFAULT));
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

std::vector<double> Reader::ReadDoubles(const std::string& name, std::vector<hsize_t>* shape) const {
  *shape = Shape(name);
  Handle set = Own(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT));
  size_t count = 1;
  for (hsize_t d : *shape) count *= d;
  std::vector<double> data(count);
  if (count > 0 && H5Dread(set.id(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0) {
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

Eigen::MatrixXf Reader::FloatMatrix(const std::string& name) const {
  const std::vector<hsize_t> shape = Shape(name);
  if (shape.size() != 2) Fail("dataset " + name + " must be 2-dimensional, got rank " + std::to_string(shape.size()));
  const Eigen::Index rows = Eigen::Index(shape[0]), cols = Eigen::Index(shape[1]);
  Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(rows, cols);
  Handle set = Own(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT));
  if (m.size() > 0 && H5Dread(set.id(), H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, m.data()) < 0) {
    Fail("cannot read dataset " + name + " (truncated file or not numeric)");
  }
  return m;
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
  if (m.size() > 0 && H5Dread(set.id(), H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, m.data()) < 0) {
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
  Handle transfer = StringTransfer(shape[0]);
  if (shape[0] > 0 && H5Dread(set.id(), type.id(), H5S_ALL, H5S_ALL, transfer.id(), pointers.data()) < 0) {
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
