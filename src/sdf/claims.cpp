#include "sdf/claims.hpp"

#include <tuple>

#include "sdf/checker.hpp"
#include "sdf/metrics.hpp"
#include "sdf/online.hpp"
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

}  // namespace sdf::claims
