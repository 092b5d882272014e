// The zero-overlap invariant over more than 10^4 ticks of dense scenarios, every tick checked by
// brute force (tests/sim/invariant.hpp), and the tick hashes of every exact collision method
// compared. Brute-force-checked ticks: airport 3,500 + circle 1,800 + bottleneck 3,600 (fewer
// once everyone has left: it runs to the end) + crossing 800 + spawned overlaps 1,000 = 10,700.
// Opt-in (label `slow`): ctest --test-dir build -L slow
#include <gtest/gtest.h>

#include "sim/invariant.hpp"
#include "support/configs.hpp"
#include "util/rng.hpp"

namespace crowddb::sim {
namespace {

struct Variant {
  std::string scenario;
  uint64_t ticks;
  std::function<void(nlohmann::json&)> edit;
};

// Runs the variant with each method: the first is checked by brute force every tick, the others
// must give the same hash every tick.
void run_variant(const Variant& v, const std::vector<std::string>& methods) {
  SCOPED_TRACE(v.scenario);
  std::vector<uint64_t> reference;
  for (const std::string& m : methods) {
    Scenario sc = test::load_edited(v.scenario, [&](nlohmann::json& j) {
      v.edit(j);
      j["access"]["collisions"] = m;
    });
    sc.world.apply_pending();
    ASSERT_TRUE(test::initially_overlap_free(sc.world, sc.config))
        << "the variant must start overlap-free";
    Simulation sim(std::move(sc.world), sc.config);
    const bool check = reference.empty();
    const test::RunResult r = test::run_checked(sim, v.ticks, check);
    if (check) {
      EXPECT_EQ(r.bad, 0u) << m;
      EXPECT_EQ(r.overlaps_at_end, 0u) << m;
      EXPECT_EQ(r.metric_mismatch, 0u) << m;
      EXPECT_GT(r.frozen_total, 0u) << "the backoff had nothing to do";
      std::printf(
          "  %s (%s): %zu ticks, %zu agent-ticks frozen, max %zu freeze rounds, %zu arrived\n",
          v.scenario.c_str(), m.c_str(), r.ticks, r.frozen_total, r.iterations_max, r.arrived);
      reference = r.hashes;
    } else {
      EXPECT_EQ(r.hashes, reference) << m;
    }
  }
}

// The thesis's rule steers: it leaves collisions for the backoff to resolve (orca and cfsm do not
// need it), and with the potential field off (w_apf 0) it leaves more of them.
void thesis_model(nlohmann::json& j, double w_apf) {
  j["steering"] = {{"model", "thesis"}, {"thesis", {{"w_apf", w_apf}}}};
}

auto set_count(std::size_t count, uint64_t seed) {
  return [=](nlohmann::json& j) {
    thesis_model(j, 1);
    j["groups"][0]["count"] = count;
    j["seed"] = seed;
  };
}

TEST(BackoffSlow, AirportAtHighDensity) {
  // 2000 travellers in the 100 x 60 m hall (twice the shipped density) and the arrivals; the
  // potential field off, which makes collisions more frequent.
  run_variant({"airport", 2500,
               [](nlohmann::json& j) {
                 thesis_model(j, 0);
                 j["groups"][0]["count"] = 2000;
               }},
              {"grid", "naive", "sweep"});
  run_variant({"airport", 1000, [](nlohmann::json& j) { thesis_model(j, 0); }}, {"sweep", "grid"});
}

TEST(BackoffSlow, CircleAtThreeDensities) {
  // More agents on the same ring need smaller discs to start apart (spacing 2 pi 12 m / count).
  for (auto [n, r, s] : {std::tuple{150, 0.24, 7}, {200, 0.18, 8}, {250, 0.14, 9}})
    run_variant({"circle", 600,
                 // clang 14 cannot capture structured bindings: copied into the capture list.
                 [count = n, radius = r, seed = s](nlohmann::json& j) {
                   set_count(static_cast<std::size_t>(count), static_cast<uint64_t>(seed))(j);
                   j["groups"][0]["radius"] = radius;
                 }},
                {"grid", "naive", "sweep", "nn"});
}

TEST(BackoffSlow, BottleneckAtThreeDensities) {
  for (auto [count, seed] : {std::pair{100, 3}, {150, 4}, {170, 5}})
    run_variant({"bottleneck", 1200,
                 set_count(static_cast<std::size_t>(count), static_cast<uint64_t>(seed))},
                {"grid", "naive", "sweep"});
}

TEST(BackoffSlow, Crossing) {
  run_variant({"crossing", 800, [](nlohmann::json& j) { thesis_model(j, 1); }},
              {"grid", "naive", "sweep"});
}

TEST(BackoffSlow, SpawnedOverlapsNeverDeepenOverALongRun) {
  // Clumps of agents spawned on top of each other (equal radii, so nn takes part once clean).
  World w(Bounds{0, 0, 150, 150});
  w.add_goal({"ne", 140, 140, 1, 3, {}});
  w.add_goal({"sw", 10, 10, 1, 3, {}});
  Rng rng(21);
  for (int c = 0; c < 20; ++c) {
    const double cx = rng.uniform(20, 130), cy = rng.uniform(20, 130);
    for (int i = 0; i < 8; ++i) {
      AgentSpec s;
      s.x = cx + rng.uniform(-2, 2);
      s.y = cy + rng.uniform(-2, 2);
      s.radius = 1;
      s.max_speed = 1;
      s.pref_speed = s.max_speed;
      s.max_accel = 0.5;
      s.goal = static_cast<uint32_t>(c % 2);
      w.insert(s);
    }
  }
  SimConfig cfg = test::thesis_config();
  cfg.steering.thesis.w_apf = 2;
  cfg.steering.thesis.w_ftc = 2;
  cfg.arrival = ArrivalPolicy::retarget;
  std::vector<uint64_t> reference;
  for (const std::string m : {"grid", "naive", "sweep", "nn"}) {
    cfg.access.collisions = m;
    Simulation sim(w, cfg);
    const test::RunResult r = test::run_checked(sim, 1000, reference.empty());
    if (reference.empty()) {
      EXPECT_EQ(r.bad, 0u);
      EXPECT_EQ(r.metric_mismatch, 0u);
      EXPECT_GT(r.overlaps_at_end, 100u);
      reference = r.hashes;
    } else {
      EXPECT_EQ(r.hashes, reference) << m;
    }
  }
}

}  // namespace
}  // namespace crowddb::sim
