// EXPLAIN ANALYZE bookkeeping: rows, loops, time and query counters per named operator, in the
// order the operators first ran (fixed by the plan, so the report's order is deterministic).
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "crowddb/query.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::sim {

struct OperatorStats {
  uint64_t loops = 0;
  uint64_t rows = 0;
  double seconds = 0;
  QueryStats query;
  // An operator-specific count shown beside it ("infeasible (3-D fallback) 12"), in total and
  // the most in one loop.
  std::string events_name;
  uint64_t events = 0, events_max = 0;
  // The operator this one ran beside, on the same threads (Executor::both): their times overlap.
  std::string beside;
  void count(const char* name, uint64_t k) {
    events_name = name;
    events += k;
    events_max = std::max(events_max, k);
  }
};

class OpLog {
 public:
  OperatorStats& at(const std::string& name) {
    for (auto& [n, s] : ops_)
      if (n == name) return s;
    ops_.emplace_back(name, OperatorStats{});
    return ops_.back().second;
  }
  // Runs body() and books one loop over `rows` rows and its wall time under `name`.
  template <class F>
  void timed(const std::string& name, std::size_t rows, F&& body) {
    Stopwatch sw;
    body();
    book(name, rows, sw.seconds());
  }
  // Books one loop over `rows` rows that took `seconds` under `name` (timed by the caller: work
  // run beside other work, Executor::both).
  OperatorStats& book(const std::string& name, std::size_t rows, double seconds) {
    OperatorStats& s = at(name);
    s.loops += 1;
    s.rows += rows;
    s.seconds += seconds;
    return s;
  }
  // Operators run side by side took `seconds` of wall time together (their own times are booked
  // as usual): the report's total counts the overlap once.
  void side_by_side(double booked_seconds, double wall_seconds) {
    overlap_ += std::max(0.0, booked_seconds - wall_seconds);
  }
  double overlap_seconds() const { return overlap_; }
  // Counts a tick on which an access path was used ("neighbours=grid").
  void used(const std::string& method) { ++methods_[method]; }

  const std::vector<std::pair<std::string, OperatorStats>>& entries() const { return ops_; }
  const std::map<std::string, uint64_t>& methods() const { return methods_; }

 private:
  std::vector<std::pair<std::string, OperatorStats>> ops_;
  std::map<std::string, uint64_t> methods_;
  double overlap_ = 0;
};

}  // namespace crowddb::sim
