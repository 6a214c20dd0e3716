// Progress reporting from the reducer: the library calls back, only mains print.
#pragma once

#include <chrono>
#include <functional>
#include <string>

namespace femb {

/// Called once per finished stage with its wall time and a one-line detail.
using ProgressFn = std::function<void(const std::string& stage, double seconds, const std::string& detail)>;

/// Wall-clock stopwatch.
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double Seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  void Restart() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace femb
