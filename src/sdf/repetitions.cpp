#include "sdf/repetitions.hpp"

#include <numeric>
#include <optional>

#include "sdf/checked.hpp"

namespace sdf {

namespace {

struct Fraction {
  uint64_t num = 1;
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

// One end of a channel as seen from an actor: walking it multiplies the fraction by num/den.
struct Step {
  ActorId to;
  uint64_t num, den;
};

struct Visit {
  ActorId actor;
  Fraction f;
};

// Non-throwing twin of scale(): false when a product does not fit. The union-find calls it
// several times per channel, mostly with a 1 somewhere (equal rates, 1/1 fractions): those skip
// their gcds and divisions, which dominated.
bool scale_to(Fraction f, uint64_t a, uint64_t b, Fraction& out) {
  if (a == b) {
    out = f;
    return true;
  }
  if (a != 1 && b != 1) {
    const uint64_t g = std::gcd(a, b);
    a /= g;
    b /= g;
  }
  uint64_t num = f.num, den = f.den;
  if (b != 1 && num != 1) {
    const uint64_t g1 = std::gcd(num, b);
    num /= g1;
    b /= g1;
  }
  if (a != 1 && den != 1) {
    const uint64_t g2 = std::gcd(a, den);
    a /= g2;
    den /= g2;
  }
  return !__builtin_mul_overflow(num, a, &out.num) && !__builtin_mul_overflow(den, b, &out.den);
}

// Union-find over the channels in file order, each node holding q_node / q_parent as a reduced
// fraction. Returns the vector when the graph is consistent and every count fits in 64 bits —
// then it is the unique primitive solution, whatever spanning forest found it — and nothing
// otherwise (the walk then produces the exact report). Channels are visited in order and the two
// finds of one channel do not depend on the previous channel's, so the memory accesses overlap;
// the walk follows one actor after another and waits for each cache miss in turn.
struct UnionFind {
  struct Node {
    uint32_t parent;
    uint32_t size;
    Fraction rel;  // q_node / q_parent, reduced
  };
  std::vector<Node> nodes;
  std::vector<uint32_t> path;

  explicit UnionFind(size_t n) : nodes(n) {
    for (size_t v = 0; v < n; ++v) nodes[v] = {static_cast<uint32_t>(v), 1, {1, 1}};
  }

  // The root of v and q_v / q_root; compresses the path. False on overflow.
  bool find(uint32_t v, uint32_t& root, Fraction& x) {
    path.clear();
    uint32_t r = v;
    while (nodes[r].parent != r) {
      path.push_back(r);
      r = nodes[r].parent;
    }
    root = r;
    // From the node nearest the root down: rel(node -> root) = rel(node -> parent) · rel(parent
    // -> root), and the node is hung directly below the root.
    Fraction above{1, 1};
    for (size_t i = path.size(); i-- > 0;) {
      Node& node = nodes[path[i]];
      Fraction to_root;
      if (!scale_to(node.rel, above.num, above.den, to_root)) return false;
      node.rel = to_root;
      node.parent = r;
      above = to_root;
    }
    x = above;
    return true;
  }
};

std::optional<std::vector<uint64_t>> union_find_vector(const Graph& g) {
  const size_t n = g.actor_count();
  UnionFind uf(n);
  const std::span<const Channel> channels = g.channels();
  constexpr size_t kAhead = 16;  // channels whose nodes are prefetched ahead of use
  for (size_t i = 0; i < channels.size(); ++i) {
    if (i + 4 * kAhead < channels.size()) __builtin_prefetch(&channels[i + 4 * kAhead]);
    if (i + kAhead < channels.size()) {
      __builtin_prefetch(&uf.nodes[channels[i + kAhead].src]);
      __builtin_prefetch(&uf.nodes[channels[i + kAhead].dst]);
    }
    const Channel& c = channels[i];
    uint32_t rs, rd;
    Fraction xs, xd, y;
    if (!uf.find(c.src, rs, xs) || !uf.find(c.dst, rd, xd)) return std::nullopt;
    // q_dst / q_rs = (q_src / q_rs) · prd / cns.
    if (!scale_to(xs, c.prd, c.cns, y)) return std::nullopt;
    if (rs == rd) {
      if (y.num != xd.num || y.den != xd.den) return std::nullopt;  // inconsistent
      continue;
    }
    // q_rd / q_rs = (q_dst / q_rs) / (q_dst / q_rd).
    Fraction rd_over_rs;
    if (!scale_to(y, xd.den, xd.num, rd_over_rs)) return std::nullopt;
    UnionFind::Node& a = uf.nodes[rs];
    UnionFind::Node& b = uf.nodes[rd];
    if (a.size >= b.size) {
      b.parent = rs;
      b.rel = rd_over_rs;
      a.size += b.size;
    } else {
      a.parent = rd;
      a.rel = {rd_over_rs.den, rd_over_rs.num};
      b.size += a.size;
    }
  }
  // Per root: the lcm of the denominators, then the gcd of the integers. After a find on every
  // actor each node hangs directly below its root with rel = q_v / q_root, so the passes read the
  // nodes in order and touch only the small per-root accumulators at random.
  std::vector<uint64_t> q(n), lcm(n, 1), common(n, 0);
  for (uint32_t v = 0; v < n; ++v) {
    uint32_t r;
    Fraction x;
    if (!uf.find(v, r, x)) return std::nullopt;
    uint64_t& l = lcm[r];
    if (x.den != 1 && __builtin_mul_overflow(l / std::gcd(l, x.den), x.den, &l))
      return std::nullopt;
  }
  for (uint32_t v = 0; v < n; ++v) {
    const UnionFind::Node& node = uf.nodes[v];  // the root itself: parent v, rel 1/1
    if (__builtin_mul_overflow(node.rel.num, lcm[node.parent] / node.rel.den, &q[v]))
      return std::nullopt;
    uint64_t& c = common[node.parent];
    if (c != 1) c = std::gcd(c, q[v]);  // once 1, always 1
  }
  for (uint32_t v = 0; v < n; ++v)
    if (const uint64_t c = common[uf.nodes[v].parent]; c != 1) q[v] /= c;
  return q;
}

// The spanning walk: depth-first from each component's lowest actor, fractions assigned at
// discovery. Its spanning tree defines q_src / q_dst of an inconsistency report and which overflow
// is reported, so it is kept exactly as first specified (naive::repetitions is its plain twin).
Repetitions walk(const Graph& g) {
  const size_t n = g.actor_count();
  const std::span<const Channel> channels = g.channels();
  // Per actor, its output steps then its input steps, each in channel order (the order of
  // Adjacency::outputs / inputs), with the rates inline: the walk then reads one contiguous block
  // per actor instead of one Channel per incident channel (with actor ids in random order, those
  // reads are cache misses and dominated the time).
  std::vector<uint64_t> off(n + 1, 0), in_start(n, 0);
  for (const Channel& c : channels) {
    ++off[c.src + 1];
    ++off[c.dst + 1];
  }
  for (size_t a = 0; a < n; ++a) off[a + 1] += off[a];
  std::vector<uint64_t> out_fill(off.begin(), off.end() - 1);
  for (const Channel& c : channels) ++in_start[c.src];  // output count per actor
  for (size_t a = 0; a < n; ++a) in_start[a] += off[a];
  std::vector<Step> steps(off[n]);
  for (const Channel& c : channels) {
    steps[out_fill[c.src]++] = {c.dst, c.prd, c.cns};
    steps[in_start[c.dst]++] = {c.src, c.cns, c.prd};
  }

  Repetitions r;
  r.q.assign(n, 0);
  std::vector<uint64_t> visited((n + 63) / 64, 0);
  auto seen = [&](ActorId a) { return (visited[a >> 6] >> (a & 63)) & 1; };
  auto mark = [&](ActorId a) { visited[a >> 6] |= uint64_t{1} << (a & 63); };
  std::vector<Visit> stack, members;
  for (ActorId start = 0; start < n; ++start) {
    if (seen(start)) continue;
    members.clear();
    mark(start);
    stack.push_back({start, {1, 1}});
    while (!stack.empty()) {
      const Visit v = stack.back();
      stack.pop_back();
      members.push_back(v);
      for (uint64_t i = off[v.actor]; i < off[v.actor + 1]; ++i) {
        const Step& s = steps[i];
        if (!seen(s.to)) {
          mark(s.to);
          stack.push_back({s.to, scale(v.f, s.num, s.den)});
        }
      }
    }
    // lcm of the denominators, then integers; the result is already primitive (see header) but
    // dividing by the gcd costs nothing and keeps that an invariant rather than a proof.
    uint64_t l = 1;
    for (const Visit& m : members) {
      const uint64_t d = m.f.den;
      if (d != 1) l = detail::mul(l / std::gcd(l, d), d, "the lcm of repetitions denominators");
    }
    uint64_t common = 0;
    for (Visit& m : members) {
      m.f.num = detail::mul(m.f.num, l / m.f.den, "a repetitions-vector entry");
      common = std::gcd(common, m.f.num);
    }
    for (const Visit& m : members) r.q[m.actor] = m.f.num / common;
  }
  for (ChannelId c = 0; c < channels.size(); ++c) {
    const Channel& ch = channels[c];
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

}  // namespace

Repetitions compute_repetitions(const Graph& g) {
  if (auto q = union_find_vector(g)) {
    // Every channel either joined two trees (which fixed the ratio of its ends exactly) or was
    // checked against the ratio already fixed, and each component's integers are one common
    // multiple of those exact ratios: every balance equation holds, no second pass needed (the
    // tests compare with the walk, which does check every channel).
    Repetitions r;
    r.q = std::move(*q);
    r.consistent = true;
    return r;
  }
  return walk(g);
}

}  // namespace sdf
