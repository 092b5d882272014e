// Latency over the first K iterations by an event simulation of self-timed execution in which
// each actor fires at most K·q[a] times (include/sdf/latency.hpp). Firings of one actor take the
// same time and start in order, so they also end in order: per actor a list of (end, count)
// batches, and a heap of (end, actor) with one entry per batch. Only a firing's end can enable
// another firing, so after time 0 only the consumers of the actors whose firings ended are
// looked at.
#include "sdf/latency.hpp"

#include <algorithm>
#include <deque>
#include <queue>

#include "checked.hpp"
#include "hsdf.hpp"
#include "sdf/throughput.hpp"

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
  const Adjacency adj(g);
  std::vector<uint64_t> tokens = g.delays(), started(n, 0), ended(n, 0);
  std::vector<uint64_t> first_start(n * k_iter, 0), last_end(n * k_iter, 0);
  std::vector<std::deque<std::pair<uint64_t, uint64_t>>> running(n);  // (end, count)
  std::priority_queue<std::pair<uint64_t, ActorId>, std::vector<std::pair<uint64_t, ActorId>>,
                      std::greater<>>
      ends;
  std::vector<ActorId> todo;
  std::vector<char> queued(n, 0);
  uint64_t now = 0;
  auto offer = [&](ActorId a) {
    if (!queued[a]) queued[a] = 1, todo.push_back(a);
  };
  auto complete = [&](ActorId a, uint64_t k) {
    for (ChannelId c : adj.outputs(a)) {
      const Channel& ch = g.channel(c);
      tokens[c] = detail::add_tokens(tokens[c], k, ch.prd, g, c);
      offer(ch.dst);
    }
    // Iterations whose last firing is among these k.
    for (uint64_t i = ended[a] / q[a]; (i + 1) * q[a] <= ended[a] + k; ++i)
      last_end[a * k_iter + i] = now;
    ended[a] += k;
  };
  for (ActorId a = 0; a < n; ++a) offer(a);
  for (;;) {
    while (!todo.empty()) {
      const ActorId a = todo.back();
      todo.pop_back();
      queued[a] = 0;
      uint64_t k = cap[a] - started[a];
      for (ChannelId c : adj.inputs(a)) k = std::min(k, tokens[c] / g.channel(c).cns);
      if (k == 0) continue;
      for (ChannelId c : adj.inputs(a)) tokens[c] -= k * g.channel(c).cns;
      // Iterations whose first firing is among these k.
      for (uint64_t i = (started[a] + q[a] - 1) / q[a]; i * q[a] < started[a] + k; ++i)
        first_start[a * k_iter + i] = now;
      started[a] += k;
      if (times[a] == 0) {
        complete(a, k);
        continue;
      }
      const uint64_t end = detail::add(now, times[a], "the time of the latency simulation");
      auto& list = running[a];
      if (!list.empty() && list.back().first == end) {
        list.back().second += k;
      } else {
        list.push_back({end, k});
        ends.push({end, a});
      }
    }
    if (ends.empty()) break;
    now = ends.top().first;
    while (!ends.empty() && ends.top().first == now) {
      const ActorId a = ends.top().second;
      ends.pop();
      const uint64_t k = running[a].front().second;
      running[a].pop_front();
      complete(a, k);
    }
  }
  Latency r;
  for (ActorId a = 0; a < n; ++a)
    if (ended[a] < cap[a]) r.stuck.push_back(a);
  r.deadlock = !r.stuck.empty();
  if (!r.deadlock) latencies_from_times(o, n, first_start, last_end, r);
  return r;
}

}  // namespace sdf
