#include "sdf/claims.hpp"

#include <tuple>

#include "sdf/checker.hpp"
#include "sdf/metrics.hpp"
#include "sdf/online.hpp"
#include "sdf/rates.hpp"
#include "sdf/repetitions.hpp"
#include "sdf/schedule.hpp"

namespace sdf::claims {

namespace {

std::tuple<size_t, size_t, uint64_t> size_of(const Graph& g) {
  uint64_t weight = 0;
  for (const Channel& c : g.channels()) weight += c.prd + c.cns + c.delay;
  return {g.actor_count(), g.channel_count(), weight};
}

void keep_smallest(Report& report, const std::string& claim, const Graph& g) {
  auto it = report.counterexamples.find(claim);
  if (it == report.counterexamples.end()) {
    report.counterexamples.emplace(claim, g);
  } else if (size_of(g) < size_of(it->second)) {
    it->second = g;
  }
}

// Runs one policy and folds the result into the stats; returns the summed buffers of the
// window when the outcome is `returns` (0 otherwise).
uint64_t measure_policy(Report& report, const std::string& prefix, PolicyStats& st, const Graph& g,
                        const std::vector<uint64_t>& q, OnlineOptions sched) {
  OnlineRunOptions opt;
  opt.scheduler = sched;
  opt.max_decisions = 2'000'000;
  const OnlineRun run = run_online(g, q, opt);
  switch (run.outcome) {
    case Outcome::returns:
      ++st.returns;
      break;
    case Outcome::periodic:
      ++st.periodic;
      keep_smallest(report, prefix + "-periodic", g);
      break;
    case Outcome::unbounded: {
      ++st.unbounded;
      keep_smallest(report, prefix + "-unbounded", g);
      bool self_loop = false;
      for (const Channel& c : g.channels()) self_loop = self_loop || c.src == c.dst;
      if (!self_loop) keep_smallest(report, prefix + "-unbounded-without-self-loops", g);
      OnlineRunOptions big = opt;
      big.growth_periods *= 16;
      big.max_listed_runs = 0;
      if (run_online(g, q, big).outcome == Outcome::unbounded) ++st.unbounded_confirmed;
      break;
    }
    case Outcome::deadlock:
      ++st.deadlock;
      keep_smallest(report, prefix + "-deadlock", g);
      break;
    case Outcome::limit:
      ++st.limit;
      keep_smallest(report, prefix + "-limit", g);
      break;
  }
  const uint64_t n = g.actor_count();
  const uint64_t wait = run.metrics.fairness.max;
  st.max_wait = std::max(st.max_wait, wait);
  if (wait + 1 >= n) {
    ++st.fairness_violations;
    keep_smallest(report, prefix + "-fairness", g);
  }
  if (wait + 1 > n) {
    ++st.fairness_violations_weak;
    keep_smallest(report, prefix + "-fairness-weak", g);
  }
  bool ok = run.runs_listed && run.metrics.followed_model;
  if (ok && (run.outcome == Outcome::returns || run.outcome == Outcome::periodic)) {
    const std::span<const Run> runs(run.runs);
    const CheckResult pre = check_admissible(g, runs.first(run.transient_decisions));
    ok = pre.valid && check_period(g, q, runs.subspan(run.transient_decisions), pre.tokens).valid;
  }
  if (!ok) {
    ++st.checker_failures;
    keep_smallest(report, prefix + "-checker", g);
  }
  if (sched.bounded && run.outcome != Outcome::returns) keep_smallest(report, "bounded-invalid", g);
  uint64_t total = 0;
  if (run.outcome == Outcome::returns)
    for (uint64_t b : run.metrics.buffers) total += b;
  return total;
}

// A mid-period change of one actor's rates by a factor (×2, ×3, ×1/2 or ×3/2 when every rate
// allows it), after a random firing within the first two periods, run by `policy`.
void measure_rate_change(Report& report, const std::string& prefix, RateChangeStats& st,
                         const Graph& g, const std::vector<uint64_t>& q, Policy policy,
                         crowddb::Rng& rng) {
  static constexpr std::pair<uint64_t, uint64_t> kFactors[] = {{2, 1}, {3, 1}, {1, 2}, {3, 2}};
  const auto a = static_cast<ActorId>(rng.below(g.actor_count()));
  auto [num, den] = kFactors[rng.below(std::size(kFactors))];
  uint64_t period = 0;
  for (uint64_t v : q) period += v;
  const uint64_t at = rng.below(2 * period);
  RateChange rc;
  try {
    rc = RateChange::scaled(g, a, num, den, at);
  } catch (const Error&) {
    num = 2, den = 1;  // a rate that the factor leaves fractional
    rc = RateChange::scaled(g, a, num, den, at);
  }
  OnlineRunOptions opt;
  opt.max_decisions = 2'000'000;
  const RateChangeResult r = simulate_rate_change(g, policy, rc, opt);
  ++st.changes;
  Graph named = g;
  named.name = g.actor_name(a) + "*" + std::to_string(num) + "/" + std::to_string(den) + "@" +
               std::to_string(at);
  if (!r.after.consistent) {  // scaling keeps a graph consistent: a failure of the experiment
    keep_smallest(report, prefix + "-change-inconsistent", named);
    return;
  }
  switch (r.outcome) {
    case Outcome::returns:
    case Outcome::periodic:
      if (r.period_checked && !r.period_valid) {
        ++st.invalid;
        keep_smallest(report, prefix + "-change-invalid", named);
        return;
      }
      ++st.periodic_again;
      st.max_firings_until_periodic =
          std::max(st.max_firings_until_periodic, r.firings_until_periodic);
      if (r.firings_until_periodic == 0)
        ++st.at_once;
      else
        keep_smallest(report, prefix + "-change-not-at-once", named);
      return;
    case Outcome::unbounded:
      ++st.unbounded;
      keep_smallest(report, prefix + "-change-unbounded", named);
      return;
    case Outcome::deadlock:
      ++st.deadlock;
      keep_smallest(report, prefix + "-change-deadlock", named);
      return;
    case Outcome::limit:
      ++st.limit;
      keep_smallest(report, prefix + "-change-limit", named);
      return;
  }
}

}  // namespace

Report run(const Options& options) {
  using gen::Shape;
  Report report;
  const Shape shapes[] = {Shape::chain, Shape::fan_out, Shape::fan_in, Shape::dag, Shape::cyclic};
  uint64_t class_id = 0;
  for (Shape shape : shapes) {
    for (bool multirate : {true, false}) {
      for (bool self_loops : {false, true}) {
        ClassStats cs;
        cs.name = std::string(gen::shape_name(shape)) +
                  (multirate ? " multi-rate" : " homogeneous") + (self_loops ? " +self-loops" : "");
        // The rate changes draw from their own stream, so the graphs do not depend on them.
        crowddb::Rng change_rng = crowddb::Rng::stream(options.seed, 1000 + class_id);
        crowddb::Rng rng = crowddb::Rng::stream(options.seed, class_id++);
        for (uint64_t i = 0; i < options.graphs_per_class; ++i) {
          gen::Spec spec;
          spec.shape = shape;
          spec.multirate = multirate;
          spec.self_loops = self_loops;
          spec.actors =
              options.min_actors +
              static_cast<uint32_t>(rng.below(options.max_actors - options.min_actors + 1));
          const gen::Generated gg = gen::generate(spec, rng);
          const Graph& g = gg.graph;
          const Repetitions rep = compute_repetitions(g);
          if (!rep.consistent || rep.q != gg.q) keep_smallest(report, "generator-q", g);
          const StaticSchedule st = static_schedule(g, gg.q);
          if (!st.complete) {
            keep_smallest(report, "generator-live", g);
            continue;
          }
          ++cs.graphs;
          uint64_t stat = 0;
          for (uint64_t b : measure(g, gg.q, Eligibility::owing, st.runs).buffers) stat += b;
          const uint64_t on =
              measure_policy(report, "online", cs.online, g, gg.q, {FiringRule::floor_key, false});
          measure_policy(report, "online-one", cs.online_one, g, gg.q, {FiringRule::one, false});
          const uint64_t bo =
              measure_policy(report, "bounded", cs.bounded, g, gg.q, {FiringRule::floor_key, true});
          measure_rate_change(report, "online", cs.online_change, g, gg.q, Policy::online,
                              change_rng);
          measure_rate_change(report, "bounded", cs.bounded_change, g, gg.q, Policy::online_bounded,
                              change_rng);
          if (on > 0) {
            ++cs.common;
            cs.buffers_static += stat;
            cs.buffers_online += on;
            cs.buffers_bounded += bo;
          }
        }
        report.classes.push_back(std::move(cs));
      }
    }
  }
  return report;
}

std::vector<Verdict> verdicts(const Report& report) {
  PolicyStats online, one, bounded;
  RateChangeStats oc, bc;
  uint64_t graphs = 0;
  auto add = [](PolicyStats& t, const PolicyStats& s) {
    t.returns += s.returns, t.periodic += s.periodic, t.unbounded += s.unbounded;
    t.deadlock += s.deadlock, t.limit += s.limit, t.checker_failures += s.checker_failures;
    t.fairness_violations += s.fairness_violations;
    t.fairness_violations_weak += s.fairness_violations_weak;
  };
  auto add_change = [](RateChangeStats& t, const RateChangeStats& s) {
    t.changes += s.changes, t.periodic_again += s.periodic_again, t.at_once += s.at_once;
    t.unbounded += s.unbounded, t.deadlock += s.deadlock, t.limit += s.limit;
    t.invalid += s.invalid;
  };
  for (const ClassStats& c : report.classes) {
    graphs += c.graphs;
    add(online, c.online), add(one, c.online_one), add(bounded, c.bounded);
    add_change(oc, c.online_change), add_change(bc, c.bounded_change);
  }
  // The smallest of the counter-examples kept under these keys.
  auto smallest = [&](std::initializer_list<const char*> keys) {
    std::string best;
    for (const char* k : keys) {
      const auto it = report.counterexamples.find(k);
      if (it == report.counterexamples.end()) continue;
      if (best.empty() || size_of(it->second) < size_of(report.counterexamples.at(best))) best = k;
    }
    return best;
  };
  std::vector<Verdict> v;
  v.push_back(
      {"`online` returns a valid period (thesis 5.3)", graphs - online.returns, graphs,
       smallest({"online-periodic", "online-unbounded", "online-deadlock", "online-limit"})});
  v.push_back({"`online --firings one` returns a valid period", graphs - one.returns, graphs,
               smallest({"online-one-periodic", "online-one-unbounded", "online-one-deadlock",
                         "online-one-limit"})});
  v.push_back({"every period and periodic cycle passes the checker (cycles are multiples of q)",
               online.checker_failures + one.checker_failures + bounded.checker_failures,
               3 * graphs, smallest({"online-checker", "online-one-checker", "bounded-checker"})});
  v.push_back({"fairness < n - 1 (thesis 5.5)", online.fairness_violations, graphs,
               smallest({"online-fairness"})});
  v.push_back({"fairness <= n - 1 (the proof's \"at most n - 1\")", online.fairness_violations_weak,
               graphs, smallest({"online-fairness-weak"})});
  v.push_back({"`online-bounded` completes a valid period",
               graphs - bounded.returns + bounded.checker_failures, graphs,
               smallest({"bounded-invalid", "bounded-checker"})});
  // A change can leave tokens from which the changed graph deadlocks whatever the schedule
  // (SDF is persistent): those changes are not counted against a scheduler.
  v.push_back(
      {"after a rate change `online` is periodic again at once (thesis 5.4: \"the "
       "convergence ... being zero\"; changes that deadlock the graph left out)",
       oc.changes - oc.deadlock - oc.at_once, oc.changes - oc.deadlock,
       smallest({"online-change-not-at-once", "online-change-unbounded", "online-change-limit",
                 "online-change-invalid", "online-change-inconsistent"})});
  v.push_back({"after a rate change `online` becomes periodic again, with a valid period",
               oc.changes - oc.deadlock - oc.periodic_again, oc.changes - oc.deadlock,
               smallest({"online-change-unbounded", "online-change-limit", "online-change-invalid",
                         "online-change-inconsistent"})});
  v.push_back({"after a rate change `online-bounded` completes a valid period",
               bc.changes - bc.deadlock - bc.periodic_again, bc.changes - bc.deadlock,
               smallest({"bounded-change-unbounded", "bounded-change-limit",
                         "bounded-change-invalid", "bounded-change-inconsistent"})});
  return v;
}

}  // namespace sdf::claims
