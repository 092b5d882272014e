#pragma once

#include <chrono>

namespace crowddb {

// Wall-clock interval timer for EXPLAIN ANALYZE and progress lines (never for decisions that
// change results: those must not depend on time).
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  void restart() { start_ = std::chrono::steady_clock::now(); }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace crowddb
