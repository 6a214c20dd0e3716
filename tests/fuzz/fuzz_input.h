// Reading a fuzzer's bytes as a stream of small integers and choices.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace femb::fuzz {

class Input {
 public:
  Input(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  bool empty() const { return at_ >= size_; }
  uint8_t Byte() { return at_ < size_ ? data_[at_++] : 0; }
  /// A number in [0, n) (n > 0).
  unsigned Below(unsigned n) { return (unsigned(Byte()) << 8 | Byte()) % n; }
  std::string Rest() {
    std::string s(reinterpret_cast<const char*>(data_ + at_), size_ - at_);
    at_ = size_;
    return s;
  }

 private:
  const uint8_t* data_;
  size_t size_, at_ = 0;
};

}  // namespace femb::fuzz
