// The storage-distribution searches of include/sdf/buffers.hpp (Stuijk, Geilen, Basten, DAC
// 2006). Distributions wait in a map from size to a set of distributions, so sizes are visited
// in increasing order and each distribution once. Visiting a size runs every distribution of it
// (bounded.hpp) and queues, for each channel with a storage dependency, the distribution with
// that channel one step (gcd(p, c)) larger.
//
// Why that finds every minimal distribution: capacities that differ by less than gcd(p, c) from
// a value ≡ d mod gcd(p, c) behave alike (tokens on the channel stay ≡ d, places ≡ cap − d), so
// a minimal distribution has every capacity ≡ d and at least the lower bound; the paper shows
// that a distribution whose dependency channels keep their capacities has the same throughput,
// so below any better distribution some dependency channel is at least one step smaller, and
// the search climbs to it. The tests compare both searches with enumeration of every
// distribution on small random graphs.
#include "sdf/buffers.hpp"

#include <map>
#include <numeric>
#include <set>

#include "bounded.hpp"
#include "checked.hpp"
#include "hsdf.hpp"
#include "sdf/schedule.hpp"

namespace sdf {

namespace {

using Distribution = std::vector<uint64_t>;

// q of a consistent, connected graph that does not deadlock with unbounded channels.
std::vector<uint64_t> checked_repetitions(const Graph& g) {
  std::vector<uint64_t> q = detail::repetitions_or_throw(g, "buffers");
  const Adjacency adj(g);
  const Components comp = connected_components(g, adj);
  if (comp.count > 1) {
    ActorId other = 0;
    while (comp.of_actor[other] == comp.of_actor[0]) ++other;
    throw Error(Error::Kind::input, "buffers needs a connected graph: actors '" + g.actor_name(0) +
                                        "' and '" + g.actor_name(other) +
                                        "' are not connected (analyse each component on its own)");
  }
  const StaticSchedule s = static_schedule(g, q);
  if (!s.complete) {
    std::string stuck;
    for (ActorId a : s.stuck) stuck += (stuck.empty() ? "'" : ", '") + g.actor_name(a) + "'";
    throw Error(Error::Kind::input,
                "buffers: the graph deadlocks whatever the capacities (stuck: " + stuck + ")");
  }
  return q;
}

uint64_t size_of(const Distribution& d) {
  uint64_t s = 0;
  for (uint64_t c : d) s = detail::add(s, c, "the size of a storage distribution");
  return s;
}

// Past t + p·⌊t / c⌋ places a self-loop's tokens, not its places, bound how many firings
// overlap, so larger capacities change nothing.
bool worth_enlarging(const Channel& ch, uint64_t capacity, uint64_t step) {
  if (ch.src != ch.dst) return true;
  const uint64_t useful = detail::add_sat(ch.delay, detail::mul_sat(ch.prd, ch.delay / ch.cns));
  return detail::add_sat(capacity, step) <= useful;
}

// -1, 0, 1 as a < b, a == b, a > b; unbounded is above every fraction.
int compare(const Throughput& a, const Throughput& b) {
  if (a.unbounded || b.unbounded) return a.unbounded == b.unbounded ? 0 : (a.unbounded ? 1 : -1);
  return detail::compare_fractions(a.num, a.den, b.num, b.den);
}

class Queue {
 public:
  Queue(const Graph& g, const BufferLimits& limits) : g_(g), limits_(limits) {}

  void push(Distribution d) {
    const uint64_t s = size_of(d);
    if (s <= limits_.max_size)
      pending_[s].insert(std::move(d));
    else
      beyond_max_size_ = true;
  }
  // Every channel with a dependency, one step larger.
  void enlarge(const Distribution& d, const std::vector<char>& dependency) {
    for (ChannelId c = 0; c < g_.channel_count(); ++c) {
      if (!dependency[c]) continue;
      const Channel& ch = g_.channel(c);
      const uint64_t step = std::gcd(ch.prd, ch.cns);
      if (!worth_enlarging(ch, d[c], step)) continue;
      Distribution e = d;
      e[c] = detail::add(e[c], step, "a channel capacity");
      push(std::move(e));
    }
  }
  bool empty() const { return pending_.empty(); }
  // The smallest size and its distributions, removed from the queue.
  std::pair<uint64_t, std::set<Distribution>> pop() {
    auto node = pending_.extract(pending_.begin());
    return {node.key(), std::move(node.mapped())};
  }
  bool beyond_max_size() const { return beyond_max_size_; }

 private:
  const Graph& g_;
  const BufferLimits& limits_;
  std::map<uint64_t, std::set<Distribution>> pending_;
  bool beyond_max_size_ = false;
};

detail::RunBudget run_budget(const BufferLimits& limits) {
  detail::RunBudget b;
  b.max_firings = limits.max_firings_per_run;
  b.max_states = limits.max_states_per_run;
  return b;
}

// The run of a live distribution simulates at least one iteration (live(): exactly one; run():
// a period, which is whole iterations), so a larger iteration can only fail, after long work.
void check_iteration(const detail::BoundedModel& model, const BufferLimits& limits) {
  if (model.iteration_firings() > limits.max_firings_per_run)
    throw detail::LimitExceeded(
        "buffers: an iteration is " + std::to_string(model.iteration_firings()) +
        " firings, more than the " + std::to_string(limits.max_firings_per_run) +
        " one exploration may simulate (the limit of this analysis)");
}

// Counts one run against the limits of the whole search.
template <class Search>
void count_run(Search& r, const detail::RunBudget& used, const BufferLimits& limits) {
  ++r.explored;
  r.states = detail::add_sat(r.states, used.states);
  r.firings = detail::add_sat(r.firings, used.firings);
  if (r.explored > limits.max_distributions)
    throw detail::LimitExceeded("buffers: more than " + std::to_string(limits.max_distributions) +
                                " storage distributions explored (the limit)");
  if (r.states > limits.max_states)
    throw detail::LimitExceeded("buffers: more than " + std::to_string(limits.max_states) +
                                " states stored over all explorations (the limit)");
}

}  // namespace

std::vector<uint64_t> buffer_lower_bounds(const Graph& g) {
  std::vector<uint64_t> lb(g.channel_count());
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    const uint64_t gcd = std::gcd(ch.prd, ch.cns);
    const char* what = "the lower bound of a channel's capacity";
    if (ch.src == ch.dst) {
      lb[c] = detail::add(ch.prd, std::max(ch.cns, ch.delay), what);
    } else {
      // p + c − gcd ≥ max(p, c) > 0, so the subtraction cannot wrap.
      const uint64_t base = detail::add(ch.prd, ch.cns, what) - gcd;
      lb[c] = std::max(detail::add(base, ch.delay % gcd, what), ch.delay);
    }
  }
  return lb;
}

Graph bounded_graph(const Graph& g, std::span<const uint64_t> capacity) {
  if (capacity.size() != g.channel_count())
    throw Error(Error::Kind::input, "bounded_graph: " + std::to_string(capacity.size()) +
                                        " capacities for " + std::to_string(g.channel_count()) +
                                        " channels");
  Graph b;
  b.name = g.name;
  b.type = g.type;
  b.sdf3_properties = g.sdf3_properties;
  b.reserve(g.actor_count(), 2 * g.channel_count());
  for (ActorId a = 0; a < g.actor_count(); ++a) {
    b.add_actor(g.actor_name(a));
    if (!g.actor_type(a).empty()) b.set_actor_type(a, g.actor_type(a));
    b.set_actor_time(a, g.actor_time(a));
  }
  for (ChannelId id = 0; id < g.channel_count(); ++id) {
    const Channel& ch = g.channel(id);
    const ChannelId c =
        b.add_channel(ch.src, ch.dst, ch.prd, ch.cns, ch.delay, std::string(g.channel_name(id)));
    b.set_port_names(c, g.src_port(id), g.dst_port(id));
  }
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    if (capacity[c] < ch.delay)
      throw Error(Error::Kind::input, "channel '" + std::string(g.channel_name(c)) +
                                          "': capacity " + std::to_string(capacity[c]) +
                                          " is below its " + std::to_string(ch.delay) +
                                          " initial tokens");
    b.add_channel(ch.dst, ch.src, ch.cns, ch.prd, capacity[c] - ch.delay,
                  std::string(g.channel_name(c)) + "#space");
  }
  return b;
}

StorageSearch minimal_storage(const Graph& g, const BufferLimits& limits) {
  const std::vector<uint64_t> q = checked_repetitions(g);
  const detail::BoundedModel model(g, q, {});
  check_iteration(model, limits);
  Queue queue(g, limits);
  queue.push(buffer_lower_bounds(g));
  StorageSearch r;
  std::vector<char> dep;
  while (!queue.empty()) {
    auto [size, set] = queue.pop();
    for (const Distribution& d : set) {
      detail::RunBudget budget = run_budget(limits);
      const bool live = model.live(d, budget, &dep);
      count_run(r, budget, limits);
      if (live)
        r.distributions.push_back(d);
      else
        queue.enlarge(d, dep);
    }
    if (!r.distributions.empty()) {
      r.size = size;
      return r;  // a std::set iterates in order: already sorted
    }
  }
  // A live graph has a deadlock-free distribution, so only max_size can have hidden it; anything
  // else is a mistake here, said plainly rather than answered wrongly.
  if (queue.beyond_max_size())
    throw detail::LimitExceeded("buffers: no deadlock-free distribution of size at most " +
                                std::to_string(limits.max_size) + " (the size limit)");
  throw std::logic_error("buffers: no deadlock-free distribution found");
}

ParetoSearch storage_throughput_pareto(const Graph& g, std::optional<uint64_t> default_time,
                                       const BufferLimits& limits) {
  const std::vector<uint64_t> q = checked_repetitions(g);
  ParetoSearch r;
  r.max_throughput = throughput_state_space(g, default_time);
  const detail::BoundedModel model(g, q, execution_times(g, default_time));
  Queue queue(g, limits);
  queue.push(buffer_lower_bounds(g));
  Throughput best;  // 0
  std::vector<char> dep;
  try {
    check_iteration(model, limits);
    while (!queue.empty()) {
      auto [size, set] = queue.pop();
      std::vector<std::pair<const Distribution*, Throughput>> results;
      Throughput top;
      for (const Distribution& d : set) {
        detail::RunBudget budget = run_budget(limits);
        const Throughput t = model.run(d, budget, &dep);
        count_run(r, budget, limits);
        results.push_back({&d, t});
        if (compare(t, top) > 0) top = t;
        queue.enlarge(d, dep);
      }
      if (compare(top, best) <= 0) continue;
      ParetoPoint p;
      p.size = size;
      p.throughput = top;
      p.throughput.states = 0;
      for (const auto& [d, t] : results)
        if (compare(t, top) == 0) p.distributions.push_back(*d);
      r.points.push_back(std::move(p));
      best = top;
      if (compare(best, r.max_throughput) >= 0) {
        r.complete = true;
        return r;
      }
    }
    r.stopped = queue.beyond_max_size()
                    ? "no distribution of size at most " + std::to_string(limits.max_size) +
                          " reaches the throughput with unbounded channels"
                    : "no channel left to enlarge (the dependency analysis found none)";
  } catch (const detail::LimitExceeded& e) {
    r.stopped = e.what();  // with the points so far, perhaps none
  }
  return r;
}

Throughput bounded_throughput(const Graph& g, std::span<const uint64_t> capacity,
                              std::optional<uint64_t> default_time, const BufferLimits& limits) {
  const std::vector<uint64_t> q = checked_repetitions(g);
  if (capacity.size() != g.channel_count())
    throw Error(Error::Kind::input, "bounded_throughput: wrong number of capacities");
  for (ChannelId c = 0; c < g.channel_count(); ++c)
    if (capacity[c] < g.channel(c).delay)
      throw Error(Error::Kind::input, "channel '" + std::string(g.channel_name(c)) +
                                          "': capacity " + std::to_string(capacity[c]) +
                                          " is below its " + std::to_string(g.channel(c).delay) +
                                          " initial tokens");
  const detail::BoundedModel model(g, q, execution_times(g, default_time));
  check_iteration(model, limits);
  detail::RunBudget budget = run_budget(limits);
  return model.run(capacity, budget);
}

std::vector<Run> min_buffer_schedule(const Graph& g, std::vector<uint64_t>* capacity,
                                     const BufferLimits& limits) {
  const StorageSearch s = minimal_storage(g, limits);
  const Distribution& d = s.distributions.front();
  const std::vector<uint64_t> q = detail::repetitions_or_throw(g, "buffers");
  StaticSchedule st = static_schedule(bounded_graph(g, d), q);
  if (!st.complete) throw std::logic_error("buffers: a deadlock-free distribution deadlocked");
  if (capacity) *capacity = d;
  return std::move(st.runs);
}

}  // namespace sdf
