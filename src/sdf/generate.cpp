#include "sdf/generate.hpp"

#include <algorithm>
#include <numeric>

namespace sdf::gen {

const char* shape_name(Shape s) {
  switch (s) {
    case Shape::chain:
      return "chain";
    case Shape::fan_out:
      return "fan-out";
    case Shape::fan_in:
      return "fan-in";
    case Shape::dag:
      return "dag";
    case Shape::cyclic:
      return "cyclic";
    case Shape::cyclic_random:
      return "cyclic-random";
  }
  return "?";
}

Generated generate(const Spec& spec, crowddb::Rng& rng) {
  static constexpr uint64_t kQ[] = {1, 2, 3, 4, 5, 6, 8, 9, 10, 12};
  static constexpr uint64_t kMult[] = {1, 1, 1, 2, 3};
  const uint32_t n = std::max<uint32_t>(spec.actors, 1);
  Generated out;
  Graph& g = out.graph;
  // Topological position p holds actor id perm[p].
  std::vector<ActorId> perm(n);
  std::iota(perm.begin(), perm.end(), 0);
  for (uint32_t i = n; i > 1; --i) std::swap(perm[i - 1], perm[rng.below(i)]);
  std::vector<uint64_t> q(n, 1);
  // Tables cut at the spec's maxima (the defaults keep them whole, and the graphs as before).
  size_t q_choices = 0, m_choices = 0;
  const uint32_t q_cap =
      std::max<uint32_t>(1, spec.max_rate ? std::min(spec.max_q, spec.max_rate) : spec.max_q);
  while (q_choices < std::size(kQ) && kQ[q_choices] <= q_cap) ++q_choices;
  while (m_choices < std::size(kMult) &&
         kMult[m_choices] <= std::max<uint32_t>(spec.max_multiplier, 1))
    ++m_choices;
  if (spec.multirate)
    for (auto& v : q) v = kQ[rng.below(q_choices)];
  for (uint32_t a = 0; a < n; ++a) {
    std::string name(1, 'a');
    name += std::to_string(a);
    g.add_actor(std::move(name));
  }

  // A channel between topological positions; delay in units of the consumer's period tokens.
  auto connect = [&](uint32_t from, uint32_t to, uint64_t delay_periods_x4) {
    const ActorId u = perm[from], v = perm[to];
    uint64_t prd = 1, cns = 1;
    if (spec.multirate) {
      const uint64_t gcd = std::gcd(q[u], q[v]);
      uint64_t m = kMult[rng.below(m_choices)];
      // The larger rate is max(q_u, q_v) / gcd * m; q <= max_rate keeps m = 1 within the cap.
      if (spec.max_rate) m = std::min<uint64_t>(m, spec.max_rate * gcd / std::max(q[u], q[v]));
      prd = q[v] / gcd * m;
      cns = q[u] / gcd * m;
    }
    const uint64_t delay = cns * q[v] * delay_periods_x4 / 4;
    g.add_channel(u, v, prd, cns, delay);
  };
  auto back_delay = [&]() -> uint64_t {
    // cyclic: 1 to 2 full periods; cyclic_random: 0 to 1 period in quarters.
    return spec.shape == Shape::cyclic ? 4 + 4 * rng.below(2) : rng.below(5);
  };

  switch (spec.shape) {
    case Shape::chain:
      for (uint32_t p = 1; p < n; ++p) connect(p - 1, p, 0);
      break;
    case Shape::fan_out:
      for (uint32_t p = 1; p < n; ++p) connect(static_cast<uint32_t>(rng.below(p)), p, 0);
      break;
    case Shape::fan_in:
      // Edges point towards position 0: reversed positions keep ids a random permutation.
      for (uint32_t p = 1; p < n; ++p) connect(p, static_cast<uint32_t>(rng.below(p)), 0);
      break;
    case Shape::dag:
    case Shape::cyclic:
    case Shape::cyclic_random: {
      // parent[p]: the spanning tree's channel into position p (positions 1 on).
      std::vector<uint32_t> parent(n, 0), depth(n, 0);
      for (uint32_t p = 1; p < n; ++p) {
        parent[p] = static_cast<uint32_t>(rng.below(p));
        depth[p] = depth[parent[p]] + 1;
        connect(parent[p], p, 0);
      }
      if (n >= 2) {
        const uint64_t extra = uint64_t{n} * spec.extra_percent / 100;
        for (uint64_t i = 0; i < extra; ++i) {
          auto x = static_cast<uint32_t>(rng.below(n)), y = static_cast<uint32_t>(rng.below(n));
          if (x == y) continue;
          if (x > y) std::swap(x, y);
          connect(x, y, 0);
        }
        if (spec.shape != Shape::dag) {
          // Each back channel goes from a position to one of its ancestors in the spanning tree,
          // so that it closes a cycle (to any earlier position it would close none unless that
          // one happened to be upstream: a quarter of 8-actor graphs had no cycle at all).
          const uint64_t back = std::max<uint64_t>(1, uint64_t{n} * spec.back_percent / 100);
          for (uint64_t i = 0; i < back; ++i) {
            const auto x = static_cast<uint32_t>(1 + rng.below(n - 1));
            uint32_t y = x;
            for (uint64_t up = 1 + rng.below(depth[x]); up > 0; --up) y = parent[y];
            connect(x, y, back_delay());
          }
        }
      }
      break;
    }
  }
  if (spec.self_loops)
    for (ActorId a = 0; a < n; ++a) g.add_channel(a, a, 1, 1, 1);
  uint64_t common = 0;
  for (uint64_t v : q) common = std::gcd(common, v);
  for (auto& v : q) v /= common;
  out.q = std::move(q);
  return out;
}

}  // namespace sdf::gen
