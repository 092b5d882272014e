// Latency over the first K iterations by an event simulation of self-timed execution in which
// each actor fires at most K·q[a] times (include/sdf/latency.hpp): the shared engine
// (self_timed.hpp) with a limit per actor, recording per actor and iteration the first start
// and the last end.
#include "sdf/latency.hpp"

#include <algorithm>

#include "checked.hpp"
#include "hsdf.hpp"
#include "sdf/throughput.hpp"
#include "self_timed.hpp"

namespace sdf {

namespace {

// L_i from the first starts and last ends per actor and iteration (index a·K + i).
void latencies_from_times(const LatencyOptions& o, size_t actors,
                          const std::vector<uint64_t>& first_start,
                          const std::vector<uint64_t>& last_end, Latency& r) {
  const uint64_t k = o.iterations;
  __extension__ using i128 = __int128;
  r.per_iteration.assign(k, 0);
  for (uint64_t i = 0; i < k; ++i) {
    i128 from = 0, to = 0;
    if (o.from) {
      from = first_start[*o.from * k + i];
      to = last_end[*o.to * k + i];
    } else {
      from = first_start[i];
      to = last_end[i];
      for (size_t a = 1; a < actors; ++a) {
        from = std::min<i128>(from, first_start[a * k + i]);
        to = std::max<i128>(to, last_end[a * k + i]);
      }
    }
    const i128 l = to - from;
    if (l > INT64_MAX || l < INT64_MIN) detail::overflow("a latency");
    r.per_iteration[i] = static_cast<int64_t>(l);
    if (i == 0 || r.per_iteration[i] > r.max) r.max = r.per_iteration[i], r.iteration = i;
  }
  for (size_t a = 0; a < actors; ++a) r.makespan = std::max(r.makespan, last_end[a * k + k - 1]);
}

// The checks of the options, and K·q[a] per actor: the firings to simulate.
std::vector<uint64_t> latency_caps(const Graph& g, const LatencyOptions& o,
                                   const std::vector<uint64_t>& q) {
  if (o.from.has_value() != o.to.has_value())
    throw Error(Error::Kind::input, "latency: give both the source and the destination actor");
  if (o.iterations == 0) throw Error(Error::Kind::input, "latency: at least one iteration");
  if (g.actor_count() == 0)
    throw Error(Error::Kind::input, "latency: the graph has no actors (no iteration to measure)");
  std::vector<uint64_t> cap(g.actor_count());
  uint64_t total = 0;
  for (ActorId a = 0; a < g.actor_count(); ++a) {
    cap[a] = detail::mul_sat(q[a], o.iterations);
    total = detail::add_sat(total, cap[a]);
  }
  if (total > o.max_firings)
    throw Error(Error::Kind::limit,
                "latency: " + std::to_string(o.iterations) + " iterations take more than " +
                    std::to_string(o.max_firings) + " firings (the limit of this analysis)");
  return cap;
}

}  // namespace

Latency latency(const Graph& g, const LatencyOptions& o, std::optional<uint64_t> default_time) {
  const std::vector<uint64_t> q = detail::repetitions_or_throw(g, "latency");
  const std::vector<uint64_t> cap = latency_caps(g, o, q);
  const std::vector<uint64_t> times = execution_times(g, default_time);
  const size_t n = g.actor_count(), k_iter = o.iterations;
  const detail::TimedPorts ports(g);
  // The first starts and last ends per actor and iteration (index a·K + i).
  struct Hooks {
    Hooks(const std::vector<uint64_t>& reps, size_t n, size_t iterations)
        : q(reps),
          k_iter(iterations),
          begun(n, 0),
          done(n, 0),
          first_start(n * iterations, 0),
          last_end(n * iterations, 0) {}
    const std::vector<uint64_t>& q;
    const size_t k_iter;
    const uint64_t* now = nullptr;
    std::vector<uint64_t> begun, done, first_start, last_end;  // firings started, ended per actor
    void instant() {}
    void started(uint32_t a, uint64_t k) {
      // Iterations whose first firing is among these k.
      for (uint64_t i = (begun[a] + q[a] - 1) / q[a]; i * q[a] < begun[a] + k; ++i)
        first_start[a * k_iter + i] = *now;
      begun[a] += k;
    }
    void completed(uint32_t a, uint64_t k) {
      // Iterations whose last firing is among these k.
      for (uint64_t i = done[a] / q[a]; (i + 1) * q[a] <= done[a] + k; ++i)
        last_end[a * k_iter + i] = *now;
      done[a] += k;
    }
  } hooks(q, n, k_iter);
  detail::SelfTimed<Hooks> run(ports, g, times, hooks, "the time of the latency simulation");
  hooks.now = &run.now;
  run.tokens = g.delays();
  run.left = cap;  // each actor fires at most K·q[a] times
  run.offer_all();
  do run.start_all();
  while (run.advance());
  Latency r;
  for (ActorId a = 0; a < n; ++a)
    if (hooks.done[a] < cap[a]) r.stuck.push_back(a);
  r.deadlock = !r.stuck.empty();
  if (!r.deadlock) latencies_from_times(o, n, hooks.first_start, hooks.last_end, r);
  return r;
}

}  // namespace sdf
