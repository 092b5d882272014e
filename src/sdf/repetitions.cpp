#include "sdf/repetitions.hpp"

#include <numeric>

#include "sdf/checked.hpp"

namespace sdf {

namespace {

struct Fraction {
  uint64_t num = 0;  // 0 = not yet visited
  uint64_t den = 1;
};

// n/d · a/b with everything reduced first, so the result is reduced and every product is at
// most the reduced result's numerator or denominator (which are bounded by the final q).
Fraction scale(Fraction f, uint64_t a, uint64_t b) {
  const uint64_t g = std::gcd(a, b);
  a /= g;
  b /= g;
  const uint64_t g1 = std::gcd(f.num, b);
  const uint64_t g2 = std::gcd(a, f.den);
  return {detail::mul(f.num / g1, a / g2, "a repetitions-vector entry"),
          detail::mul(f.den / g2, b / g1, "a repetitions-vector entry")};
}

}  // namespace

Repetitions compute_repetitions(const Graph& g) {
  const size_t n = g.actor_count();
  const Adjacency adj(g);
  Repetitions r;
  r.q.assign(n, 0);
  std::vector<Fraction> frac(n);
  std::vector<ActorId> stack, members;
  for (ActorId start = 0; start < n; ++start) {
    if (frac[start].num != 0) continue;
    members.clear();
    frac[start] = {1, 1};
    stack.push_back(start);
    while (!stack.empty()) {
      const ActorId a = stack.back();
      stack.pop_back();
      members.push_back(a);
      for (ChannelId c : adj.outputs(a)) {
        const Channel& ch = g.channel(c);
        if (frac[ch.dst].num == 0) {
          frac[ch.dst] = scale(frac[a], ch.prd, ch.cns);
          stack.push_back(ch.dst);
        }
      }
      for (ChannelId c : adj.inputs(a)) {
        const Channel& ch = g.channel(c);
        if (frac[ch.src].num == 0) {
          frac[ch.src] = scale(frac[a], ch.cns, ch.prd);
          stack.push_back(ch.src);
        }
      }
    }
    // lcm of the denominators, then integers; the result is already primitive (see header) but
    // dividing by the gcd costs nothing and keeps that an invariant rather than a proof.
    uint64_t l = 1;
    for (ActorId a : members) {
      const uint64_t d = frac[a].den;
      l = detail::mul(l / std::gcd(l, d), d, "the lcm of repetitions denominators");
    }
    uint64_t common = 0;
    for (ActorId a : members) {
      r.q[a] = detail::mul(frac[a].num, l / frac[a].den, "a repetitions-vector entry");
      common = std::gcd(common, r.q[a]);
    }
    for (ActorId a : members) r.q[a] /= common;
  }
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    const detail::u128 lhs = static_cast<detail::u128>(r.q[ch.src]) * ch.prd;
    const detail::u128 rhs = static_cast<detail::u128>(r.q[ch.dst]) * ch.cns;
    if (lhs != rhs) {
      r.consistent = false;
      r.channel = c;
      r.q_src = r.q[ch.src];
      r.q_dst = r.q[ch.dst];
      r.q.clear();
      return r;
    }
  }
  r.consistent = true;
  return r;
}

}  // namespace sdf
