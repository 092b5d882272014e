#include "sdf/rates.hpp"

#include "sdf/checked.hpp"
#include "sdf/checker.hpp"
#include "sdf/metrics.hpp"
#include "sdf/schedule.hpp"

namespace sdf {

const char* policy_name(Policy p) {
  switch (p) {
    case Policy::static_order:
      return "static";
    case Policy::online:
      return "online";
    case Policy::online_bounded:
      return "online-bounded";
  }
  return "?";
}

RateChange RateChange::uniform(const Graph& g, ActorId a, uint64_t prd, uint64_t cns,
                               uint64_t at_firing) {
  if (prd == 0 || cns == 0) throw Error(Error::Kind::input, "rate change: rates must be positive");
  RateChange rc;
  rc.actor = a;
  rc.at_firing = at_firing;
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    if (ch.src == a || ch.dst == a)
      rc.rates.push_back({c, ch.src == a ? prd : ch.prd, ch.dst == a ? cns : ch.cns});
  }
  return rc;
}

RateChange RateChange::scaled(const Graph& g, ActorId a, uint64_t num, uint64_t den,
                              uint64_t at_firing) {
  if (num == 0 || den == 0)
    throw Error(Error::Kind::input, "rate change: the factor must be positive");
  RateChange rc;
  rc.actor = a;
  rc.at_firing = at_firing;
  auto scale = [&](ChannelId c, uint64_t r) {
    const detail::u128 v = static_cast<detail::u128>(r) * num;
    if (v % den != 0 || v / den > UINT64_MAX)
      throw Error(Error::Kind::input,
                  "rate change: channel '" + std::string(g.channel_name(c)) + "': " +
                      std::to_string(r) + "·" + std::to_string(num) + "/" + std::to_string(den) +
                      (v % den != 0 ? " is not a whole number" : " does not fit in 64 bits"));
    return static_cast<uint64_t>(v / den);
  };
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    if (ch.src == ch.dst) continue;  // a self-loop models the actor's state, not its data
    if (ch.src == a || ch.dst == a)
      rc.rates.push_back(
          {c, ch.src == a ? scale(c, ch.prd) : ch.prd, ch.dst == a ? scale(c, ch.cns) : ch.cns});
  }
  return rc;
}

namespace {

// Buffers over the periodic part of an online run that starts at `start`.
std::vector<uint64_t> cycle_buffers(const Graph& g, std::span<const uint64_t> q,
                                    const OnlineScheduler& start, const OnlineRun& run,
                                    bool bounded) {
  OnlineScheduler s = start;
  for (uint64_t i = 0; i < run.transient_decisions; ++i) s.step();
  Meter m(g, q, bounded ? Eligibility::owing : Eligibility::fireable, s.tokens(),
          bounded ? s.iteration_counts() : std::span<const uint64_t>{});
  for (uint64_t i = 0; i < run.cycle_decisions; ++i) {
    const auto r = s.step();
    if (!r) break;
    m.record(*r);
  }
  return m.metrics().buffers;
}

}  // namespace

RateChangeResult simulate_rate_change(const Graph& g, Policy policy, const RateChange& change,
                                      const OnlineRunOptions& options) {
  if (change.actor >= g.actor_count()) throw Error(Error::Kind::input, "unknown actor");
  std::vector<bool> given(g.channel_count(), false);
  for (const ChannelRates& r : change.rates) {
    if (r.channel >= g.channel_count())
      throw Error(Error::Kind::input, "rate change: unknown channel");
    if (given[r.channel])
      throw Error(
          Error::Kind::input,
          "rate change: channel '" + std::string(g.channel_name(r.channel)) + "' is given twice");
    given[r.channel] = true;
    const Channel& ch = g.channel(r.channel);
    if (ch.src != change.actor && ch.dst != change.actor)
      throw Error(Error::Kind::input,
                  "rate change: channel '" + std::string(g.channel_name(r.channel)) +
                      "' is not a channel of '" + g.actor_name(change.actor) + "'");
    if ((ch.src != change.actor && r.prd != ch.prd) || (ch.dst != change.actor && r.cns != ch.cns))
      throw Error(Error::Kind::input, "rate change: channel '" +
                                          std::string(g.channel_name(r.channel)) +
                                          "': only the actor's own ports change");
    if (r.prd == 0 || r.cns == 0)
      throw Error(Error::Kind::input, "rate change: rates must be positive");
  }
  const Repetitions rep = compute_repetitions(g);
  if (!rep.consistent)
    throw Error(Error::Kind::input, "the graph is inconsistent (channel '" +
                                        std::string(g.channel_name(rep.channel)) + "')");
  const StaticSchedule first = static_schedule(g, rep.q);
  if (!first.complete)
    throw Error(Error::Kind::input,
                "the graph deadlocks (actor '" + g.actor_name(first.stuck.front()) + "' is stuck)");
  RateChangeResult out;
  out.q_before = rep.q;
  out.changed = g;
  for (const ChannelRates& r : change.rates) out.changed.set_rates(r.channel, r.prd, r.cns);
  out.after = compute_repetitions(out.changed);
  if (out.after.consistent) out.q_after = out.after.q;
  const Graph& g2 = out.changed;

  OnlineOptions sched = options.scheduler;
  sched.bounded = policy == Policy::online_bounded;
  if (policy == Policy::static_order) {
    out.buffers_before = measure(g, rep.q, Eligibility::owing, first.runs).buffers;
    // Tokens after `at_firing` firings of the repeated period: whole periods change nothing.
    const uint64_t per = total_firings(first.runs);
    uint64_t left = change.at_firing % per;
    std::vector<Run> prefix;
    for (const Run& r : first.runs) {
      if (left == 0) break;
      prefix.push_back({r.actor, std::min(left, r.count)});
      left -= prefix.back().count;
    }
    out.tokens_at_change = check_admissible(g, prefix).tokens;
    if (!out.after.consistent) return out;
    const StaticSchedule next = static_schedule(g2, out.q_after, out.tokens_at_change);
    if (!next.complete) {
      out.outcome = Outcome::deadlock;
      out.stuck = next.stuck;
      return out;
    }
    out.outcome = Outcome::returns;
    out.period_firings = total_firings(next.runs);
    out.period_decisions = next.runs.size();
    out.period_checked = true;
    out.period_valid = check_period(g2, out.q_after, next.runs, out.tokens_at_change).valid;
    out.buffers_after =
        measure(g2, out.q_after, Eligibility::owing, next.runs, out.tokens_at_change).buffers;
    return out;
  }

  OnlineRunOptions opts = options;
  opts.scheduler = sched;
  const OnlineScheduler fresh(g, rep.q, sched);
  const OnlineRun before = run_online(g, rep.q, fresh, opts);
  out.outcome_before = before.outcome;
  out.channel_before = before.channel;
  // Buffers over one period only if there is one: a window of a run that never repeats (the
  // online rule letting a channel grow) measures nothing.
  if (before.outcome == Outcome::returns || before.outcome == Outcome::periodic)
    out.buffers_before = cycle_buffers(g, rep.q, fresh, before, sched.bounded);
  OnlineScheduler s = fresh;
  while (s.firings() < change.at_firing) {
    if (s.decisions() >= options.max_decisions)
      throw Error(Error::Kind::input, "rate change: firing " + std::to_string(change.at_firing) +
                                          " is not reached within the decision limit");
    if (!s.step(change.at_firing - s.firings()))
      throw Error(Error::Kind::input,
                  "rate change: the run stops before firing " + std::to_string(change.at_firing));
  }
  out.tokens_at_change.assign(s.tokens().begin(), s.tokens().end());
  if (!out.after.consistent) return out;
  // The scheduler copies the graph's rates; the changed graph is what the meter and caps see.
  s.change_rates(change.actor, change.rates, out.q_after);
  const OnlineRun after = run_online(g2, out.q_after, s, opts);
  out.outcome = after.outcome;
  out.channel = after.channel;
  out.stuck = after.stuck;
  if (after.outcome == Outcome::returns || after.outcome == Outcome::periodic) {
    out.firings_until_periodic = after.transient_firings;
    out.period_firings = after.cycle_firings;
    out.period_decisions = after.cycle_decisions;
    out.buffers_after = cycle_buffers(g2, out.q_after, s, after, sched.bounded);
    // The periodic part, replayed through the checker from the state where it starts.
    if (after.cycle_decisions <= options.max_listed_runs) {
      OnlineScheduler r = s;
      for (uint64_t i = 0; i < after.transient_decisions; ++i) r.step();
      const std::vector<uint64_t> start(r.tokens().begin(), r.tokens().end());
      std::vector<Run> runs;
      for (uint64_t i = 0; i < after.cycle_decisions; ++i) runs.push_back(*r.step());
      out.period_checked = true;
      out.period_valid = check_period(g2, out.q_after, runs, start).valid;
    }
  }
  return out;
}

}  // namespace sdf
