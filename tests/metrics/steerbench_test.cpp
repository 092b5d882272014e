// SteerBench's metrics against values worked by hand.
#include "metrics/steerbench.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <memory>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "crowddb/error.hpp"
#include "crowddb/simulation.hpp"
#include "util/byte_codec.hpp"
#include "util/executor.hpp"
#include "util/rng.hpp"
#include "world/geometry.hpp"

namespace crowddb::metrics {
namespace {

// `count` agents of radius 0.1 m bound for goal 0, uniform in [5, 95]^2.
void add_walkers(World& w, Rng& rng, int count) {
  for (int k = 0; k < count; ++k) {
    AgentSpec a;
    a.x = rng.uniform(5, 95);
    a.y = rng.uniform(5, 95);
    a.radius = 0.1;
    a.goal = 0;
    w.insert(a);
  }
  w.apply_pending();
}

// The same scores in the same order, bit for bit.
void expect_same_scores(const SteerBench& a, const SteerBench& b) {
  const std::vector<AgentScore>&sa = a.scores(), &sb = b.scores();  // (each call flushes)
  ASSERT_EQ(sa.size(), sb.size());
  auto bits = [](double v) { return std::bit_cast<uint64_t>(v); };
  for (std::size_t k = 0; k < sa.size(); ++k) {
    const AgentScore &x = sa[k], &y = sb[k];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(bits(x.time), bits(y.time)) << k;
    EXPECT_EQ(bits(x.path_length), bits(y.path_length)) << k;
    EXPECT_EQ(bits(x.energy), bits(y.energy)) << k;
    EXPECT_EQ(bits(x.acceleration), bits(y.acceleration)) << k;
    EXPECT_EQ(x.arrived, y.arrived);
  }
}

TEST(SteerBench, ConstantWalkGivesTimePathAndEnergyByHand) {
  World w(Bounds{0, 0, 100, 10});
  w.add_goal({"g", 90, 5, 0.5, 1, {}});
  AgentSpec a;
  a.x = 10;
  a.y = 5;
  a.vx = 1;
  a.pref_speed = 1;
  a.max_speed = 1;
  a.goal = 0;
  w.insert(a);
  w.apply_pending();
  SteerBench sb(0.1, true);
  sb.start(w);
  // Move the agent by hand: 1 m/s along x for 20 ticks, then 2 m/s for 10.
  AgentTable& t = w.agents_for_tick();
  TickMetrics m;
  for (int k = 0; k < 30; ++k) {
    t.x[0] += k < 20 ? 0.1 : 0.2;
    sb.tick(w, m);
  }
  const AgentScore& s = sb.scores()[0];
  EXPECT_NEAR(s.time, 3.0, 1e-9);
  EXPECT_NEAR(s.path_length, 4.0, 1e-9);
  EXPECT_NEAR(s.energy, 20 * 0.5 * 1 + 10 * 0.5 * 4, 1e-6);
  // One change of velocity by 1 m/s in one tick of 0.1 s: 10 m/s^2.
  EXPECT_NEAR(s.acceleration, 10, 1e-6);
  EXPECT_EQ(s.collisions, 0u);
  const SteerBenchTotals tot = sb.totals();
  EXPECT_NEAR(tot.composite01, s.time + s.energy, 1e-9);
  EXPECT_NEAR(tot.composite02, s.time + s.energy + s.acceleration, 1e-9);
}

// An agent that arrives in a tick is closed in it, and that tick is not counted: by hand, on one
// thread and on two (the row that arrives goes to the one-thread pass; the others stay open).
TEST(SteerBench, AnArrivalIsClosedInItsTickWithoutCountingIt) {
  for (int threads : {1, 2}) {
    World w(Bounds{0, 0, 100, 10});
    w.add_goal({"g", 90, 5, 0.5, 1, {}});
    for (double y : {3.0, 7.0}) {
      AgentSpec a;
      a.x = 10;
      a.y = y;
      a.goal = 0;
      w.insert(a);
    }
    w.apply_pending();
    SteerBench sb(0.1, false);
    sb.start(w);
    Executor ex(threads);
    AgentTable& t = w.agents_for_tick();
    TickMetrics m;
    for (int k = 1; k <= 5; ++k) {
      t.x[0] += 0.1;
      t.x[1] += 0.1;
      if (k == 3) t.state[0] = AgentState::arrived;
      sb.tick(w, m, &ex);
    }
    const std::vector<AgentScore>& s = sb.scores();
    ASSERT_EQ(s.size(), 2u);
    EXPECT_TRUE(s[0].arrived);
    EXPECT_NEAR(s[0].time, 0.2, 1e-12);  // ticks 1 and 2
    EXPECT_NEAR(s[0].path_length, 0.2, 1e-12);
    EXPECT_FALSE(s[1].arrived);
    EXPECT_NEAR(s[1].time, 0.5, 1e-12);
  }
}

TEST(SteerBench, CollisionEpisodesCountOncePerAgentAndEpisode) {
  World w(Bounds{0, 0, 100, 100});
  w.add_goal({"g", 90, 50, 0.5, 1, {}});
  for (double x : {10.0, 11.0, 30.0}) {
    AgentSpec a;
    a.x = x;
    a.y = 50;
    a.radius = 0.5;
    a.goal = 0;
    w.insert(a);
  }
  w.apply_pending();
  SteerBench sb(0.1, true);
  sb.start(w);
  AgentTable& t = w.agents_for_tick();
  TickMetrics m;
  m.overlapping_pairs = 1;  // tells the collector to look
  // Overlap agents 0 and 1 by 0.2 m for three ticks, apart for one, overlap again; agent 2
  // touches the wall at x = 100 - 0.4 (penetration 0.1 m) once.
  const double gaps[] = {0.8, 0.8, 0.8, 1.2, 0.8, 1.0005};
  for (double g : gaps) {
    t.x[1] = t.x[0] + g;
    t.x[2] = g == 1.2 ? 99.6 : 30;
    sb.tick(w, m);
  }
  EXPECT_EQ(sb.scores()[0].collisions, 2u);  // two episodes
  EXPECT_EQ(sb.scores()[1].collisions, 2u);
  EXPECT_EQ(sb.scores()[2].collisions, 1u);  // the wall
  EXPECT_EQ(sb.totals().collisions, 5u);
}

// Among many obstacles (hundreds of circles, triangles and boxes, some inside others, agents
// walking into and out of them), the collision episodes with obstacles are those of the naive
// test of every agent against every obstacle, tick by tick.
TEST(SteerBench, ObstacleCollisionsAmongManyObstaclesAreTheNaiveCount) {
  World w(Bounds{0, 0, 100, 100});
  w.add_goal({"g", 99, 50, 0.5, 1, {}});
  for (int i = 0; i < 40; ++i)  // a lattice 2.4 m apart: no two agents ever touch
    for (int j = 0; j < 40; ++j) {
      AgentSpec a;
      a.x = 2 + 2.4 * i;
      a.y = 2 + 2.4 * j;
      a.radius = 0.3;
      a.goal = 0;
      w.insert(a);
    }
  w.apply_pending();
  Rng rng(7);
  for (int o = 0; o < 300; ++o) {
    const double x = rng.uniform(0, 100), y = rng.uniform(0, 100), s = rng.uniform(0.1, 2);
    if (o % 3 == 0)
      w.add_obstacle(CircleObstacle{x, y, s, 1});
    else if (o % 3 == 1)
      w.add_obstacle(PolygonObstacle{{{x, y}, {x + s, y}, {x, y + s}}, 1});
    else
      w.add_obstacle(PolygonObstacle{{{x, y}, {x + s, y}, {x + s, y + 0.3}, {x, y + 0.3}}, 1});
  }
  SteerBench sb(0.1, true);
  sb.start(w);
  AgentTable& t = w.agents_for_tick();
  const std::vector<double> x0 = t.x, y0 = t.y;
  TickMetrics m;
  m.obstacle_overlaps = 1;                    // tells the collector to look
  const auto touching = [&](std::size_t i) {  // SteerSuite's penetration over 1 mm, naively
    std::vector<std::size_t> out;
    const double x = t.x[i], y = t.y[i], r = t.radius[i];
    const auto circles = w.circles();
    for (std::size_t k = 0; k < circles.size(); ++k)
      if (r + circles[k].radius - std::hypot(circles[k].x - x, circles[k].y - y) > 0.001)
        out.push_back(k);
    for (std::size_t k = 0; k < w.polygons().size(); ++k) {
      const auto& v = w.polygons()[k].vertices;
      const double pen = point_in_polygon(v, x, y) ? r : r - std::sqrt(dist2_to_boundary(v, x, y));
      if (pen > 0.001) out.push_back(circles.size() + k);
    }
    return out;
  };
  std::vector<std::vector<std::size_t>> before(t.size());
  std::vector<std::size_t> episodes(t.size(), 0);
  std::size_t all = 0;
  for (int tick = 0; tick < 12; ++tick) {
    for (std::size_t i = 0; i < t.size(); ++i) {
      t.x[i] = x0[i] + rng.uniform(-0.5, 0.5);
      t.y[i] = y0[i] + rng.uniform(-0.5, 0.5);
      std::vector<std::size_t> now = touching(i);
      for (std::size_t k : now)
        episodes[i] += std::find(before[i].begin(), before[i].end(), k) == before[i].end();
      before[i] = std::move(now);
    }
    sb.tick(w, m);
  }
  const std::vector<AgentScore>& got = sb.scores();
  ASSERT_EQ(got.size(), t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_EQ(got[i].collisions, episodes[i]) << "agent " << i;
    all += episodes[i];
  }
  EXPECT_GT(all, 200u);  // many episodes to compare
}

// The tracks follow agents, not rows: the same walks give the same scores, bit for bit, whether
// the table keeps its rows in place or shuffles them every few ticks (as the curve order does,
// after which the tracks are laid out again in row order), with agents arriving (in the very
// ticks the rows are shuffled, so that a row finds its track by id and closes it at once) and
// leaving on the way, and the scores read in the middle of the run.
TEST(SteerBench, ScoresDoNotDependOnTheRowOrder) {
  auto make = [] {
    World w(Bounds{0, 0, 100, 100});
    w.add_goal({"g", 90, 50, 0.5, 1, {}});
    Rng rng(5);
    add_walkers(w, rng, 300);
    return w;
  };
  World still = make(), shuffled = make();
  SteerBench a(0.1, false), b(0.1, false);
  a.start(still);
  b.start(shuffled);
  Rng order_rng(9);
  TickMetrics m;
  for (int tick = 1; tick <= 60; ++tick) {
    for (World* w : {&still, &shuffled}) {
      AgentTable& t = w->agents_for_tick();
      for (std::size_t i = 0; i < t.size(); ++i) {  // each agent's own walk, from its id
        Rng walk = Rng::stream(static_cast<uint64_t>(tick), t.id[i]);
        t.x[i] += walk.uniform(-0.1, 0.1);
        t.y[i] += walk.uniform(-0.1, 0.1);
      }
    }
    if (tick % 5 == 0) {  // some arrive: the same agents in both
      for (World* w : {&still, &shuffled}) {
        AgentTable& t = w->agents_for_tick();
        for (std::size_t i = 0; i < t.size(); ++i)
          if ((t.id[i] ^ static_cast<uint64_t>(tick)) % 13 == 0) t.state[i] = AgentState::arrived;
      }
    }
    if (tick % 7 == 0) {  // some leave: the same agents in both
      for (World* w : {&still, &shuffled}) {
        std::vector<std::size_t> rows;
        const AgentTable& t = w->agents();
        for (std::size_t i = 0; i < t.size(); ++i)
          if ((t.id[i] ^ static_cast<uint64_t>(tick)) % 11 == 0) rows.push_back(i);
        w->remove_rows(rows);
      }
    }
    if (tick % 5 == 0) {
      std::vector<uint32_t> order(shuffled.agents().size());
      std::iota(order.begin(), order.end(), 0u);
      for (std::size_t i = order.size(); i > 1; --i)
        std::swap(order[i - 1], order[order_rng.below(i)]);
      shuffled.permute_rows(order);
    }
    a.tick(still, m);
    b.tick(shuffled, m);
    if (tick % 13 == 0) {
      ASSERT_EQ(a.scores().size(), b.scores().size());
    }
  }
  ASSERT_EQ(a.scores().size(), b.scores().size());
  expect_same_scores(a, b);
  std::size_t closed = 0;
  for (std::size_t k = 0; k < a.scores().size(); ++k) {
    closed += a.scores()[k].arrived;
  }
  EXPECT_GT(closed, 20u);  // agents did leave
  EXPECT_LT(closed, a.scores().size());
  EXPECT_GT(a.totals().avg_path, 1.0);  // the walks were measured
}

// The per-row pass on threads gives the scores of one thread, bit for bit, and the same saved
// state, through ticks in which agents walk, arrive (closed in their tick), leave, enter and are
// reordered, on enough rows for several chunks.
TEST(SteerBench, ThreadsScoreAsOneThread) {
  World w(Bounds{0, 0, 100, 100});
  w.add_goal({"g", 50, 50, 0.5, 1, {}});
  Rng rng(13);
  add_walkers(w, rng, 20000);
  SteerBench one(0.1, false), two(0.1, false), three(0.1, false);
  Executor ex2(2), ex3(3);
  for (SteerBench* s : {&one, &two, &three}) s->start(w);
  Rng order_rng(17);
  TickMetrics m;
  for (int tick = 1; tick <= 30; ++tick) {
    AgentTable& t = w.agents_for_tick();
    for (std::size_t i = 0; i < t.size(); ++i) {
      Rng walk = Rng::stream(static_cast<uint64_t>(tick), t.id[i]);
      t.x[i] += walk.uniform(-0.1, 0.1);
      t.y[i] += walk.uniform(-0.1, 0.1);
      if (walk.below(400) == 0) t.state[i] = AgentState::arrived;  // arrives in this tick
    }
    if (tick % 4 == 0) {  // the arrived leave, a few others too; some enter
      std::vector<std::size_t> rows;
      for (std::size_t i = 0; i < t.size(); ++i)
        if (t.state[i] == AgentState::arrived || (t.id[i] ^ static_cast<uint64_t>(tick)) % 97 == 0)
          rows.push_back(i);
      w.remove_rows(rows);
      add_walkers(w, rng, 300);
    }
    if (tick % 5 == 0) {  // a reorder: every row's slot goes stale at once
      std::vector<uint32_t> order(w.agents().size());
      std::iota(order.begin(), order.end(), 0u);
      for (std::size_t i = order.size(); i > 1; --i)
        std::swap(order[i - 1], order[order_rng.below(i)]);
      w.permute_rows(order);
    }
    one.tick(w, m);
    two.tick(w, m, &ex2);
    three.tick(w, m, &ex3);
  }
  EXPECT_GT(one.scores().size(), 22000u);  // agents did enter
  std::size_t closed = 0;
  for (const AgentScore& a : one.scores()) closed += a.arrived;
  EXPECT_GT(closed, 1000u);  // and arrive
  for (const SteerBench* s : {&two, &three}) {
    expect_same_scores(one, *s);
    ByteWriter a, b;
    one.save(a);
    s->save(b);
    EXPECT_EQ(a.take(), b.take());
  }
}

// A run saved halfway and restored into a fresh SteerBench ends with the same scores, bit for bit,
// and the same saved bytes as the run that went on (agents leave, enter and are reordered on the
// way); checkpoints whose parts disagree are refused with the input error.
TEST(SteerBench, ARestoredRunEndsAsTheUninterruptedOneAndBadCheckpointsAreRefused) {
  World w(Bounds{0, 0, 100, 100});
  w.add_goal({"g", 50, 50, 0.5, 1, {}});
  Rng rng(11);
  add_walkers(w, rng, 200);
  SteerBench a(0.1, false);
  a.start(w);
  std::unique_ptr<SteerBench> b;
  TickMetrics m;
  for (int tick = 1; tick <= 40; ++tick) {
    AgentTable& t = w.agents_for_tick();
    for (std::size_t i = 0; i < t.size(); ++i) {
      Rng walk = Rng::stream(static_cast<uint64_t>(tick), t.id[i]);
      t.x[i] += walk.uniform(-0.1, 0.1);
    }
    if (tick % 6 == 0) {  // some leave, some enter
      std::vector<std::size_t> rows;
      for (std::size_t i = 0; i < t.size(); ++i)
        if ((t.id[i] ^ static_cast<uint64_t>(tick)) % 9 == 0) rows.push_back(i);
      w.remove_rows(rows);
      add_walkers(w, rng, 7);
    }
    if (tick % 5 == 0) {
      std::vector<uint32_t> order(w.agents().size());
      std::iota(order.begin(), order.end(), 0u);
      std::reverse(order.begin(), order.end());
      w.permute_rows(order);
    }
    a.tick(w, m);
    if (b) b->tick(w, m);
    if (tick == 17) {
      ByteWriter out;
      a.save(out);
      const std::string bytes = out.take();
      b = std::make_unique<SteerBench>(0.1, false);
      ByteReader in(bytes, "test");
      b->restore(in);
      EXPECT_TRUE(in.at_end());
    }
  }
  ASSERT_EQ(a.scores().size(), b->scores().size());
  EXPECT_GT(a.scores().size(), 220u);  // agents did enter
  expect_same_scores(a, *b);
  ByteWriter sa, sb;
  a.save(sa);
  b->save(sb);
  EXPECT_EQ(sa.take(), sb.take());

  // Hand-made checkpoints: scores (ids), tracks (id, score index), the ids measured, and the
  // one id whose score says it arrived.
  auto checkpoint = [](std::vector<uint64_t> scores,
                       std::vector<std::pair<uint64_t, uint64_t>> tracks,
                       std::vector<uint64_t> known, uint64_t arrived = UINT64_MAX) {
    ByteWriter out;
    out.u64(3);
    out.u64(scores.size());
    for (uint64_t id : scores) {
      out.u64(id);
      out.u64(0);
      for (int v = 0; v < 4; ++v) out.f64(0);
      out.u8(id == arrived);
    }
    out.u64(tracks.size());
    for (const auto& [id, score] : tracks) {
      out.u64(id);
      out.u64(score);
      for (int v = 0; v < 4; ++v) out.f64(0);
      out.u8(0);
      out.u64(3);
    }
    out.vec(known);
    out.u64(0);
    out.u64(0);
    return out.take();
  };
  auto refused = [](const std::string& bytes) {
    SteerBench s(0.1, false);
    ByteReader in(bytes, "test");
    try {
      s.restore(in);
    } catch (const Error& e) {
      return e.kind() == Error::Kind::input;
    }
    return false;
  };
  EXPECT_FALSE(refused(checkpoint({5, 6}, {{6, 1}}, {5, 6})));  // the well-formed one
  EXPECT_TRUE(refused(checkpoint({5, 6}, {{6, 0}}, {5, 6})));   // a track under another's score
  EXPECT_TRUE(refused(checkpoint({5, 6}, {{6, 2}}, {5, 6})));   // a score that is not there
  EXPECT_TRUE(refused(checkpoint({5, 6}, {{6, 1}, {6, 1}}, {5, 6})));  // a track twice
  EXPECT_TRUE(refused(checkpoint({5, 5}, {}, {5, 5})));                // an agent scored twice
  EXPECT_TRUE(refused(checkpoint({5, 6}, {}, {5, 7})));                // other ids measured
  EXPECT_TRUE(refused(checkpoint({5, 6}, {}, {5})));
  EXPECT_FALSE(refused(checkpoint({5, 6}, {{6, 1}}, {5, 6}, 5)));  // 5 arrived, 6 walks on
  EXPECT_TRUE(refused(checkpoint({5, 6}, {{6, 1}}, {5, 6}, 6)));   // a track of one that arrived
}

}  // namespace
}  // namespace crowddb::metrics
