// The thesis's claims (DESIGN §8, docs/sdf.md "The thesis's claims, tested"): a quick random
// sample here, thousands of graphs in claims_slow_test.cpp, and the smallest counter-example of
// each failed claim pinned as a data file.
#include "sdf/claims.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "helpers.hpp"
#include "sdf/checker.hpp"
#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/naive.hpp"
#include "sdf/online.hpp"
#include "sdf/repetitions.hpp"

namespace sdf {
namespace {

TEST(Claims, RandomSampleBoundedAlwaysValidAndEveryScheduleChecks) {
  claims::Options o;
  o.graphs_per_class = 25;  // 20 classes: 500 graphs, each run by three policies
  o.seed = 7;
  const claims::Report r = claims::run(o);
  ASSERT_EQ(r.classes.size(), 20u);
  uint64_t graphs = 0, returns = 0, periodic = 0, unbounded = 0;
  for (const claims::ClassStats& c : r.classes) {
    graphs += c.graphs;
    EXPECT_EQ(c.graphs, 25u) << c.name;  // the generator's graphs are consistent and live
    EXPECT_EQ(c.bounded.returns, c.graphs) << c.name;
    for (const claims::PolicyStats* s : {&c.online, &c.online_one, &c.bounded}) {
      EXPECT_EQ(s->checker_failures, 0u) << c.name;
      EXPECT_EQ(s->limit + s->deadlock, 0u) << c.name;
    }
    returns += c.online.returns;
    periodic += c.online.periodic;
    unbounded += c.online.unbounded;
    // After a rate change bounded completes a valid period unless the change deadlocks the
    // graph; every period after a change passes the checker.
    EXPECT_EQ(c.bounded_change.changes, c.graphs) << c.name;
    EXPECT_EQ(c.bounded_change.periodic_again + c.bounded_change.deadlock, c.graphs) << c.name;
    EXPECT_EQ(c.bounded_change.invalid + c.online_change.invalid, 0u) << c.name;
    EXPECT_EQ(c.online_change.limit, 0u) << c.name;
  }
  EXPECT_EQ(graphs, 500u);
  EXPECT_EQ(r.counterexamples.count("generator-q"), 0u);
  EXPECT_EQ(r.counterexamples.count("generator-live"), 0u);
  EXPECT_EQ(r.counterexamples.count("bounded-invalid"), 0u);
  // Measured, not assumed: the sample shows all three outcomes of `online`.
  EXPECT_GT(returns, 0u);
  EXPECT_GT(periodic, 0u);
  EXPECT_GT(unbounded, 0u);
  // The verdicts against a recount that shares nothing with the experiment but the generator:
  // the same graphs (the same streams and specs as claims::run), each run by the naive online
  // scheduler (recomputed per decision), its period checked by the checker and its fairness
  // read from the naive run's own waits.
  const std::vector<claims::Verdict> v = claims::verdicts(r);
  ASSERT_EQ(v.size(), 9u);
  uint64_t recount = 0, fails[2] = {0, 0}, unfair = 0, unfair_weak = 0;
  uint64_t class_id = 0;
  for (gen::Shape shape : {gen::Shape::chain, gen::Shape::fan_out, gen::Shape::fan_in,
                           gen::Shape::dag, gen::Shape::cyclic})
    for (bool multirate : {true, false})
      for (bool self_loops : {false, true}) {
        crowddb::Rng rng = crowddb::Rng::stream(o.seed, class_id++);
        for (uint64_t i = 0; i < o.graphs_per_class; ++i) {
          gen::Spec spec;
          spec.shape = shape;
          spec.multirate = multirate;
          spec.self_loops = self_loops;
          spec.actors =
              o.min_actors + static_cast<uint32_t>(rng.below(o.max_actors - o.min_actors + 1));
          const gen::Generated gg = gen::generate(spec, rng);
          ++recount;
          for (int one = 0; one < 2; ++one) {
            OnlineRunOptions opt;
            opt.max_decisions = 2'000'000;
            opt.scheduler.firings = one ? FiringRule::one : FiringRule::floor_key;
            const naive::NaiveOnline n = naive::online(gg.graph, gg.q, opt);
            const bool valid =
                n.outcome == Outcome::returns && check_period(gg.graph, gg.q, n.runs).valid;
            fails[one] += !valid;
            if (one) continue;
            uint64_t wait = 0;
            for (uint64_t w : n.waits) wait = std::max(wait, w);
            unfair += wait + 1 >= gg.graph.actor_count();
            unfair_weak += wait + 1 > gg.graph.actor_count();
          }
        }
      }
  EXPECT_EQ(recount, graphs);
  EXPECT_EQ(v[0].graphs, graphs);
  EXPECT_EQ(v[0].fails, fails[0]);
  EXPECT_EQ(v[1].fails, fails[1]);
  EXPECT_EQ(v[3].fails, unfair);
  EXPECT_EQ(v[4].fails, unfair_weak);
  EXPECT_EQ(v[5].fails, 0u);  // online-bounded
  EXPECT_EQ(v[8].fails, 0u);  // online-bounded after a rate change
  EXPECT_GT(v[6].fails, 0u);  // online is not periodic at once after every change
  for (const claims::Verdict& x : v) {
    EXPECT_LE(x.fails, x.graphs) << x.claim;
    EXPECT_EQ(x.fails > 0, !x.counterexample.empty()) << x.claim;
    EXPECT_TRUE(x.counterexample.empty() || r.counterexamples.count(x.counterexample) == 1);
  }
}

// Each pinned counter-example still fails its claim. The file name says which:
// <policy>-<claim>.json with policy online | online-one | bounded.
TEST(Claims, PinnedCounterExamplesStillFail) {
  const std::filesystem::path dir = test::data("counterexamples");
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().stem().string();
    SCOPED_TRACE(name);
    ++files;
    const Graph g = read_graph_file(entry.path().string());
    const Repetitions rep = compute_repetitions(g);
    ASSERT_TRUE(rep.consistent);
    OnlineRunOptions o;
    std::string claim;
    if (name.rfind("online-one-", 0) == 0) {
      o.scheduler.firings = FiringRule::one;
      claim = name.substr(11);
    } else if (name.rfind("online-", 0) == 0) {
      claim = name.substr(7);
    } else if (name.rfind("bounded-", 0) == 0) {
      o.scheduler.bounded = true;
      claim = name.substr(8);
    } else {
      FAIL() << "unknown counter-example file";
    }
    const OnlineRun run = run_online(g, rep.q, o);
    const uint64_t n = g.actor_count();
    if (claim == "periodic") {
      EXPECT_EQ(run.outcome, Outcome::periodic);
    } else if (claim.rfind("unbounded", 0) == 0) {
      EXPECT_EQ(run.outcome, Outcome::unbounded);
      o.growth_periods = 4096;
      EXPECT_EQ(run_online(g, rep.q, o).outcome, Outcome::unbounded);
    } else if (claim == "fairness") {
      EXPECT_GE(run.metrics.fairness.max, n - 1);
    } else if (claim == "fairness-weak") {
      EXPECT_GT(run.metrics.fairness.max, n - 1);
    } else {
      FAIL() << "unknown claim " << claim;
    }
    if (o.scheduler.bounded) {
      ASSERT_EQ(run.outcome, Outcome::returns);
      EXPECT_TRUE(check_period(g, rep.q, run.runs).valid);
    }
  }
  EXPECT_GE(files, 10);
}

}  // namespace
}  // namespace sdf
