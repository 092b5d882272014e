// The thesis's claims about `online`, tested on random consistent live graphs (DESIGN §8):
// does it return to the initial state (a valid period), become periodic without returning, or
// grow without bound; does its fairness stay below n - 1; does `online-bounded` always complete
// a valid period. Every schedule produced is passed through the checker. Used by
// `sdfsched claims`, the claims tests and docs/sdf.md.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sdf/generate.hpp"
#include "sdf/graph.hpp"

namespace sdf::claims {

struct PolicyStats {
  uint64_t returns = 0, periodic = 0, unbounded = 0, deadlock = 0, limit = 0;
  // `unbounded` runs that are still unbounded with a 16 times larger growth cap.
  uint64_t unbounded_confirmed = 0;
  uint64_t fairness_violations = 0;       // max wait >= n - 1 (the thesis: "< n - 1")
  uint64_t fairness_violations_weak = 0;  // max wait > n - 1 (the thesis: "at most n - 1")
  uint64_t max_wait = 0;
  uint64_t checker_failures = 0;  // a `returns` period or a periodic cycle the checker rejects
};

struct ClassStats {
  std::string name;
  uint64_t graphs = 0;
  PolicyStats online, online_one, bounded;
  // Summed per-channel buffer sizes over one period, on the graphs where `online` returns (so
  // the three policies are compared on the same graphs).
  uint64_t common = 0;
  uint64_t buffers_static = 0, buffers_online = 0, buffers_bounded = 0;
};

struct Report {
  std::vector<ClassStats> classes;
  // Smallest failing graph per failed claim ("online-periodic", "online-unbounded",
  // "online-fairness", "online-one-periodic", ... "bounded-invalid"), by actors, channels, size.
  std::map<std::string, Graph> counterexamples;
};

struct Options {
  uint64_t graphs_per_class = 100;
  uint64_t seed = 1;
  uint32_t min_actors = 2, max_actors = 10;
};

Report run(const Options& options);

}  // namespace sdf::claims
