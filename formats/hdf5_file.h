// A thin RAII layer over the HDF5 C API: just what the superelement file needs. Matrices are
// stored in C (row-major) order with shape (rows, cols), so h5py and h5dump show them as written.
#pragma once

#include <hdf5.h>

#include <Eigen/Core>
#include <string>
#include <vector>

namespace femb::h5 {

/// An open HDF5 object handle (file or group), closed on destruction.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*closer)(hid_t)) : id_(id), closer_(closer) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = -1; }
  Handle& operator=(Handle&& o) noexcept;
  ~Handle();
  hid_t id() const { return id_; }

 private:
  hid_t id_ = -1;
  herr_t (*closer_)(hid_t) = nullptr;
};

/// A single-precision matrix filtered for HDF5 by the caller (PackFloats: no HDF5 call, so any
/// thread may pack while one writes): each column in chunks of at most 2^20 rows, each chunk
/// shuffled (the bytes of equal significance together) and deflated at level 1, or kept as it is
/// where deflate does not shrink it (the chunk's filter mask says so). Every HDF5 reader decodes
/// it through its own filter pipeline; readers that take rows see no difference but speed.
struct PackedFloats {
  std::string name;
  hsize_t rows = 0, cols = 0, chunk_rows = 0;
  struct Chunk {
    hsize_t row = 0, col = 0;
    bool raw = false;  ///< stored unfiltered (deflate did not shrink it)
    std::vector<unsigned char> bytes;
  };
  std::vector<Chunk> chunks;
  size_t stored_bytes() const;
};
/// Packs the column-major rows x cols values at `data` (a column a chunk: the components of a
/// vector field apart, which compress 15% better than interleaved).
PackedFloats PackFloats(std::string name, const float* data, long rows, long cols);

/// Writes datasets and attributes below one location of a file being created at `path`.
/// Every failure throws femb::InputError naming the file and the object.
class Writer {
 public:
  /// Creates (truncates) the file `path`. `v110`: HDF5 1.10's file format (readable by HDF5
  /// 1.10 and later: h5py, ParaView, MATLAB R2019+), whose datasets of one chunk need no chunk
  /// index (the 1.8 format spent 3 KB a dataset on one: a fifth of a compressed animation).
  explicit Writer(const std::string& path, bool v110 = false);
  void CreateGroup(const std::string& group);
  void Matrix(const std::string& name, const Eigen::MatrixXd& value);
  void Vector(const std::string& name, const Eigen::VectorXd& value);
  void IntMatrix(const std::string& name, const Eigen::MatrixXi& value);
  void IntVector(const std::string& name, const std::vector<int>& value);
  /// Single precision (animation frames: half the size, 1e-7 relative resolution), stored in
  /// chunks with HDF5's shuffle and deflate filters (every HDF5 reader decodes them). With
  /// `step` > 0 the values are first rounded to multiples of it (a power of two keeps the
  /// multiples exact): the low bits that carry no information at that resolution then compress.
  void FloatMatrix(const std::string& name, const Eigen::MatrixXf& value, float step = 0.0f);
  /// A dataset of a PackedFloats (PackFloats, above) written as its chunks are, filters and all.
  void Packed(const PackedFloats& data);
  void Scalar(const std::string& name, double value);
  void Strings(const std::string& name, const std::vector<std::string>& value);
  /// Attributes on an existing object ("/" for the root).
  void Attribute(const std::string& object, const std::string& name, const std::string& value);
  void Attribute(const std::string& object, const std::string& name, long value);
  /// Copies the objects `names` (datasets, with their storage and filters as they are: no
  /// decompression) from the HDF5 file `source` to the same names in this file.
  void CopyFrom(const std::string& source, const std::vector<std::string>& names);
  void Close();

 private:
  /// One dataset of the given shape (empty: scalar), stored as `file_type`, read from `data`
  /// as `memory_type`.
  /// `compress`: chunked, shuffled and deflated (2-D shapes).
  void WriteData(const std::string& name, const std::vector<hsize_t>& shape, hid_t file_type, hid_t memory_type,
                 const void* data, bool compress = false);
  void WriteDoubles(const std::string& name, const std::vector<hsize_t>& shape, const double* data) {
    WriteData(name, shape, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, data);
  }
  std::string path_;
  Handle file_;
};

/// Reads datasets and attributes of an existing file. Every failure (no file, not HDF5,
/// truncated, missing object, wrong shape) throws femb::InputError naming the file and object.
class Reader {
 public:
  explicit Reader(const std::string& path);
  bool Exists(const std::string& name) const;
  Eigen::MatrixXd Matrix(const std::string& name) const;
  /// A 2-D dataset in single precision (a file's float data without a double-precision copy).
  Eigen::MatrixXf FloatMatrix(const std::string& name) const;
  Eigen::VectorXd Vector(const std::string& name) const;
  Eigen::MatrixXi IntMatrix(const std::string& name) const;
  Eigen::VectorXi IntVector(const std::string& name) const;
  double Scalar(const std::string& name) const;
  std::vector<std::string> Strings(const std::string& name) const;
  std::string StringAttribute(const std::string& object, const std::string& name) const;
  bool HasAttribute(const std::string& object, const std::string& name) const;
  long IntAttribute(const std::string& object, const std::string& name) const;
  /// Shape of a dataset (empty for a scalar).
  std::vector<hsize_t> Shape(const std::string& name) const;
  const std::string& path() const { return path_; }

 private:
  std::vector<double> ReadDoubles(const std::string& name, std::vector<hsize_t>* shape) const;
  [[noreturn]] void Fail(const std::string& what) const;
  std::string path_;
  Handle file_;
};

}  // namespace femb::h5
