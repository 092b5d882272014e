#include "bounded.hpp"

#include <algorithm>
#include <deque>
#include <numeric>
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
    : g_(g), ports_(g), q_(std::move(q)), times_(std::move(times)) {
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
  const size_t m = g_.channel_count();
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
  // What arrived at the current instant (while tracking): tokens and places per channel; who
  // waited for whom; the reference actor's completed firings.
  struct Hooks {
    const BoundedModel& model;
    RunBudget& budget;
    const std::vector<uint64_t>* tokens = nullptr;  // the engine's
    const std::vector<uint64_t>* space = nullptr;
    bool track = false;
    uint64_t done_ref = 0;
    std::vector<uint64_t> got_tokens, got_space;
    std::vector<ChannelId> touched;
    Waits waits;
    void instant() {
      if (!track) return;
      for (ChannelId c : touched) got_tokens[c] = got_space[c] = 0;
      touched.clear();
    }
    void started(ActorId a, uint64_t k) {
      if (track) {
        // The batch waited for a channel when the tokens (places) there before this instant's
        // arrivals would not have sufficed for all k firings.
        for (const Port& p : model.inputs(a))
          if (static_cast<u128>((*tokens)[p.channel]) <
              static_cast<u128>(got_tokens[p.channel]) + u128{k} * p.rate)
            waits.wait(a, p.other);
        for (const Port& p : model.outputs(a)) {
          if (static_cast<u128>((*space)[p.channel]) <
              static_cast<u128>(got_space[p.channel]) + u128{k} * p.rate) {
            waits.wait(a, p.other);
            waits.lack_places(p.channel);
          }
        }
      }
      model.spend(budget, k);
    }
    void completed(ActorId a, uint64_t k) {
      if (track) {
        for (const Port& p : model.outputs(a)) {
          got_tokens[p.channel] += k * p.rate;
          touched.push_back(p.channel);
        }
        for (const Port& p : model.inputs(a)) {
          got_space[p.channel] += k * p.rate;
          touched.push_back(p.channel);
        }
      }
      if (a == model.reference_)
        done_ref = add(done_ref, k, "the firings of the bounded exploration");
    }
  };
  Hooks hooks{*this,
              budget,
              nullptr,
              nullptr,
              false,
              0,
              std::vector<uint64_t>(m, 0),
              std::vector<uint64_t>(m, 0),
              {},
              Waits(m)};
  // In a connected bounded graph with some timed actor every instant ends (every count is tied
  // to that actor's, which starts finitely often per instant); were that wrong, the firing
  // budget would still end it.
  SelfTimed<Hooks> run(ports_, g_, times_, hooks, "the time of the bounded exploration");
  run.tokens.resize(m);
  run.space.resize(m);
  for (ChannelId c = 0; c < m; ++c) {
    run.tokens[c] = g_.channel(c).delay;
    run.space[c] = cap[c] - run.tokens[c];
  }
  hooks.tokens = &run.tokens;
  hooks.space = &run.space;

  std::unordered_map<std::string, std::pair<uint64_t, uint64_t>> seen;  // -> (time, done_ref)
  std::string period_key;
  uint64_t mark = q_[reference_];
  run.offer_all();
  run.start_all();
  for (;;) {
    if (run.busy == 0) {  // a standstill: nothing runs and nothing can start
      r.num = 0;
      r.den = 1;
      if (dependency) *dependency = standstill_dependencies(g_, run.tokens, run.space);
      return r;
    }
    if (hooks.done_ref >= mark) {
      mark = add(hooks.done_ref / q_[reference_] * q_[reference_], q_[reference_],
                 "the firings of the bounded exploration");
      std::string key = run.encode();
      if (hooks.track) {
        if (key == period_key) {
          *dependency = hooks.waits.storage_dependencies(g_);
          return r;
        }
      } else {
        const auto [it, fresh] = seen.try_emplace(std::move(key), run.now, hooks.done_ref);
        if (!fresh) {
          const uint64_t firings = hooks.done_ref - it->second.second;
          const uint64_t time = run.now - it->second.first;
          if (time == 0) throw std::logic_error("bounded execution: a period without time");
          const uint64_t den = mul(q_[reference_], time, "the throughput's denominator");
          const uint64_t gcd = std::gcd(firings, den);
          r.num = firings / gcd;
          r.den = den / gcd;
          if (!dependency) return r;
          hooks.track = true;
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
    run.advance();
    run.start_all();
  }
}

}  // namespace sdf::detail
