#include <algorithm>
#include <deque>

#include "sdf/checked.hpp"
#include "sdf/schedule.hpp"

namespace sdf {

uint64_t total_firings(std::span<const Run> runs) {
  uint64_t t = 0;
  for (const Run& r : runs) t = detail::add_sat(t, r.count);
  return t;
}

std::string run_length_form(const Graph& g, std::span<const Run> runs) {
  std::string s;
  for (const Run& r : runs) {
    s += '(';
    s += std::to_string(r.count);
    s += ' ';
    s += g.actor_name(r.actor);
    s += ')';
  }
  return s;
}

namespace {

// Firings in a row actor a can make now, at most `cap`.
uint64_t can_fire(const Graph& g, const Adjacency& adj, std::span<const uint64_t> tokens, ActorId a,
                  uint64_t cap) {
  uint64_t k = cap;
  for (ChannelId c : adj.inputs(a)) {
    const Channel& ch = g.channel(c);
    k = std::min(k, detail::firings_allowed(tokens[c], ch.prd, ch.cns, ch.src == ch.dst));
    if (k == 0) break;
  }
  return k;
}

// Fires a k times in a row (admissibility already checked). A self-loop nets production
// against consumption, so a loop that gains tokens never dips below zero on the way.
void fire(const Graph& g, const Adjacency& adj, std::vector<uint64_t>& tokens, ActorId a,
          uint64_t k) {
  for (ChannelId c : adj.inputs(a)) {
    const Channel& ch = g.channel(c);
    if (ch.src != ch.dst) tokens[c] -= k * ch.cns;  // k·cns <= tokens
  }
  for (ChannelId c : adj.outputs(a)) {
    const Channel& ch = g.channel(c);
    if (ch.src == ch.dst && ch.prd < ch.cns) {
      tokens[c] -= k * (ch.cns - ch.prd);
    } else {
      const uint64_t gain = ch.src == ch.dst ? ch.prd - ch.cns : ch.prd;
      tokens[c] = detail::add_tokens(tokens[c], k, gain, g, c);
    }
  }
}

}  // namespace

StaticSchedule static_schedule(const Graph& g, std::span<const uint64_t> q,
                               std::span<const uint64_t> tokens0) {
  const size_t n = g.actor_count();
  const Adjacency adj(g);
  std::vector<uint64_t> tokens =
      tokens0.empty() ? g.delays() : std::vector<uint64_t>(tokens0.begin(), tokens0.end());
  StaticSchedule s;
  s.fired.assign(n, 0);
  std::deque<ActorId> ready;
  std::vector<char> queued(n, 0);
  for (ActorId a = 0; a < n; ++a) {
    if (q[a] > 0 && can_fire(g, adj, tokens, a, 1) > 0) {
      ready.push_back(a);
      queued[a] = 1;
    }
  }
  while (!ready.empty()) {
    const ActorId a = ready.front();
    ready.pop_front();
    queued[a] = 0;
    // Inputs only grow while an actor waits in the queue, so recomputing here fires it as often
    // as it can when its turn comes (the thesis's r(A) taken at removal time).
    const uint64_t k = can_fire(g, adj, tokens, a, q[a] - s.fired[a]);
    if (k == 0) continue;
    fire(g, adj, tokens, a, k);
    s.fired[a] += k;
    s.runs.push_back({a, k});
    auto offer = [&](ActorId b) {
      if (!queued[b] && s.fired[b] < q[b] && can_fire(g, adj, tokens, b, 1) > 0) {
        ready.push_back(b);
        queued[b] = 1;
      }
    };
    for (ChannelId c : adj.outputs(a)) offer(g.channel(c).dst);
    offer(a);
  }
  for (ActorId a = 0; a < n; ++a)
    if (s.fired[a] < q[a]) s.stuck.push_back(a);
  s.complete = s.stuck.empty();
  if (s.complete) return s;

  // Each stuck actor has an input that lacks tokens for its next firing; that input's source is
  // stuck too (a source that reached its count delivered enough for every firing of the period).
  // Following those inputs backwards from any stuck actor must therefore close a cycle.
  std::vector<int64_t> blocking(n, -1);
  for (ActorId a : s.stuck) {
    for (ChannelId c : adj.inputs(a)) {
      const Channel& ch = g.channel(c);
      if (detail::firings_allowed(tokens[c], ch.prd, ch.cns, ch.src == ch.dst) == 0 &&
          s.fired[ch.src] < q[ch.src]) {
        blocking[a] = c;
        break;
      }
    }
  }
  std::vector<int64_t> seen_at(n, -1);
  std::vector<ChannelId> path;
  ActorId a = s.stuck.front();
  while (blocking[a] >= 0 && seen_at[a] < 0) {
    seen_at[a] = static_cast<int64_t>(path.size());
    path.push_back(static_cast<ChannelId>(blocking[a]));
    a = g.channel(path.back()).src;
  }
  if (blocking[a] >= 0 && seen_at[a] >= 0) {
    // path[seen_at[a]..] walks the cycle backwards; report it forwards.
    s.starved_cycle.assign(path.begin() + seen_at[a], path.end());
    std::reverse(s.starved_cycle.begin(), s.starved_cycle.end());
  }
  return s;
}

}  // namespace sdf
