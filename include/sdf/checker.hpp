// The schedule checker: a token simulation independent of every scheduler. A list of runs is a
// valid period from a token state when every firing is admissible (its consumer finds cns
// tokens on each input), every actor fires a positive multiple of its repetition count, and the
// token state at the end equals the one at the start. Runs are checked in O(degree) each, however
// many firings they hold, with exact 64-bit arithmetic (an overflow is reported, not wrapped).
//
// Thread-safety: pure functions.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sdf/graph.hpp"
#include "sdf/schedule.hpp"

namespace sdf {

struct CheckResult {
  bool valid = false;
  std::string reason;            // empty when valid; one line otherwise
  uint64_t failed_firing = 0;    // 1-based index of the first inadmissible firing, 0 if none
  std::vector<uint64_t> fired;   // firings per actor
  std::vector<uint64_t> tokens;  // token state after the runs (as far as they got)
};

// Every firing admissible from `tokens` (default: the delays). `valid` says just that.
CheckResult check_admissible(const Graph& g, std::span<const Run> runs,
                             std::span<const uint64_t> tokens = {});

// A valid period: admissible, each actor fired a positive multiple of q, state back to the start.
CheckResult check_period(const Graph& g, std::span<const uint64_t> q, std::span<const Run> runs,
                         std::span<const uint64_t> tokens = {});

}  // namespace sdf
