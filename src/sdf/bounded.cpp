#include "bounded.hpp"

#include <algorithm>
#include <deque>
#include <numeric>
#include <queue>
#include <string>
#include <unordered_map>

#include "checked.hpp"
#include "scc.hpp"

namespace sdf::detail {

namespace {

__extension__ using u128 = unsigned __int128;

// Who waited for whom during a run, and which channels' places were waited for.
class Waits {
 public:
  explicit Waits(size_t channels) : lack_(channels, 0) {}
  void wait(ActorId waiter, ActorId on) { edges_.push_back({waiter, on}); }
  void lack_places(ChannelId c) { lack_[c] = 1; }

  // Channels whose places were waited for on a cycle of waits: both ends in one strongly
  // connected component (a self-loop's wait is a cycle by itself).
  std::vector<char> storage_dependencies(const Graph& g) {
    const auto n = static_cast<uint32_t>(g.actor_count());
    std::sort(edges_.begin(), edges_.end());
    edges_.erase(std::unique(edges_.begin(), edges_.end()), edges_.end());
    std::vector<uint32_t> off(n + 1, 0), succ(edges_.size());
    for (const auto& e : edges_) ++off[e.first + 1];
    for (uint32_t a = 0; a < n; ++a) off[a + 1] += off[a];
    for (size_t i = 0; i < edges_.size(); ++i) succ[i] = edges_[i].second;
    uint32_t count = 0;
    const std::vector<uint32_t> comp = strong_components(n, off, succ, count);
    std::vector<char> dep(g.channel_count(), 0);
    for (ChannelId c = 0; c < g.channel_count(); ++c)
      dep[c] = lack_[c] && comp[g.channel(c).src] == comp[g.channel(c).dst];
    return dep;
  }

 private:
  std::vector<std::pair<ActorId, ActorId>> edges_;
  std::vector<char> lack_;
};

// At a standstill every actor waits: for the producer of an input short of tokens, for the
// consumer of an output short of places.
std::vector<char> standstill_dependencies(const Graph& g, std::span<const uint64_t> tokens,
                                          std::span<const uint64_t> space) {
  Waits w(g.channel_count());
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    if (tokens[c] < ch.cns) w.wait(ch.dst, ch.src);
    if (space[c] < ch.prd) {
      w.wait(ch.src, ch.dst);
      w.lack_places(c);
    }
  }
  return w.storage_dependencies(g);
}

}  // namespace

BoundedModel::BoundedModel(const Graph& g, std::vector<uint64_t> q, std::vector<uint64_t> times)
    : g_(g), q_(std::move(q)), times_(std::move(times)) {
  const Adjacency adj(g);
  const auto n = static_cast<ActorId>(g.actor_count());
  in_off_.assign(n + 1, 0);
  out_off_.assign(n + 1, 0);
  for (ActorId a = 0; a < n; ++a) {
    for (ChannelId c : adj.inputs(a)) ports_.push_back({c, g.channel(c).src, g.channel(c).cns});
    in_off_[a + 1] = static_cast<uint32_t>(ports_.size());
  }
  out_off_[0] = static_cast<uint32_t>(ports_.size());
  for (ActorId a = 0; a < n; ++a) {
    for (ChannelId c : adj.outputs(a)) ports_.push_back({c, g.channel(c).dst, g.channel(c).prd});
    out_off_[a + 1] = static_cast<uint32_t>(ports_.size());
  }
  for (ActorId a = 1; a < g.actor_count(); ++a)
    if (q_[a] < q_[reference_]) reference_ = a;
  for (uint64_t v : q_) sum_q_ = add_sat(sum_q_, v);
  for (uint64_t t : times_) all_untimed_ = all_untimed_ && t == 0;
}

void BoundedModel::spend(RunBudget& budget, uint64_t k) const {
  budget.firings = add_sat(budget.firings, k);
  if (budget.firings > budget.max_firings)
    throw LimitExceeded("buffers: one exploration of a storage distribution simulates more than " +
                        std::to_string(budget.max_firings) +
                        " firings (the limit of this analysis; an iteration is " +
                        std::to_string(sum_q_) + ")");
}

bool BoundedModel::live(std::span<const uint64_t> cap, RunBudget& budget,
                        std::vector<char>* dependency) const {
  const size_t n = g_.actor_count(), m = g_.channel_count();
  std::vector<uint64_t> tokens(m), space(m), fired(n, 0);
  for (ChannelId c = 0; c < m; ++c) {
    tokens[c] = g_.channel(c).delay;
    space[c] = cap[c] - tokens[c];
  }
  // Firings of a in a row now, at most `limit`. A self-loop (prd = cns in a consistent graph)
  // is in both lists and gets its tokens and places back after each firing.
  auto can_fire = [&](ActorId a, uint64_t limit) {
    uint64_t k = limit;
    for (const Port& p : inputs(a)) k = std::min(k, tokens[p.channel] / p.rate);
    for (const Port& p : outputs(a)) k = std::min(k, space[p.channel] / p.rate);
    return k;
  };
  // tokens + places = capacity on every channel between firings, so nothing overflows.
  auto fire = [&](ActorId a, uint64_t k) {
    for (const Port& p : inputs(a)) {
      tokens[p.channel] -= k * p.rate;
      space[p.channel] += k * p.rate;
    }
    for (const Port& p : outputs(a)) {
      space[p.channel] -= k * p.rate;
      tokens[p.channel] += k * p.rate;
    }
    fired[a] += k;
  };
  // The ready queue, each actor capped at q (then at nothing).
  auto run = [&](bool capped) {
    std::deque<ActorId> ready;
    std::vector<char> queued(n, 0);
    auto limit = [&](ActorId a) { return capped ? q_[a] - std::min(fired[a], q_[a]) : UINT64_MAX; };
    auto offer = [&](ActorId a) {
      if (!queued[a] && can_fire(a, std::min<uint64_t>(limit(a), 1)) > 0) {
        ready.push_back(a);
        queued[a] = 1;
      }
    };
    for (ActorId a = 0; a < n; ++a) offer(a);
    while (!ready.empty()) {
      const ActorId a = ready.front();
      ready.pop_front();
      queued[a] = 0;
      const uint64_t k = can_fire(a, limit(a));
      if (k == 0) continue;
      if (k == UINT64_MAX) throw std::logic_error("bounded execution: an actor without channels");
      spend(budget, k);
      fire(a, k);
      for (const Port& p : outputs(a)) offer(p.other);
      for (const Port& p : inputs(a)) offer(p.other);  // places freed
      offer(a);
    }
  };
  run(true);
  bool complete = true;
  for (ActorId a = 0; a < n; ++a) complete = complete && fired[a] == q_[a];
  if (complete) return true;
  if (dependency) {
    run(false);
    *dependency = standstill_dependencies(g_, tokens, space);
  }
  return false;
}

Throughput BoundedModel::run(std::span<const uint64_t> cap, RunBudget& budget,
                             std::vector<char>* dependency) const {
  const size_t n = g_.actor_count(), m = g_.channel_count();
  Throughput r;
  if (all_untimed_ || m == 0) {
    // Without time a live graph fires without bound at one instant.
    r.unbounded = live(cap, budget, dependency);
    if (r.unbounded) {
      r.num = r.den = 0;
      if (dependency) dependency->assign(m, 0);
    }
    return r;
  }
  std::vector<uint64_t> tokens(m), space(m);
  for (ChannelId c = 0; c < m; ++c) {
    tokens[c] = g_.channel(c).delay;
    space[c] = cap[c] - tokens[c];
  }
  // Firings in progress per actor: (end time, count), sorted by end time; one entry of `ends`
  // per (end time, actor), earliest first.
  std::vector<std::vector<std::pair<uint64_t, uint64_t>>> running(n);
  std::priority_queue<std::pair<uint64_t, ActorId>, std::vector<std::pair<uint64_t, ActorId>>,
                      std::greater<>>
      ends;
  uint64_t now = 0, busy = 0, done_ref = 0;
  bool track = false;
  // What arrived at the current instant (while tracking): tokens and places per channel.
  std::vector<uint64_t> got_tokens(m, 0), got_space(m, 0);
  std::vector<ChannelId> touched;
  Waits waits(m);

  // Actors that may be able to start: only a firing's end can enable one (a start takes tokens
  // and places that no other actor uses), so after the first instant only the neighbours of
  // the actors whose firings ended are looked at.
  std::vector<ActorId> todo;
  std::vector<char> queued(n, 0);
  auto offer = [&](ActorId a) {
    if (!queued[a]) queued[a] = 1, todo.push_back(a);
  };
  auto complete = [&](ActorId a, uint64_t k) {
    for (const Port& p : outputs(a)) {
      const uint64_t more = k * p.rate;  // ≤ the places claimed ≤ capacity
      tokens[p.channel] += more;
      if (track) got_tokens[p.channel] += more, touched.push_back(p.channel);
      offer(p.other);
    }
    for (const Port& p : inputs(a)) {
      const uint64_t more = k * p.rate;
      space[p.channel] += more;
      if (track) got_space[p.channel] += more, touched.push_back(p.channel);
      offer(p.other);
    }
    if (a == reference_) done_ref = add(done_ref, k, "the firings of the bounded exploration");
  };

  // Starts every firing that can start now; firings without time end at once. In a connected
  // bounded graph with some timed actor this ends (every count is tied to that actor's, which
  // starts finitely often per instant); were that wrong, the firing budget would still end it.
  auto start_all = [&] {
    while (!todo.empty()) {
      const ActorId a = todo.back();
      todo.pop_back();
      queued[a] = 0;
      // Most looks find some channel short (no division needed for that).
      bool blocked = false;
      for (const Port& p : inputs(a)) blocked = blocked || tokens[p.channel] < p.rate;
      for (const Port& p : outputs(a)) blocked = blocked || space[p.channel] < p.rate;
      if (blocked) continue;
      uint64_t k = UINT64_MAX;
      for (const Port& p : inputs(a)) k = std::min(k, tokens[p.channel] / p.rate);
      for (const Port& p : outputs(a)) k = std::min(k, space[p.channel] / p.rate);
      if (k == UINT64_MAX) throw std::logic_error("bounded execution: an actor without channels");
      if (track) {
        // The batch waited for a channel when the tokens (places) there before this instant's
        // arrivals would not have sufficed for all k firings.
        for (const Port& p : inputs(a))
          if (static_cast<u128>(tokens[p.channel]) <
              static_cast<u128>(got_tokens[p.channel]) + u128{k} * p.rate)
            waits.wait(a, p.other);
        for (const Port& p : outputs(a)) {
          if (static_cast<u128>(space[p.channel]) <
              static_cast<u128>(got_space[p.channel]) + u128{k} * p.rate) {
            waits.wait(a, p.other);
            waits.lack_places(p.channel);
          }
        }
      }
      spend(budget, k);
      for (const Port& p : inputs(a)) tokens[p.channel] -= k * p.rate;
      for (const Port& p : outputs(a)) space[p.channel] -= k * p.rate;
      if (times_[a] == 0) {
        complete(a, k);
      } else {
        // An actor's firings all take the same time: later starts end later.
        const uint64_t end = add(now, times_[a], "the time of the bounded exploration");
        auto& list = running[a];
        if (!list.empty() && list.back().first == end) {
          list.back().second += k;
        } else {
          list.push_back({end, k});
          ends.push({end, a});
        }
        busy += k;
      }
    }
  };

  auto encode = [&] {
    std::string key;
    key.reserve((m + n + 4 * n) * 8);
    auto put = [&](uint64_t v) { key.append(reinterpret_cast<const char*>(&v), sizeof v); };
    for (uint64_t t : tokens) put(t);
    for (const auto& list : running) {
      put(list.size());
      for (const auto& [end, k] : list) put(end - now), put(k);
    }
    return key;
  };

  std::unordered_map<std::string, std::pair<uint64_t, uint64_t>> seen;  // -> (time, done_ref)
  std::string period_key;
  uint64_t mark = q_[reference_];
  for (ActorId a = 0; a < n; ++a) offer(a);
  start_all();
  for (;;) {
    if (busy == 0) {  // a standstill: nothing runs and nothing can start
      r.num = 0;
      r.den = 1;
      if (dependency) *dependency = standstill_dependencies(g_, tokens, space);
      return r;
    }
    if (done_ref >= mark) {
      mark = add(done_ref / q_[reference_] * q_[reference_], q_[reference_],
                 "the firings of the bounded exploration");
      std::string key = encode();
      if (track) {
        if (key == period_key) {
          *dependency = waits.storage_dependencies(g_);
          return r;
        }
      } else {
        const auto [it, fresh] = seen.try_emplace(std::move(key), now, done_ref);
        if (!fresh) {
          const uint64_t firings = done_ref - it->second.second;
          const uint64_t time = now - it->second.first;
          if (time == 0) throw std::logic_error("bounded execution: a period without time");
          const uint64_t den = mul(q_[reference_], time, "the throughput's denominator");
          const uint64_t gcd = std::gcd(firings, den);
          r.num = firings / gcd;
          r.den = den / gcd;
          if (!dependency) return r;
          track = true;
          period_key = it->first;
          seen.clear();
        } else if (++budget.states > budget.max_states) {
          throw LimitExceeded(
              "buffers: one exploration of a storage distribution stores more than " +
              std::to_string(budget.max_states) + " states (the limit of this analysis)");
        }
        r.states = budget.states;
      }
    }
    // The next instant: the earliest end of a firing in progress.
    now = ends.top().first;
    if (track) {
      for (ChannelId c : touched) got_tokens[c] = got_space[c] = 0;
      touched.clear();
    }
    while (!ends.empty() && ends.top().first == now) {
      const ActorId a = ends.top().second;
      ends.pop();
      auto& list = running[a];
      const uint64_t k = list.front().second;
      list.erase(list.begin());
      busy -= k;
      complete(a, k);
    }
    start_all();
  }
}

}  // namespace sdf::detail
