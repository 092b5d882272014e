// Graph statistics (include/sdf/stats.hpp). Simple cycles by Johnson's algorithm ("Finding all
// the elementary circuits of a directed graph", SIAM J. Comput. 1975), with explicit stacks so
// that long cycles do not exhaust the call stack: for each actor s in increasing order, the
// cycles whose smallest actor is s, searched among the actors ≥ s of s's strongly connected
// component; an actor from which no cycle back to s was found stays blocked until one of its
// successors is unblocked, which keeps the search linear per cycle found. Parallel channels are
// separate arcs, so each gives its own cycles.
#include "sdf/stats.hpp"

#include <algorithm>

#include "checked.hpp"
#include "scc.hpp"
#include "sdf/repetitions.hpp"

namespace sdf {

namespace {

class Cycles {
 public:
  Cycles(uint32_t n, const std::vector<uint32_t>& off, const std::vector<uint32_t>& succ,
         const std::vector<uint32_t>& comp, const StatsLimits& limits)
      : off_(off), succ_(succ), comp_(comp), limits_(limits), blocked_(n, 0), b_(n) {}

  // Counts the cycles whose smallest actor is s. False when a limit stopped the count.
  bool from(uint32_t s) {
    s_ = s;
    for (uint32_t v : touched_) blocked_[v] = 0, b_[v].clear();
    touched_.clear();
    struct Frame {
      uint32_t v, next;
      bool found;
    };
    std::vector<Frame> frames;
    auto push = [&](uint32_t v) {
      blocked_[v] = 1;
      touched_.push_back(v);
      frames.push_back({v, off_[v], false});
    };
    push(s);
    while (!frames.empty()) {
      Frame& f = frames.back();
      if (f.next < off_[f.v + 1]) {
        const uint32_t w = succ_[f.next++];
        if (++steps_ > limits_.max_steps) return false;
        if (!in_scope(w)) continue;
        if (w == s) {
          f.found = true;
          if (count_ == limits_.max_cycles) return false;  // one more than the limit allows
          ++count_;
        } else if (!blocked_[w]) {
          push(w);
        }
        continue;
      }
      const uint32_t v = f.v;
      const bool found = f.found;
      frames.pop_back();
      if (found) {
        unblock(v);
        if (!frames.empty()) frames.back().found = true;
      } else {
        for (uint32_t i = off_[v]; i < off_[v + 1]; ++i) {
          const uint32_t w = succ_[i];
          if (!in_scope(w)) continue;
          auto& bw = b_[w];
          steps_ += bw.size();
          if (std::find(bw.begin(), bw.end(), v) == bw.end()) {
            if (bw.empty()) touched_.push_back(w);
            bw.push_back(v);
          }
        }
        if (steps_ > limits_.max_steps) return false;
      }
    }
    return true;
  }

  uint64_t count() const { return count_; }

 private:
  bool in_scope(uint32_t w) const { return w >= s_ && comp_[w] == comp_[s_]; }

  void unblock(uint32_t u) {
    std::vector<uint32_t> work{u};
    while (!work.empty()) {
      const uint32_t x = work.back();
      work.pop_back();
      if (!blocked_[x]) continue;
      blocked_[x] = 0;
      for (uint32_t w : b_[x]) work.push_back(w);
      b_[x].clear();
    }
  }

  const std::vector<uint32_t>& off_;
  const std::vector<uint32_t>& succ_;
  const std::vector<uint32_t>& comp_;
  const StatsLimits& limits_;
  std::vector<char> blocked_;
  std::vector<std::vector<uint32_t>> b_;  // b_[w]: blocked actors to unblock with w
  std::vector<uint32_t> touched_;
  uint32_t s_ = 0;
  uint64_t count_ = 0, steps_ = 0;
};

}  // namespace

GraphStats graph_stats(const Graph& g, const StatsLimits& limits) {
  GraphStats st;
  const auto n = static_cast<uint32_t>(g.actor_count());
  st.actors = n;
  st.channels = g.channel_count();
  uint64_t tokens = 0;
  bool tokens_fit = true;
  for (const Channel& c : g.channels()) {
    st.self_loops += c.src == c.dst;
    tokens_fit = tokens_fit && !__builtin_add_overflow(tokens, c.delay, &tokens);
  }
  if (tokens_fit) st.initial_tokens = tokens;
  try {
    const Repetitions rep = compute_repetitions(g);
    st.consistent = rep.consistent;
    if (rep.consistent) {
      uint64_t sum = 0, max = 0;
      bool fits = true;
      for (uint64_t v : rep.q) {
        fits = fits && !__builtin_add_overflow(sum, v, &sum);
        max = std::max(max, v);
      }
      if (fits) st.repetitions_sum = sum;
      st.repetitions_max = max;
    }
  } catch (const Error& e) {
    if (e.kind() != Error::Kind::overflow) throw;
    st.repetitions_overflow = true;
  }
  const Adjacency adj(g);
  st.components = connected_components(g, adj).count;
  std::vector<uint32_t> off(n + 1, 0), succ;
  succ.reserve(g.channel_count());
  for (ActorId a = 0; a < n; ++a) {
    for (ChannelId c : adj.outputs(a)) succ.push_back(g.channel(c).dst);
    off[a + 1] = static_cast<uint32_t>(succ.size());
  }
  const std::vector<uint32_t> comp = detail::strong_components(n, off, succ, st.sccs);
  std::vector<uint32_t> size(st.sccs, 0);
  std::vector<char> cyclic(st.sccs, 0);
  for (ActorId a = 0; a < n; ++a) ++size[comp[a]];
  for (const Channel& c : g.channels())
    if (comp[c.src] == comp[c.dst]) cyclic[comp[c.src]] = 1;  // a self-loop, or inside an SCC
  for (uint32_t c = 0; c < st.sccs; ++c) {
    st.largest_scc = std::max(st.largest_scc, size[c]);
    st.cyclic_sccs += cyclic[c];
  }
  Cycles cycles(n, off, succ, comp, limits);
  for (ActorId s = 0; s < n && st.cycles_complete; ++s)
    if (cyclic[comp[s]]) st.cycles_complete = cycles.from(s);
  st.simple_cycles = cycles.count();
  return st;
}

}  // namespace sdf
