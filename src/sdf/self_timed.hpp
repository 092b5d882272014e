// Self-timed execution, the event loop shared by latency, the bounded model's run and the
// throughput state space: at each instant every actor starts as many firings as its input
// tokens allow (and, with capacities, the free places on its outputs; and, with a limit, the
// firings it may still start); firings without execution time end at once and may enable more;
// time then advances to the earliest end of a firing in progress. The firings of one actor all
// take the same time, so they end in the order they started: per actor a queue of (end, count)
// batches, and a heap with one (end, actor) entry per batch. Only a firing's end can enable
// another firing (a start takes tokens and places that no other actor uses), so after the first
// instant only the neighbours of the actors whose firings ended are looked at. What is started
// at one instant does not depend on the order the actors are looked at (firing as much as
// possible reaches the same state), which is why the three analyses could share this loop.
//
// The analyses record what they need through hooks (static, so the calls inline):
//   void instant()                         time has advanced to `now`, before any completion
//   void started(uint32_t a, uint64_t k)   k firings of a start, before they take their tokens
//                                          and places
//   void completed(uint32_t a, uint64_t k) k firings of a have delivered their tokens and places
//
// Thread-safety: TimedPorts is immutable; a SelfTimed run is single-threaded state.
#pragma once

#include <cstdint>
#include <functional>
#include <queue>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "checked.hpp"
#include "sdf/graph.hpp"

namespace sdf::detail {

// The topology the engine runs on, built once: per actor its input ports, then per actor its
// output ports, each in channel order with the rate inline (one contiguous block per actor).
// Actors and channels are numbered locally; a self-loop is in both lists.
struct TimedPorts {
  struct Port {
    uint32_t channel;  // local
    uint32_t other;    // local actor: the producer of an input, the consumer of an output
    uint64_t rate;     // cns of an input, prd of an output
  };
  std::vector<Port> ports;
  std::vector<uint32_t> in_off, out_off;
  std::vector<ChannelId> global;  // local channel -> the graph's (overflow messages)

  // The whole graph (local numbers are the graph's).
  explicit TimedPorts(const Graph& g);
  // The actors `actors` (local[a]: a's index among them, UINT32_MAX for every other actor) and
  // the channels between them, numbered in channel order.
  TimedPorts(const Graph& g, std::span<const ActorId> actors, std::span<const uint32_t> local);

  size_t actors() const { return in_off.size() - 1; }
  size_t channels() const { return global.size(); }
  std::span<const Port> inputs(uint32_t a) const {
    return {ports.data() + in_off[a], ports.data() + in_off[a + 1]};
  }
  std::span<const Port> outputs(uint32_t a) const {
    return {ports.data() + out_off[a], ports.data() + out_off[a + 1]};
  }
};

template <class Hooks>
class SelfTimed {
 public:
  // times: per local actor. what_time names the clock in an overflow message.
  SelfTimed(const TimedPorts& t, const Graph& g, std::span<const uint64_t> times, Hooks& hooks,
            const char* what_time)
      : t_(t),
        g_(g),
        times_(times),
        hooks_(hooks),
        what_time_(what_time),
        queued_(t.actors(), 0),
        running_(t.actors()),
        head_(t.actors(), 0) {}

  std::vector<uint64_t> tokens;  // per local channel
  std::vector<uint64_t> space;   // free places per channel; empty: channels without capacity
  std::vector<uint64_t> left;    // firings each actor may still start; empty: no limit
  uint64_t now = 0;
  uint64_t busy = 0;  // firings in progress (those without time never are)

  void offer(uint32_t a) {
    if (!queued_[a]) queued_[a] = 1, todo_.push_back(a);
  }
  void offer_all() {
    for (uint32_t a = 0; a < t_.actors(); ++a) offer(a);
  }

  // Starts every firing that can start now (of the actors offered, and of those their firings
  // without time enable).
  void start_all() {
    while (!todo_.empty()) {
      const uint32_t a = todo_.back();
      todo_.pop_back();
      queued_[a] = 0;
      uint64_t k = left.empty() ? UINT64_MAX : left[a];
      if (k == 0) continue;
      // Most looks find some channel short (no division needed for that).
      bool blocked = false;
      for (const auto& p : t_.inputs(a)) blocked = blocked || tokens[p.channel] < p.rate;
      if (!space.empty())
        for (const auto& p : t_.outputs(a)) blocked = blocked || space[p.channel] < p.rate;
      if (blocked) continue;
      for (const auto& p : t_.inputs(a)) k = std::min(k, tokens[p.channel] / p.rate);
      if (!space.empty())
        for (const auto& p : t_.outputs(a)) k = std::min(k, space[p.channel] / p.rate);
      if (k == UINT64_MAX) continue;  // nothing limits it: not in the analyses' graphs
      hooks_.started(a, k);
      for (const auto& p : t_.inputs(a)) tokens[p.channel] -= k * p.rate;
      if (!space.empty())
        for (const auto& p : t_.outputs(a)) space[p.channel] -= k * p.rate;
      if (!left.empty()) left[a] -= k;
      if (times_[a] == 0) {
        complete(a, k);
        continue;
      }
      const uint64_t end = add(now, times_[a], what_time_);
      auto& list = running_[a];
      if (list.size() > head_[a] && list.back().first == end) {
        list.back().second += k;
      } else {
        list.push_back({end, k});
        ends_.push({end, a});
      }
      busy += k;
    }
  }

  // Advances to the earliest end of a firing in progress and completes every firing that ends
  // then; false (and nothing changes) when none is in progress.
  bool advance() {
    if (ends_.empty()) return false;
    now = ends_.top().first;
    hooks_.instant();
    while (!ends_.empty() && ends_.top().first == now) {
      const uint32_t a = ends_.top().second;
      ends_.pop();
      auto& list = running_[a];
      const uint64_t k = list[head_[a]].second;
      if (++head_[a] == list.size()) list.clear(), head_[a] = 0;
      busy -= k;
      complete(a, k);
    }
    return true;
  }

  // The state: the tokens, then per actor its batches in progress as (time left, count).
  std::string encode() const {
    std::string key;
    key.reserve((tokens.size() + 3 * t_.actors()) * 8);
    auto put = [&](uint64_t v) { key.append(reinterpret_cast<const char*>(&v), sizeof v); };
    for (uint64_t v : tokens) put(v);
    for (uint32_t a = 0; a < t_.actors(); ++a) {
      put(running_[a].size() - head_[a]);
      for (size_t i = head_[a]; i < running_[a].size(); ++i)
        put(running_[a][i].first - now), put(running_[a][i].second);
    }
    return key;
  }

 private:
  void complete(uint32_t a, uint64_t k) {
    for (const auto& p : t_.outputs(a)) {
      tokens[p.channel] = add_tokens(tokens[p.channel], k, p.rate, g_, t_.global[p.channel]);
      offer(p.other);
    }
    if (!space.empty())
      for (const auto& p : t_.inputs(a)) {
        space[p.channel] += k * p.rate;  // at most the places taken: within the capacity
        offer(p.other);
      }
    hooks_.completed(a, k);
  }

  const TimedPorts& t_;
  const Graph& g_;
  std::span<const uint64_t> times_;
  Hooks& hooks_;
  const char* what_time_;
  std::vector<uint32_t> todo_;
  std::vector<char> queued_;
  // Per actor its batches in progress from head_[a] on, in order of end.
  std::vector<std::vector<std::pair<uint64_t, uint64_t>>> running_;
  std::vector<size_t> head_;
  std::priority_queue<std::pair<uint64_t, uint32_t>, std::vector<std::pair<uint64_t, uint32_t>>,
                      std::greater<>>
      ends_;
};

}  // namespace sdf::detail
