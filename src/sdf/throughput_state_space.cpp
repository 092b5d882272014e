// Throughput by exploring the timed state space of self-timed execution (Ghamarian et al.,
// "Throughput analysis of synchronous data flow graphs", ACSD 2006), one strongly connected
// component at a time (channels from other components are ignored: the minimum over the
// components is the graph's throughput).
//
// A state, recorded at every instant once no more firings can start, is the tokens on the
// component's channels and, per actor, the remaining times of its firings in progress (as
// (remaining, count) pairs). Time advances to the next completion (the self-timed engine of
// self_timed.hpp, over the component). Within a component tokens
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
#include "self_timed.hpp"

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
      : g_(g),
        ports_(g, actors, local),
        times_(actors.size()),
        states_(states),
        max_states_(max_states) {
    for (size_t i = 0; i < actors.size(); ++i) times_[i] = times[actors[i]];
  }

  bool has_channels() const { return ports_.channels() != 0; }

  // Firings of actors_[0] and time between two visits of the first repeated state; time 0
  // never happens here (the caller handles all-zero-time components). firings == 0: deadlock.
  std::pair<uint64_t, uint64_t> explore() {
    struct Hooks {
      uint64_t fired = 0;   // firings of the reference actor (local 0) started
      uint64_t starts = 0;  // batches started at the current instant
      void instant() { starts = 0; }
      void started(uint32_t a, uint64_t k) {
        // Unreachable in a consistent strongly connected component with a timed actor (its
        // firings end later, and every other firing depends on them); kept as a guard.
        if (++starts > 100'000'000)
          throw Error(Error::Kind::input, "throughput: firings without execution time do not end");
        if (a == 0) fired = detail::add(fired, k, "the firings of the state-space exploration");
      }
      void completed(uint32_t, uint64_t) {}
    } hooks;
    detail::SelfTimed<Hooks> run(ports_, g_, times_, hooks,
                                 "the time of the state-space exploration");
    run.tokens.resize(ports_.channels());
    for (size_t i = 0; i < ports_.channels(); ++i)
      run.tokens[i] = g_.channel(ports_.global[i]).delay;
    std::unordered_map<std::string, std::pair<uint64_t, uint64_t>>
        seen;  // state -> (time, firings)
    run.offer_all();
    for (;;) {
      run.start_all();
      if (run.busy == 0) return {0, 1};  // deadlock
      const auto [it, fresh] = seen.try_emplace(run.encode(), run.now, hooks.fired);
      if (!fresh) return {hooks.fired - it->second.second, run.now - it->second.first};
      if (++states_ > max_states_)
        throw Error(Error::Kind::limit, "the state space of throughput has more than " +
                                            std::to_string(max_states_) +
                                            " states (the limit of this analysis)");
      run.advance();  // to the next completion
    }
  }

 private:
  const Graph& g_;
  const detail::TimedPorts ports_;  // the component's actors and the channels between them
  std::vector<uint64_t> times_;     // per local actor
  uint64_t& states_;
  uint64_t max_states_;
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
