// Progress reporting from the reducer: the library calls back, only mains print.
#pragma once

#include <chrono>
#include <cstdio>
#include <functional>
#include <string>

namespace femb {

/// Called once per finished stage with its wall time and a one-line detail.
using ProgressFn = std::function<void(const std::string& stage, double seconds, const std::string& detail)>;

/// A progress detail or message with up to four numbers: printf's `fmt` (double conversions only).
inline std::string Format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, fmt, a, b, c, d);
  return buffer;
}

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
