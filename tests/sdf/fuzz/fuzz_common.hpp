// Shared body of the libFuzzer targets for the graph readers: any input either reads or fails
// with sdf::Error; what reads must survive the analyses (bounded in size) and a write/read
// round trip through both formats. Anything else (another exception, a sanitizer report, a
// round-trip mismatch) is a finding.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sdf/io.hpp"
#include "sdf/online.hpp"
#include "sdf/repetitions.hpp"
#include "sdf/schedule.hpp"
#include "sdf/throughput.hpp"

namespace sdf::fuzz {

inline bool same(const Graph& a, const Graph& b) {
  if (a.actor_count() != b.actor_count() || a.channel_count() != b.channel_count()) return false;
  for (ActorId x = 0; x < a.actor_count(); ++x)
    if (a.actor_name(x) != b.actor_name(x) || a.actor_time(x) != b.actor_time(x) ||
        (!a.actor_type(x).empty() && a.actor_type(x) != b.actor_type(x)))
      return false;
  for (ChannelId c = 0; c < a.channel_count(); ++c) {
    const Channel &p = a.channel(c), &q = b.channel(c);
    if (p.src != q.src || p.dst != q.dst || p.prd != q.prd || p.cns != q.cns ||
        p.delay != q.delay || a.channel_name(c) != b.channel_name(c) ||
        (!a.src_port(c).empty() &&
         (a.src_port(c) != b.src_port(c) || a.dst_port(c) != b.dst_port(c))))
      return false;
  }
  return true;
}

inline void exercise(Graph (*read)(std::string_view, const std::string&), std::string_view text) {
  Graph g;
  try {
    g = read(text, "fuzz");
  } catch (const Error&) {
    return;
  }
  // Round trips: what was read must be written so that it reads back the same.
  if (!same(g, read_json(write_json(g), "json")) || !same(g, read_sdf3(write_sdf3(g), "sdf3")))
    std::abort();
  (void)write_dot(g);
  // Timed analyses on small graphs, with a default time for actors without one: the two
  // throughput methods must agree.
  try {
    if (g.actor_count() <= 16) {
      ThroughputLimits lim;
      lim.max_states = 20000;
      lim.max_hsdf_size = 5000;
      lim.max_token_graph = 1'000'000;
      std::string ss, mcm;
      try {
        ss = throughput_state_space(g, 1, lim).str();
      } catch (const Error&) {
      }
      try {
        mcm = throughput_mcm(g, 1, lim).str();
      } catch (const Error&) {
      }
      if (!ss.empty() && !mcm.empty() && ss != mcm) std::abort();
    }
  } catch (const Error&) {
  }
  try {
    const Repetitions r = compute_repetitions(g);
    if (!r.consistent || g.actor_count() > 64) return;
    const StaticSchedule s = static_schedule(g, r.q);
    if (!s.complete) return;
    OnlineRunOptions o;
    o.max_decisions = 2000;
    o.max_listed_runs = 2000;
    (void)run_online(g, r.q, o);
  } catch (const Error& e) {
    if (e.kind() != Error::Kind::overflow) std::abort();
  }
}

}  // namespace sdf::fuzz
