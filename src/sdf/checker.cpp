#include "sdf/checker.hpp"

#include "sdf/checked.hpp"

namespace sdf {

CheckResult check_admissible(const Graph& g, std::span<const Run> runs,
                             std::span<const uint64_t> tokens0) {
  using detail::u128;
  CheckResult r;
  r.tokens = tokens0.empty() ? g.delays() : std::vector<uint64_t>(tokens0.begin(), tokens0.end());
  r.fired.assign(g.actor_count(), 0);
  if (r.tokens.size() != g.channel_count()) {
    r.reason = "token state has the wrong number of channels";
    return r;
  }
  const Adjacency adj(g);
  uint64_t done = 0;  // firings checked so far
  for (const Run& run : runs) {
    if (run.actor >= g.actor_count()) {
      r.reason = "run names an unknown actor";
      r.failed_firing = done + 1;
      return r;
    }
    if (run.count == 0) continue;
    // k firings in a row: on an input that is not a self-loop the i-th firing (1-based) needs
    // i·cns tokens there, so the last one decides; on a self-loop losing d = cns - prd per
    // firing, the k-th needs cns + (k-1)·d. The first inadmissible firing is reported.
    uint64_t ok = run.count;  // firings of this run that are admissible
    for (ChannelId c : adj.inputs(run.actor)) {
      const Channel& ch = g.channel(c);
      const u128 t = r.tokens[c];
      uint64_t allowed;
      if (ch.src != ch.dst) {
        allowed = static_cast<uint64_t>(std::min<u128>(t / ch.cns, UINT64_MAX));
      } else if (t < ch.cns) {
        allowed = 0;
      } else if (ch.prd >= ch.cns) {
        allowed = UINT64_MAX;
      } else {
        allowed =
            static_cast<uint64_t>(std::min<u128>(1 + (t - ch.cns) / (ch.cns - ch.prd), UINT64_MAX));
      }
      if (allowed < ok) ok = allowed;
    }
    if (ok < run.count) {
      r.failed_firing = done + ok + 1;
      r.reason = "firing " + std::to_string(r.failed_firing) + " (" + g.actor_name(run.actor) +
                 ") is not admissible";
      return r;
    }
    // Apply in 128 bits (a self-loop nets its production against its consumption), then
    // narrow with a check.
    for (ChannelId c : adj.inputs(run.actor)) {
      const Channel& ch = g.channel(c);
      if (ch.src != ch.dst) r.tokens[c] -= static_cast<uint64_t>(run.count * u128{ch.cns});
    }
    for (ChannelId c : adj.outputs(run.actor)) {
      const Channel& ch = g.channel(c);
      u128 t = r.tokens[c] + static_cast<u128>(run.count) * ch.prd;
      if (ch.src == ch.dst) t -= static_cast<u128>(run.count) * ch.cns;  // admissible: >= 0
      if (t > UINT64_MAX) {
        r.reason =
            "the token count on channel '" + std::string(g.channel_name(c)) + "' exceeds 64 bits";
        r.failed_firing = done + 1;
        return r;
      }
      r.tokens[c] = static_cast<uint64_t>(t);
    }
    r.fired[run.actor] = detail::add_sat(r.fired[run.actor], run.count);
    done = detail::add_sat(done, run.count);
  }
  r.valid = true;
  return r;
}

CheckResult check_period(const Graph& g, std::span<const uint64_t> q, std::span<const Run> runs,
                         std::span<const uint64_t> tokens0) {
  CheckResult r = check_admissible(g, runs, tokens0);
  if (!r.valid) return r;
  r.valid = false;
  for (ActorId a = 0; a < g.actor_count(); ++a) {
    if (r.fired[a] == 0 || r.fired[a] % q[a] != 0) {
      r.reason = "actor '" + g.actor_name(a) + "' fired " + std::to_string(r.fired[a]) +
                 " times, not a positive multiple of its repetition count " + std::to_string(q[a]);
      return r;
    }
  }
  const std::vector<uint64_t> start =
      tokens0.empty() ? g.delays() : std::vector<uint64_t>(tokens0.begin(), tokens0.end());
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    if (r.tokens[c] != start[c]) {
      r.reason = "channel '" + std::string(g.channel_name(c)) + "' ends with " +
                 std::to_string(r.tokens[c]) + " tokens, not its initial " +
                 std::to_string(start[c]);
      return r;
    }
  }
  r.valid = true;
  return r;
}

}  // namespace sdf
