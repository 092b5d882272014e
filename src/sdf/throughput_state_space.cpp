// Throughput by exploring the timed state space of self-timed execution (Ghamarian et al.,
// "Throughput analysis of synchronous data flow graphs", ACSD 2006), one strongly connected
// component at a time (channels from other components are ignored: the minimum over the
// components is the graph's throughput).
//
// A state, recorded at every instant once no more firings can start, is the tokens on the
// component's channels and, per actor, the remaining times of its firings in progress (as
// (remaining, count) pairs). Time advances to the next completion. Within a component tokens
// are bounded, so some state repeats; between its two visits lie F firings of a reference
// actor r in T time units, and the throughput is F / (q[r]·T) iterations per time unit.
// A state with nothing in progress and nothing enabled is a deadlock (throughput 0). A
// component whose actors all take no time is unbounded when it does not deadlock (decided by
// the same exploration with every time set to 1).
#include <algorithm>
#include <numeric>
#include <string>
#include <unordered_map>

#include "checked.hpp"
#include "hsdf.hpp"
#include "scc.hpp"
#include "sdf/throughput.hpp"

namespace sdf {

namespace {

struct Fraction {
  bool unbounded = false;
  uint64_t num = 0, den = 1;
};

class Component {
 public:
  Component(const Graph& g, const std::vector<ActorId>& actors, const std::vector<uint32_t>& local,
            const std::vector<uint64_t>& times, uint64_t& states, uint64_t max_states)
      : g_(g), actors_(actors), times_(times), states_(states), max_states_(max_states) {
    in_.resize(actors.size());
    out_.resize(actors.size());
    for (ChannelId c = 0; c < g.channel_count(); ++c) {
      const Channel& ch = g.channel(c);
      const uint32_t s = local[ch.src], d = local[ch.dst];
      if (s == UINT32_MAX || d == UINT32_MAX) continue;
      const auto id = static_cast<uint32_t>(channels_.size());
      channels_.push_back(c);
      out_[s].push_back(id);
      in_[d].push_back(id);
    }
  }

  bool has_channels() const { return !channels_.empty(); }

  // Firings of actors_[0] and time between two visits of the first repeated state; time 0
  // never happens here (the caller handles all-zero-time components). firings == 0: deadlock.
  std::pair<uint64_t, uint64_t> explore() {
    const size_t na = actors_.size();
    tokens_.resize(channels_.size());
    for (size_t i = 0; i < channels_.size(); ++i) tokens_[i] = g_.channel(channels_[i]).delay;
    running_.assign(na, {});
    std::unordered_map<std::string, std::pair<uint64_t, uint64_t>>
        seen;  // state -> (time, firings)
    uint64_t now = 0, fired = 0;
    for (;;) {
      start_all(fired);
      bool busy = false;
      for (const auto& r : running_) busy = busy || !r.empty();
      if (!busy) return {0, 1};  // deadlock
      std::string key = encode();
      const auto [it, fresh] = seen.try_emplace(std::move(key), now, fired);
      if (!fresh) return {fired - it->second.second, now - it->second.first};
      if (++states_ > max_states_)
        throw Error(Error::Kind::limit, "the state space of throughput has more than " +
                                            std::to_string(max_states_) +
                                            " states (the limit of this analysis)");
      // Advance to the next completion.
      uint64_t dt = UINT64_MAX;
      for (const auto& r : running_)
        if (!r.empty()) dt = std::min(dt, r.front().first);
      now = detail::add(now, dt, "the time of the state-space exploration");
      for (size_t a = 0; a < na; ++a) {
        auto& r = running_[a];
        for (auto& [rem, n] : r) rem -= dt;
        while (!r.empty() && r.front().first == 0) {
          produce(a, r.front().second);
          r.erase(r.begin());
        }
      }
    }
  }

 private:
  void produce(size_t a, uint64_t n) {
    for (uint32_t c : out_[a]) {
      const Channel& ch = g_.channel(channels_[c]);
      tokens_[c] = detail::add_tokens(tokens_[c], n, ch.prd, g_, channels_[c]);
    }
  }

  // Starts every enabled firing; firings without execution time end at once and may enable
  // more.
  void start_all(uint64_t& fired) {
    bool progress = true;
    uint64_t rounds = 0;
    while (progress) {
      progress = false;
      for (size_t a = 0; a < actors_.size(); ++a) {
        uint64_t n = UINT64_MAX;
        for (uint32_t c : in_[a]) n = std::min(n, tokens_[c] / g_.channel(channels_[c]).cns);
        if (n == 0 || n == UINT64_MAX) continue;
        for (uint32_t c : in_[a]) tokens_[c] -= n * g_.channel(channels_[c]).cns;
        if (a == 0) fired = detail::add(fired, n, "the firings of the state-space exploration");
        const uint64_t t = times_[actors_[a]];
        if (t == 0) {
          produce(a, n);
        } else {
          auto& r = running_[a];
          // All started now end together: merge with an entry of the same remaining time.
          auto it = std::lower_bound(r.begin(), r.end(), t,
                                     [](const auto& e, uint64_t v) { return e.first < v; });
          if (it != r.end() && it->first == t)
            it->second += n;
          else
            r.insert(it, {t, n});
        }
        progress = true;
      }
      if (++rounds > 100'000'000)
        throw Error(Error::Kind::input, "throughput: firings without execution time do not end");
    }
  }

  std::string encode() const {
    std::string k;
    auto put = [&](uint64_t v) { k.append(reinterpret_cast<const char*>(&v), sizeof v); };
    for (uint64_t t : tokens_) put(t);
    for (const auto& r : running_) {
      put(r.size());
      for (const auto& [rem, n] : r) put(rem), put(n);
    }
    return k;
  }

  const Graph& g_;
  const std::vector<ActorId>& actors_;
  const std::vector<uint64_t>& times_;
  uint64_t& states_;
  uint64_t max_states_;
  std::vector<ChannelId> channels_;
  std::vector<std::vector<uint32_t>> in_, out_;
  std::vector<uint64_t> tokens_;
  std::vector<std::vector<std::pair<uint64_t, uint64_t>>> running_;  // sorted by remaining time
};

}  // namespace

Throughput throughput_state_space(const Graph& g, std::optional<uint64_t> default_time,
                                  const ThroughputLimits& limits) {
  const std::vector<uint64_t> q = detail::repetitions_or_throw(g, "throughput");
  const std::vector<uint64_t> times = execution_times(g, default_time);
  const auto n = static_cast<uint32_t>(g.actor_count());
  const Adjacency adj(g);
  std::vector<uint32_t> off(n + 1, 0), succ;
  succ.reserve(g.channel_count());
  for (ActorId a = 0; a < n; ++a) {
    for (ChannelId c : adj.outputs(a)) succ.push_back(g.channel(c).dst);
    off[a + 1] = static_cast<uint32_t>(succ.size());
  }
  uint32_t count = 0;
  const std::vector<uint32_t> comp = detail::strong_components(n, off, succ, count);
  std::vector<std::vector<ActorId>> members(count);
  for (ActorId a = 0; a < n; ++a) members[comp[a]].push_back(a);

  Throughput r;
  r.unbounded = true;
  std::vector<uint32_t> local(n, UINT32_MAX);
  const std::vector<uint64_t> ones(n, 1);
  for (uint32_t c = 0; c < count; ++c) {
    const std::vector<ActorId>& actors = members[c];
    for (size_t i = 0; i < actors.size(); ++i) local[actors[i]] = static_cast<uint32_t>(i);
    bool timed = false;
    for (ActorId a : actors) timed = timed || times[a] != 0;
    Component sc(g, actors, local, timed ? times : ones, r.states, limits.max_states);
    for (ActorId a : actors) local[a] = UINT32_MAX;
    if (!sc.has_channels()) continue;  // no cycle: no constraint
    const auto [firings, time] = sc.explore();
    Fraction f;
    if (firings == 0) {
      f = {false, 0, 1};
    } else if (!timed) {
      continue;  // live and without time: no constraint
    } else {
      const uint64_t den = detail::mul(q[actors[0]], time, "the throughput's denominator");
      const uint64_t gcd = std::gcd(firings, den);
      f = {false, firings / gcd, den / gcd};
    }
    if (r.unbounded || detail::compare_fractions(f.num, f.den, r.num, r.den) < 0)
      r.unbounded = false, r.num = f.num, r.den = f.den;
    if (r.num == 0) break;
  }
  if (r.unbounded) r.num = r.den = 0;
  return r;
}

}  // namespace sdf
