// Benchmark-only variants of a steering model: the model with some of its options changed, to
// measure what those options cost. Not models of their own (the engine's registry does not know
// them) and not defaults: a variant's crowd flows differently, often worse.
//
// "orca-core": the default orca without the three additions for crowds that RVO2's ORCA does not
// have: keeping to a side (pass_side none), the stream gap (stream_gap 0) and the seeded
// perturbation of the wishes (0; RVO2's examples add one, the side-by-side's RVO2 loop does
// not). The rest stays: the right of way, contact and retreat planes, the backoff, the
// stalemate watch. What the three buy is in docs/steering.md; what they cost, in
// docs/bench/journal.md ("What keeping to a side, the stream gap and the perturbation cost").
#pragma once

#include <string>

#include "crowddb/simulation.hpp"

namespace crowddb::bench {

// The registered model a name runs (itself unless it names a variant).
inline std::string engine_model(const std::string& name) {
  return name == "orca-core" ? "orca" : name;
}

// Sets the variant's options on a configuration parsed for engine_model(name).
inline void apply_variant(const std::string& name, SimConfig& cfg) {
  if (name == "orca-core") {
    cfg.steering.orca.pass_side = OrcaParams::PassSide::none;
    cfg.steering.orca.stream_gap = 0;
    cfg.steering.perturbation = 0;
  }
}

}  // namespace crowddb::bench
