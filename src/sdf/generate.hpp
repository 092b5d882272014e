// Random SDF graphs for tests, benchmarks and the claims experiment, built from a chosen
// repetitions vector so the right answer is known by construction: a channel u -> v gets
// prd = q_v/g·m and cns = q_u/g·m (g = gcd(q_u, q_v), m a small multiplier), which balances.
//
// Shapes: chain; fan_out (out-tree from one source); fan_in (in-tree into one sink); dag (random
// spanning tree plus extra forward channels); cyclic (dag plus back channels, each carrying a
// full period of its consumer's tokens, so the graph is live); cyclic_random (back channels with
// random delays: may deadlock). Actor ids are a random permutation of the topological order.
// self_loops adds SDF3's one-token self-loop (prd = cns = 1, one delay) to every actor.
//
// Deterministic: the same spec and seed give the same graph (crowddb::Rng, no std:: distributions).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sdf/graph.hpp"
#include "util/rng.hpp"

namespace sdf::gen {

enum class Shape { chain, fan_out, fan_in, dag, cyclic, cyclic_random };
const char* shape_name(Shape s);

struct Spec {
  Shape shape = Shape::dag;
  uint32_t actors = 8;
  bool multirate = true;  // false: every rate 1 (homogeneous SDF)
  bool self_loops = false;
  uint32_t extra_percent = 50;  // dag/cyclic: extra forward channels, % of the actor count
  uint32_t back_percent = 30;   // cyclic: back channels, % of the actor count (at least one)
  uint32_t max_q = 12;          // multi-rate: repetition counts drawn from those up to this
  uint32_t max_multiplier = 3;  // multi-rate: rate multipliers m drawn from those up to this
  // > 0: every rate at most this (the repetition counts drawn up to it too, and a multiplier
  // that would pass it lowered to the largest that does not). 0: no cap beyond the above.
  uint32_t max_rate = 0;
};

struct Generated {
  Graph graph;
  std::vector<uint64_t> q;  // the repetitions vector by construction (primitive)
};

Generated generate(const Spec& spec, crowddb::Rng& rng);

}  // namespace sdf::gen
