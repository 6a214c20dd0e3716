// Plain arrays as bytes and back: what the MPI ranks of a distributed reduction send each other
// (shared_columns.h), in this machine's layout (the ranks run one build).
#pragma once

#include <cstring>
#include <string>

namespace femb {

/// Appends `count` values to `out`.
template <typename T>
void AppendBytes(std::string& out, const T* data, size_t count) {
  out.append(reinterpret_cast<const char*>(data), count * sizeof(T));
}

/// Reads `count` values at `from` into `data`; returns where the next ones start.
template <typename T>
const char* TakeBytes(const char* from, T* data, size_t count) {
  std::memcpy(data, from, count * sizeof(T));
  return from + count * sizeof(T);
}

}  // namespace femb
