// The thesis's claims about `online`, tested on random consistent live graphs (DESIGN §8):
// does it return to the initial state (a valid period), become periodic without returning, or
// grow without bound; does its fairness stay below n - 1; does `online-bounded` always complete
// a valid period; and after a mid-period rate change (thesis 5.4: one actor's rates scaled by a
// factor, at a random firing), does each become periodic again, and `online` at once (the
// thesis: "the convergence of the online algorithm being zero"). Every schedule produced is
// passed through the checker. Used by `sdfsched claims`, the claims tests and docs/sdf.md.
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

// After a rate change: `periodic_again` counts runs that returned or became periodic with a
// period the checker accepts (from where it starts), `at_once` those among them with no firing
// before the period; the rest grew without bound, deadlocked or hit the decision limit.
struct RateChangeStats {
  uint64_t changes = 0, periodic_again = 0, at_once = 0, unbounded = 0, deadlock = 0, limit = 0;
  uint64_t invalid = 0;  // a period after the change that the checker rejects
  uint64_t max_firings_until_periodic = 0;
};

struct ClassStats {
  std::string name;
  uint64_t graphs = 0;
  PolicyStats online, online_one, bounded;
  RateChangeStats online_change, bounded_change;
  // Summed per-channel buffer sizes over one period, on the graphs where `online` returns (so
  // the three policies are compared on the same graphs).
  uint64_t common = 0;
  uint64_t buffers_static = 0, buffers_online = 0, buffers_bounded = 0;
};

struct Report {
  std::vector<ClassStats> classes;
  // Smallest failing graph per failed claim ("online-periodic", "online-unbounded",
  // "online-fairness", "online-one-periodic", ... "bounded-invalid", "online-change-not-at-once",
  // "online-change-unbounded", ...), by actors, channels, size. A rate-change counter-example is
  // named after its change, `ACTOR*NUM/DEN@FIRING` (the form of `simulate --rate-change`).
  std::map<std::string, Graph> counterexamples;
};

// One line per claim: how many graphs fail it out of how many, and the smallest counter-example.
struct Verdict {
  std::string claim;
  uint64_t fails = 0, graphs = 0;
  std::string counterexample;  // a key of Report::counterexamples, empty when none
};
std::vector<Verdict> verdicts(const Report& report);

struct Options {
  uint64_t graphs_per_class = 100;
  uint64_t seed = 1;
  uint32_t min_actors = 2, max_actors = 10;
};

Report run(const Options& options);

}  // namespace sdf::claims
