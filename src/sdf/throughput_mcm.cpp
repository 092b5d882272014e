// Throughput as the inverse of the maximum cycle ratio (execution time / tokens) of the HSDF
// expansion. The expansion's edges with tokens are cut into their tokens; the token graph has a
// vertex per token and an edge from token x to token y weighted by the longest (in execution
// time) token-free path from x's consumer to y's producer, both firings included; successive
// tokens of one edge are joined with weight 0. A cycle of the token graph with m edges and
// weight w is a cycle of the expansion with m tokens and execution time w, so the maximum cycle
// mean of the token graph (Karp, 1978: exact, in integers) is the maximum cycle ratio.
// A token-free cycle of the expansion is a deadlock.
#include <algorithm>
#include <numeric>

#include "hsdf.hpp"
#include "scc.hpp"
#include "sdf/throughput.hpp"

namespace sdf {

namespace {

__extension__ using i128 = __int128;
constexpr i128 kNegInf = -(static_cast<i128>(1) << 120);

i128 gcd128(i128 a, i128 b) {  // a, b >= 0
  while (b != 0) {
    const i128 t = a % b;
    a = b;
    b = t;
  }
  return a;
}

struct TokenGraph {
  // Token vertices: for expansion edge e with tokens, base[e] .. base[e] + tokens - 1; the
  // first is produced by e.src, the last consumed by e.dst.
  std::vector<uint64_t> base;
  uint64_t tokens = 0;
  struct Arc {
    uint32_t from, to;
    i128 weight;
  };
  std::vector<Arc> arcs;
};

class Mcm {
 public:
  Mcm(const Graph& g, std::optional<uint64_t> default_time, const ThroughputLimits& limits)
      : g_(g), limits_(limits) {
    const std::vector<uint64_t> q = detail::repetitions_or_throw(g, "throughput");
    const std::vector<uint64_t> times = execution_times(g, default_time);
    h_ = detail::expand(g, q, limits.max_hsdf_size);
    const size_t n = h_.actor.size();
    time_.resize(n);
    for (size_t f = 0; f < n; ++f) time_[f] = times[h_.actor[f]];
    // Token-free successors in compressed form (edges are sorted by src).
    zoff_.assign(n + 1, 0);
    toff_.assign(n + 1, 0);
    for (const detail::HsdfEdge& e : h_.edges) ++(e.tokens == 0 ? zoff_ : toff_)[e.src + 1];
    for (size_t f = 0; f < n; ++f) zoff_[f + 1] += zoff_[f], toff_[f + 1] += toff_[f];
    zsucc_.resize(zoff_[n]);
    tedge_.resize(toff_[n]);
    std::vector<uint32_t> zf(zoff_.begin(), zoff_.end() - 1), tf(toff_.begin(), toff_.end() - 1);
    for (uint32_t i = 0; i < h_.edges.size(); ++i) {
      const detail::HsdfEdge& e = h_.edges[i];
      if (e.tokens == 0)
        zsucc_[zf[e.src]++] = e.dst;
      else
        tedge_[tf[e.src]++] = i;
    }
  }

  Throughput run() {
    Throughput r;
    if (const std::vector<uint32_t> cycle = token_free_cycle(); !cycle.empty()) {
      r.num = 0, r.den = 1;
      for (uint32_t f : cycle) r.deadlock_cycle.push_back(firing_name(f));
      return r;
    }
    build_token_graph();
    // Karp on each strongly connected component of the token graph that holds a cycle.
    const auto n = static_cast<uint32_t>(tg_.tokens);
    std::vector<uint32_t> off(n + 1, 0), succ(tg_.arcs.size());
    for (const auto& a : tg_.arcs) ++off[a.from + 1];
    for (uint32_t v = 0; v < n; ++v) off[v + 1] += off[v];
    {
      std::vector<uint32_t> fill(off.begin(), off.end() - 1);
      for (const auto& a : tg_.arcs) succ[fill[a.from]++] = a.to;
    }
    uint32_t count = 0;
    const std::vector<uint32_t> comp = detail::strong_components(n, off, succ, count);
    std::vector<std::vector<uint32_t>> members(count);
    for (uint32_t v = 0; v < n; ++v) members[comp[v]].push_back(v);
    bool found = false;
    i128 best_w = 0, best_m = 1;
    std::vector<uint32_t> best_cycle;
    for (uint32_t c = 0; c < count; ++c) {
      std::vector<uint32_t> cycle;
      i128 w = 0, m = 1;
      if (!karp(members[c], comp, c, w, m, cycle)) continue;
      if (!found || w * best_m > best_w * m)
        found = true, best_w = w, best_m = m, best_cycle = cycle;
    }
    if (!found || best_w == 0) {  // no cycle, or only cycles without execution time
      r.unbounded = true;
      r.num = r.den = 0;
      return r;
    }
    // Throughput = tokens / time of the critical cycle, reduced.
    const i128 gcd = gcd128(best_w, best_m);
    const i128 num = best_m / gcd, den = best_w / gcd;
    if (den > static_cast<i128>(UINT64_MAX) || num > static_cast<i128>(UINT64_MAX))
      throw Error(Error::Kind::overflow, "the throughput's numerator or denominator");
    r.num = static_cast<uint64_t>(num);
    r.den = static_cast<uint64_t>(den);
    expand_cycle(best_cycle, r);
    return r;
  }

 private:
  std::string firing_name(uint32_t f) const {
    return g_.actor_name(h_.actor[f]) + "_" + std::to_string(h_.index[f]);
  }

  // A cycle of token-free edges (a deadlock), or empty.
  std::vector<uint32_t> token_free_cycle() const {
    const auto n = static_cast<uint32_t>(h_.actor.size());
    std::vector<uint8_t> state(n, 0);  // 0 new, 1 on the path, 2 done
    std::vector<std::pair<uint32_t, uint32_t>> path;
    for (uint32_t root = 0; root < n; ++root) {
      if (state[root] != 0) continue;
      path.push_back({root, zoff_[root]});
      state[root] = 1;
      while (!path.empty()) {
        auto& [v, slot] = path.back();
        if (slot == zoff_[v + 1]) {
          state[v] = 2;
          path.pop_back();
          continue;
        }
        const uint32_t w = zsucc_[slot++];
        if (state[w] == 1) {
          std::vector<uint32_t> cycle;
          size_t i = path.size();
          while (path[i - 1].first != w) --i;
          for (; i <= path.size(); ++i) cycle.push_back(path[i - 1].first);
          return cycle;
        }
        if (state[w] == 0) {
          state[w] = 1;
          path.push_back({w, zoff_[w]});
        }
      }
    }
    return {};
  }

  // Longest token-free paths from firing `from` (its own time included) to every firing it
  // reaches, in topological order of the reached part; pred receives the predecessors.
  void longest_from(uint32_t from, std::vector<i128>& dist, std::vector<uint32_t>& pred,
                    std::vector<uint32_t>& reached) {
    // Topological order of the reached part by a depth-first post-order.
    reached.clear();
    order_.clear();
    std::vector<std::pair<uint32_t, uint32_t>> stack{{from, zoff_[from]}};
    seen_[from] = stamp_;
    while (!stack.empty()) {
      auto& [v, slot] = stack.back();
      if (slot == zoff_[v + 1]) {
        order_.push_back(v);
        stack.pop_back();
        continue;
      }
      const uint32_t w = zsucc_[slot++];
      if (seen_[w] != stamp_) {
        seen_[w] = stamp_;
        stack.push_back({w, zoff_[w]});
      }
    }
    for (auto it = order_.rbegin(); it != order_.rend(); ++it) {
      dist[*it] = kNegInf;
      reached.push_back(*it);
    }
    dist[from] = time_[from];
    pred[from] = UINT32_MAX;
    for (uint32_t v : reached)
      for (uint32_t s = zoff_[v]; s < zoff_[v + 1]; ++s) {
        const uint32_t w = zsucc_[s];
        const i128 d = dist[v] + time_[w];
        if (d > dist[w]) dist[w] = d, pred[w] = v;
      }
    ++stamp_;
  }

  void build_token_graph() {
    tg_.base.resize(h_.edges.size());
    for (size_t e = 0; e < h_.edges.size(); ++e) {
      tg_.base[e] = tg_.tokens;
      tg_.tokens += h_.edges[e].tokens;
      if (tg_.tokens > UINT32_MAX - 1 ||
          static_cast<double>(tg_.tokens) * static_cast<double>(tg_.tokens + 1) >
              static_cast<double>(limits_.max_token_graph))
        throw Error(Error::Kind::limit,
                    "the HSDF expansion holds more initial tokens than the cycle-ratio analysis "
                    "takes (Karp's table would exceed " +
                        std::to_string(limits_.max_token_graph) + " entries)");
    }
    const size_t n = h_.actor.size();
    std::vector<i128> dist(n);
    std::vector<uint32_t> pred(n), reached;
    seen_.assign(n, 0);
    stamp_ = 1;
    std::vector<int64_t> arc_at;  // per token vertex: index of its arc from the current source
    for (size_t e = 0; e < h_.edges.size(); ++e) {
      const detail::HsdfEdge& he = h_.edges[e];
      if (he.tokens == 0) continue;
      for (uint64_t i = 0; i + 1 < he.tokens; ++i)
        tg_.arcs.push_back({static_cast<uint32_t>(tg_.base[e] + i),
                            static_cast<uint32_t>(tg_.base[e] + i + 1), 0});
    }
    // From the last token of every edge into firing v: the same paths, so compute them once
    // per consuming firing.
    std::vector<std::vector<uint32_t>> last_into(n);
    for (size_t e = 0; e < h_.edges.size(); ++e)
      if (h_.edges[e].tokens != 0)
        last_into[h_.edges[e].dst].push_back(
            static_cast<uint32_t>(tg_.base[e] + h_.edges[e].tokens - 1));
    for (uint32_t v = 0; v < n; ++v) {
      if (last_into[v].empty()) continue;
      longest_from(v, dist, pred, reached);
      for (uint32_t x : reached)
        for (uint32_t s = toff_[x]; s < toff_[x + 1]; ++s) {
          const uint32_t e = tedge_[s];
          for (uint32_t from : last_into[v])
            tg_.arcs.push_back({from, static_cast<uint32_t>(tg_.base[e]), dist[x]});
        }
    }
  }

  // Karp's maximum cycle mean on one component; false when it holds no cycle.
  bool karp(const std::vector<uint32_t>& vs, const std::vector<uint32_t>& comp, uint32_t c,
            i128& best_w, i128& best_m, std::vector<uint32_t>& cycle) {
    const size_t m = vs.size();
    local_.resize(tg_.tokens);
    for (size_t i = 0; i < m; ++i) local_[vs[i]] = static_cast<uint32_t>(i);
    std::vector<std::pair<uint32_t, uint32_t>> arcs;  // local (from, to)
    std::vector<i128> weight;
    for (size_t a = 0; a < tg_.arcs.size(); ++a) {
      const auto& arc = tg_.arcs[a];
      if (comp[arc.from] == c && comp[arc.to] == c) {
        arcs.push_back({local_[arc.from], local_[arc.to]});
        weight.push_back(arc.weight);
      }
    }
    if (arcs.empty()) return false;
    // D[k][v]: the heaviest walk of exactly k arcs from vertex 0 to v.
    std::vector<i128> D((m + 1) * m, kNegInf);
    std::vector<uint32_t> P((m + 1) * m, UINT32_MAX);
    D[0] = 0;
    for (size_t k = 1; k <= m; ++k)
      for (size_t a = 0; a < arcs.size(); ++a) {
        const i128 prev = D[(k - 1) * m + arcs[a].first];
        if (prev == kNegInf) continue;
        const i128 d = prev + weight[a];
        i128& cur = D[k * m + arcs[a].second];
        if (d > cur) cur = d, P[k * m + arcs[a].second] = arcs[a].first;
      }
    // λ = max_v min_k (D[m][v] − D[k][v]) / (m − k).
    bool any = false;
    size_t arg = 0;
    i128 lw = 0, lm = 1;
    for (size_t v = 0; v < m; ++v) {
      if (D[m * m + v] == kNegInf) continue;
      i128 vw = 0, vm = 0;
      for (size_t k = 0; k < m; ++k) {
        if (D[k * m + v] == kNegInf) continue;
        const i128 w = D[m * m + v] - D[k * m + v], len = static_cast<i128>(m - k);
        if (vm == 0 || w * vm < vw * len) vw = w, vm = len;
      }
      if (vm != 0 && (!any || vw * lm > lw * vm)) any = true, lw = vw, lm = vm, arg = v;
    }
    if (!any) return false;
    // The heaviest m-arc walk to arg holds a cycle of mean λ: find it on the walk.
    std::vector<uint32_t> walk(m + 1);
    walk[m] = static_cast<uint32_t>(arg);
    for (size_t k = m; k > 0; --k) walk[k - 1] = P[k * m + walk[k]];
    std::vector<int64_t> last(m, -1);
    for (size_t k = 0; k <= m; ++k) {
      const uint32_t v = walk[k];
      if (last[v] >= 0) {
        const size_t from = static_cast<size_t>(last[v]);
        const i128 w = D[k * m + v] - D[from * m + v];
        const auto len = static_cast<i128>(k - from);
        if (w * lm == lw * len) {
          cycle.clear();
          for (size_t i = from; i < k; ++i) cycle.push_back(vs[walk[i]]);
          const i128 gcd = gcd128(lw, lm);
          best_w = lw / (gcd == 0 ? 1 : gcd);
          best_m = lm / (gcd == 0 ? 1 : gcd);
          if (best_w == 0) best_m = 1;
          return true;
        }
      }
      last[v] = static_cast<int64_t>(k);
    }
    throw std::logic_error("throughput_mcm: no critical cycle on Karp's walk");
  }

  // A simple cycle of firings of the critical token-graph cycle, with its time and tokens. The
  // token-graph cycle is a closed walk of the expansion that may pass a firing twice; every
  // simple cycle it splits into has a ratio of at most the maximum and together they reach it,
  // so each has exactly the maximum ratio: the first one closed is reported.
  void expand_cycle(const std::vector<uint32_t>& tokens, Throughput& r) {
    const size_t n = h_.actor.size();
    std::vector<i128> dist(n);
    std::vector<uint32_t> pred(n), reached;
    auto edge_of = [&](uint32_t t) {
      return static_cast<size_t>(std::upper_bound(tg_.base.begin(), tg_.base.end(), t,
                                                  [](uint64_t x, uint64_t b) { return x < b; }) -
                                 tg_.base.begin() - 1);
    };
    // The closed walk as (firing, tokens on the edge to the next firing).
    std::vector<std::pair<uint32_t, uint64_t>> walk;
    for (size_t i = 0; i < tokens.size(); ++i) {
      const size_t e = edge_of(tokens[i]);
      if (tokens[i] != tg_.base[e] + h_.edges[e].tokens - 1) continue;  // inside a chain
      const size_t next = edge_of(tokens[(i + 1) % tokens.size()]);
      const uint32_t v = h_.edges[e].dst, x = h_.edges[next].src;
      longest_from(v, dist, pred, reached);
      std::vector<uint32_t> path;
      for (uint32_t f = x; f != UINT32_MAX; f = pred[f]) path.push_back(f);
      for (auto it = path.rbegin(); it != path.rend(); ++it) walk.push_back({*it, 0});
      walk.back().second = h_.edges[next].tokens;
    }
    std::vector<int64_t> at(n, -1);
    size_t from = 0, to = walk.size();
    for (size_t j = 0; j < walk.size(); ++j) {
      if (at[walk[j].first] >= 0) {
        from = static_cast<size_t>(at[walk[j].first]), to = j;
        break;
      }
      at[walk[j].first] = static_cast<int64_t>(j);
    }
    for (size_t j = from; j < to; ++j) {
      r.critical_cycle.push_back(firing_name(walk[j].first));
      r.cycle_time += time_[walk[j].first];
      r.cycle_tokens += walk[j].second;
    }
  }

  const Graph& g_;
  const ThroughputLimits& limits_;
  detail::Hsdf h_;
  std::vector<uint64_t> time_;
  std::vector<uint32_t> zoff_, zsucc_, toff_, tedge_;
  TokenGraph tg_;
  std::vector<uint32_t> local_, seen_, order_;
  uint32_t stamp_ = 1;
};

}  // namespace

Throughput throughput_mcm(const Graph& g, std::optional<uint64_t> default_time,
                          const ThroughputLimits& limits) {
  return Mcm(g, default_time, limits).run();
}

}  // namespace sdf
