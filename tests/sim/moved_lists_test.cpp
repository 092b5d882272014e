// The neighbour lists after the tick's move (sim/moved_lists.hpp) against the naive neighbour
// query on the rows as they are now: the row renumbering against World::remove_rows, the lists'
// answer where they are sure, the scan of every row, and both put together.
#include "sim/moved_lists.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "query/naive_paths.hpp"
#include "sim/stalemate.hpp"
#include "util/rng.hpp"

namespace crowddb::sim {
namespace {

World lists_test_crowd(std::size_t n, double side, Rng& rng, bool lattice) {
  World w{Bounds{-50, -50, side + 50, side + 50}};
  w.add_goal({"G", side / 2, side / 2, 0.5, 1, {}});
  for (std::size_t i = 0; i < n; ++i) {
    AgentSpec a;
    if (lattice) {  // equal distances everywhere: ties broken by id
      const auto per_row = static_cast<std::size_t>(std::ceil(std::sqrt(double(n))));
      a.x = double(i % per_row) * side / double(per_row);
      a.y = double(i / per_row) * side / double(per_row);
    } else {
      a.x = rng.uniform(0, side);
      a.y = rng.uniform(0, side);
    }
    a.radius = 0.25;
    a.goal = 0;
    w.insert(a);
  }
  w.apply_pending();
  return w;
}

NeighbourLists naive_lists(const AgentTable& t, std::span<const uint32_t> rows, double range,
                           uint32_t k) {
  NeighbourNaive path;
  Executor ex{1};
  QueryStats stats;
  NeighbourLists out;
  path.run(DiscView::of(t), rows, range, k, out, ex, stats);
  return out;
}

std::vector<uint32_t> rows_listed(const NeighbourLists& l, std::size_t q) {
  const auto s = l.rows_of(q);
  return {s.begin(), s.end()};
}

TEST(RowRenumbering, FollowsWorldRemoveRows) {
  Rng rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = 1 + rng.below(40);
    World w = lists_test_crowd(n, 20, rng, false);
    std::vector<uint64_t> id_before(w.agents().id.begin(), w.agents().id.end());
    std::vector<std::size_t> removed;
    const int mode = trial % 4;
    for (std::size_t r = 0; r < n; ++r) {
      const bool take = mode == 0   ? rng.below(4) == 0
                        : mode == 1 ? r + 3 >= n  // the last rows
                        : mode == 2 ? r < 5       // the first rows
                                    : rng.below(2) == 0;
      if (take) removed.push_back(r);
    }
    for (std::size_t a = removed.size(); a > 1; --a)  // any order
      std::swap(removed[a - 1], removed[rng.below(a)]);
    const RowRenumbering rn(n, removed);
    w.remove_rows(removed);
    const AgentTable& t = w.agents();
    ASSERT_EQ(rn.now(), t.size());
    ASSERT_EQ(rn.before(), n);
    for (uint32_t b = 0; b < n; ++b) {
      const bool gone = std::find(removed.begin(), removed.end(), b) != removed.end();
      const uint32_t now = rn.now_of(b);
      if (gone) {
        EXPECT_EQ(now, RowRenumbering::kGone) << "trial " << trial << " row " << b;
        continue;
      }
      ASSERT_LT(now, t.size()) << "trial " << trial << " row " << b;
      EXPECT_EQ(t.id[now], id_before[b]);
      EXPECT_EQ(rn.before_of(now), b);
    }
  }
}

// A table, its lists before a move, the move and the removals; then the table now. Returns the
// move, whose positions before point into `x0`, `y0`.
struct MovedCrowd {
  World w;
  std::vector<double> x0, y0;
  NeighbourLists before;
  TickMove move;
};

MovedCrowd make_moved_crowd(std::size_t n, double side, double step, Rng& rng, bool lattice,
                            double lists_range, uint32_t lists_k) {
  MovedCrowd m{lists_test_crowd(n, side, rng, lattice), {}, {}, {}, {}};
  AgentTable& t = m.w.agents_for_tick();
  m.x0.assign(t.x.begin(), t.x.end());
  m.y0.assign(t.y.begin(), t.y.end());
  m.before = naive_lists(t, {}, lists_range, lists_k);
  double move_max = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    // Some stand, some take the full step (the bound is met with equality), the rest between.
    const int kind = static_cast<int>(rng.below(3));
    const double len = kind == 0 ? 0 : kind == 1 ? step : rng.uniform(0, step);
    const double a = rng.uniform(0, 2 * std::numbers::pi);
    t.x[i] += len * std::cos(a);
    t.y[i] += len * std::sin(a);
    const double dx = t.x[i] - m.x0[i], dy = t.y[i] - m.y0[i];
    move_max = std::max(move_max, std::sqrt(dx * dx + dy * dy));
  }
  std::vector<std::size_t> removed;
  for (std::size_t r = 0; r < t.size(); ++r)
    if (rng.below(8) == 0) removed.push_back(r);
  m.move = {NearLists{&m.before, lists_range, lists_k}, m.x0, m.y0, move_max,
            RowRenumbering(t.size(), removed)};
  m.w.remove_rows(removed);
  return m;
}

TEST(ListsAfterMove, SureAnswersAreTheNaiveQuerysAndTheRestFillsIn) {
  Rng rng(11);
  std::size_t sure = 0, unsure_total = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const bool lattice = trial % 5 == 0;
    const std::size_t n = 50 + rng.below(400);
    // From sparse (everyone sure) to a jam (many not), and steps up to a good part of the range.
    const double side = std::sqrt(double(n) / rng.uniform(0.2, 3.0));
    const double step = rng.uniform(0, 0.6);
    const double range = rng.uniform(0.3, 1.6);
    const uint32_t k = 1 + static_cast<uint32_t>(rng.below(8));
    MovedCrowd m = make_moved_crowd(n, side, step, rng, lattice, 5, 10);
    const AgentTable& t = m.w.agents();
    std::vector<uint32_t> queries;
    for (uint32_t i = 0; i < t.size(); ++i)
      if (rng.below(3) != 0) queries.push_back(i);
    NeighbourLists got;
    std::vector<uint32_t> unsure;
    Executor ex{1 + trial % 2};
    lists_after_move(t, m.move, queries, range, k, got, unsure, ex);
    const NeighbourLists want = naive_lists(t, queries, range, k);
    ASSERT_EQ(got.queries(), queries.size());
    std::size_t u = 0;
    for (std::size_t q = 0; q < queries.size(); ++q) {
      if (u < unsure.size() && unsure[u] == q) {
        EXPECT_TRUE(got.rows_of(q).empty());
        ++u;
        continue;
      }
      EXPECT_EQ(rows_listed(got, q), rows_listed(want, q))
          << "trial " << trial << " query row " << queries[q];
    }
    ASSERT_EQ(u, unsure.size()) << "unsure places out of order";
    sure += queries.size() - unsure.size();
    unsure_total += unsure.size();
    // The unsure ones answered by the scan, put in their places: every list the naive one.
    std::vector<uint32_t> rows;
    for (uint32_t a : unsure) rows.push_back(queries[a]);
    NeighbourLists answers;
    scan_rows(t, rows, range, k, answers, ex);
    fill_unsure(got, unsure, answers);
    for (std::size_t q = 0; q < queries.size(); ++q)
      ASSERT_EQ(rows_listed(got, q), rows_listed(want, q))
          << "trial " << trial << " query row " << queries[q];
    // The squared distances too, as the query gives them (the idle groups read them).
    EXPECT_EQ(got.dist2, want.dist2) << "trial " << trial;
  }
  // Both kinds were met: the test says something about each.
  EXPECT_GT(sure, 1000u);
  EXPECT_GT(unsure_total, 100u);
}

// In a jam the model's lists (10 within 5 m) reach less far than the range asked plus the moves,
// and the k nearest listed are the answer only where the k-th of them is nearer than anyone
// unlisted can have come. Dense crowds (every third a lattice: ties everywhere) whose rows stand,
// take the full step or less, steps of at most 5 cm on even trials and up to 30 cm on odd ones,
// and every fifth with nobody moving (ties at the list's bound itself): the answers the lists
// give for such rows are the naive query's, rows and squared distances.
TEST(ListsAfterMove, InAJamTheKthListedBoundsTheRest) {
  Rng rng(23);
  std::size_t by_kth = 0, unsure_total = 0;
  for (int trial = 0; trial < 45; ++trial) {
    const bool lattice = trial % 3 == 0;
    const std::size_t n = 100 + rng.below(400);
    const double side = std::sqrt(double(n) / rng.uniform(2.5, 5.0));
    const double step = trial % 5 == 4   ? 0.0
                        : trial % 2 == 0 ? rng.uniform(0, 0.05)
                                         : rng.uniform(0.05, 0.3);
    const double range = rng.uniform(0.8, 1.6);
    const uint32_t k = 1 + static_cast<uint32_t>(rng.below(9));
    MovedCrowd m = make_moved_crowd(n, side, step, rng, lattice, 5, 10);
    const AgentTable& t = m.w.agents();
    std::vector<uint32_t> queries(t.size());
    for (uint32_t i = 0; i < t.size(); ++i) queries[i] = i;
    NeighbourLists got;
    std::vector<uint32_t> unsure;
    Executor ex{1 + trial % 2};
    lists_after_move(t, m.move, queries, range, k, got, unsure, ex);
    const NeighbourLists want = naive_lists(t, queries, range, k);
    std::size_t u = 0;
    for (std::size_t q = 0; q < queries.size(); ++q) {
      if (u < unsure.size() && unsure[u] == q) {
        ++u;
        continue;
      }
      ASSERT_EQ(rows_listed(got, q), rows_listed(want, q))
          << "trial " << trial << " query row " << queries[q];
      const std::vector<double> got_d2(got.dist2.begin() + got.offset[q],
                                       got.dist2.begin() + got.offset[q + 1]);
      const std::vector<double> want_d2(want.dist2.begin() + want.offset[q],
                                        want.dist2.begin() + want.offset[q + 1]);
      ASSERT_EQ(got_d2, want_d2) << "trial " << trial << " query row " << queries[q];
      // Sure although the list's bound falls short of the range plus the moves?
      const uint32_t b = m.move.rows.before_of(queries[q]);
      const auto listed = m.before.rows_of(b);
      if (listed.size() < 10) continue;
      const double bx = m.x0[listed.back()] - m.x0[b], by = m.y0[listed.back()] - m.y0[b];
      const double mx = t.x[queries[q]] - m.x0[b], my = t.y[queries[q]] - m.y0[b];
      const double need = range + std::sqrt(mx * mx + my * my) + m.move.move_max;
      if (std::sqrt(bx * bx + by * by) < need) ++by_kth;
    }
    ASSERT_EQ(u, unsure.size()) << "unsure places out of order";
    unsure_total += unsure.size();
  }
  EXPECT_GT(by_kth, 2000u);        // the k-th's bound answered these
  EXPECT_GT(unsure_total, 1000u);  // and left others, where it is not sure
}

TEST(ListsAfterMove, EverythingUnsureWithoutUsableLists) {
  Rng rng(3);
  MovedCrowd m = make_moved_crowd(100, 10, 0.1, rng, false, 5, 10);
  const AgentTable& t = m.w.agents();
  const std::vector<uint32_t> queries = {0, 5, 9};
  NeighbourLists got;
  std::vector<uint32_t> unsure;
  Executor ex{1};
  TickMove none = m.move;
  none.lists = {};
  lists_after_move(t, none, queries, 1, 6, got, unsure, ex);
  EXPECT_EQ(unsure, (std::vector<uint32_t>{0, 1, 2}));
  TickMove nan = m.move;
  nan.move_max = NAN;
  lists_after_move(t, nan, queries, 1, 6, got, unsure, ex);
  EXPECT_EQ(unsure.size(), 3u);
  TickMove short_x = m.move;
  short_x.x = short_x.x.first(10);  // positions of another table
  lists_after_move(t, short_x, queries, 1, 6, got, unsure, ex);
  EXPECT_EQ(unsure.size(), 3u);
}

TEST(LargestMove, IsTheFarthestMoveAndKeepsANaN) {
  Rng rng(23);
  for (std::size_t n : {0u, 1u, 7u, 4096u, 10001u}) {
    std::vector<double> x0(n), y0(n), x1(n), y1(n);
    double want = 0;
    for (std::size_t i = 0; i < n; ++i) {
      x0[i] = rng.uniform(-100, 100);
      y0[i] = rng.uniform(-100, 100);
      x1[i] = x0[i] + rng.uniform(-0.2, 0.2);
      y1[i] = y0[i] + rng.uniform(-0.2, 0.2);
      const double dx = x1[i] - x0[i], dy = y1[i] - y0[i];
      want = std::max(want, dx * dx + dy * dy);
    }
    for (int threads : {1, 2}) {
      Executor ex{threads};
      EXPECT_EQ(largest_move(x0, y0, x1, y1, ex), std::sqrt(want)) << n;
      if (n == 0) continue;
      // A NaN anywhere, first, in the middle or last, whatever comes after it.
      for (std::size_t at : {std::size_t{0}, n / 2, n - 1}) {
        const double keep = x1[at];
        x1[at] = NAN;
        EXPECT_TRUE(std::isnan(largest_move(x0, y0, x1, y1, ex))) << n << " at " << at;
        x1[at] = keep;
      }
    }
  }
}

// neighbours_after_move: all three ways give the naive query's lists (and squared distances);
// without the move the path answers all.
TEST(ListsAfterMove, NeighboursAfterMoveAreTheQuerysEveryWay) {
  Rng rng(29);
  AnsweredBy total;
  for (int trial = 0; trial < 30; ++trial) {
    const std::size_t n = 100 + rng.below(600);
    const double density = trial % 3 == 0 ? 0.4 : trial % 3 == 1 ? 2.0 : 3.5;
    MovedCrowd m = make_moved_crowd(n, std::sqrt(double(n) / density), 0.15, rng, false, 5, 10);
    const AgentTable& t = m.w.agents();
    std::vector<uint32_t> queries;
    const uint32_t every = trial % 2 == 0 ? 1 : 9;  // many rows, or a few
    for (uint32_t i = 0; i < t.size(); i += every) queries.push_back(i);
    Executor ex{1 + trial % 2};
    QueryStats stats;
    auto path = neighbour_method("grid", t.size()).make();
    NeighbourLists got;
    got.with_dist2 = trial % 4 < 2;
    const AnsweredBy by = neighbours_after_move(t, &m.move, queries, 1.1, 6, *path, got, ex, stats);
    EXPECT_EQ(by.lists + by.scan + by.query, queries.size());
    const NeighbourLists want = naive_lists(t, queries, 1.1, 6);
    EXPECT_EQ(got.offset, want.offset) << "trial " << trial;
    EXPECT_EQ(got.row, want.row) << "trial " << trial;
    if (got.with_dist2) {
      EXPECT_EQ(got.dist2, want.dist2) << "trial " << trial;
    }
    total.lists += by.lists;
    total.scan += by.scan;
    total.query += by.query;
    NeighbourLists by_path;
    const AnsweredBy none =
        neighbours_after_move(t, nullptr, queries, 1.1, 6, *path, by_path, ex, stats);
    EXPECT_EQ(none.query, queries.size());
    EXPECT_EQ(by_path.row, want.row);
  }
  EXPECT_GT(total.lists, 0u);
  EXPECT_GT(total.scan, 0u);
  EXPECT_GT(total.query, 0u);
}

TEST(ScanRows, AsTheNaiveQueryAcrossBlocksAndTails) {
  Rng rng(5);
  // n = 100: a lattice of spacing 1, so range 1 meets neighbours at exactly the range (not within).
  for (std::size_t n : {1u, 3u, 4u, 5u, 97u, 100u, 4096u, 4099u, 9001u}) {
    World w = lists_test_crowd(n, std::sqrt(double(n)), rng, n == 100);
    const AgentTable& t = w.agents();
    std::vector<uint32_t> rows;
    for (uint32_t i = 0; i < t.size(); i += 1 + static_cast<uint32_t>(n / 7)) rows.push_back(i);
    rows.push_back(static_cast<uint32_t>(t.size() - 1));
    Executor ex{2};
    for (double range : {0.5, 1.0, 3.0})
      for (uint32_t k : {1u, 6u, 40u}) {
        NeighbourLists got;
        scan_rows(t, rows, range, k, got, ex);
        const NeighbourLists want = naive_lists(t, rows, range, k);
        ASSERT_EQ(got.row, want.row) << "n " << n << " range " << range << " k " << k;
        ASSERT_EQ(got.offset, want.offset);
        ASSERT_EQ(got.dist2, want.dist2);
      }
  }
}

// The stalemate stage given the tick's move against the same stage asking its neighbour query for
// every row looked at: the same actions, directions, clocks and counts, in crowds from loose (the
// lists answer all) to jammed (a few rows scanned, or many left to the query).
TEST(ListsAfterMove, StalematesActAsWithTheQueryAlone) {
  Rng rng(19);
  std::size_t by_lists = 0, by_scan = 0, by_query = 0, acted = 0;
  for (int trial = 0; trial < 24; ++trial) {
    const std::size_t n = 100 + rng.below(500);
    const double density = trial % 4 == 0 ? 0.5 : trial % 4 == 1 ? 1.0 : trial % 4 == 2 ? 1.8 : 3.0;
    MovedCrowd m = make_moved_crowd(n, std::sqrt(double(n) / density), 0.13, rng, false, 5, 10);
    World& w = m.w;
    w.add_goal({"far", -40, -40, 0.5, 1, {}});
    SimConfig cfg;
    AgentTable& t = w.agents_for_tick();
    for (std::size_t i = 0; i < t.size(); ++i) {
      t.goal[i] = static_cast<uint32_t>(rng.below(2));
      w.refresh_target(i);
      t.pref_speed[i] = t.max_speed[i] = 1.3;
      t.radius[i] = rng.uniform(0.2, 0.3);
      t.progress_best[i] = 0;  // no progress possible: the clock runs
      t.stall_ticks[i] = static_cast<uint32_t>(cfg.ticks_for(rng.uniform(0, 6)));
    }
    World with_lists = w, query_only = w;
    Executor ex{2};
    QueryStats s1, s2;
    auto p1 = neighbour_method("grid", t.size()).make();
    auto p2 = neighbour_method("grid", t.size()).make();
    const StallCounts a = stalemates(with_lists, cfg, 500, *p1, ex, s1, nullptr, &m.move);
    const StallCounts b = stalemates(query_only, cfg, 500, *p2, ex, s2);
    EXPECT_EQ(a.stalled, b.stalled) << "trial " << trial;
    EXPECT_EQ(a.queueing, b.queueing);
    EXPECT_EQ(a.yielding, b.yielding);
    EXPECT_EQ(a.sidestepping, b.sidestepping);
    EXPECT_EQ(a.making_way, b.making_way);
    EXPECT_EQ(a.head_on, b.head_on);
    const AgentTable &ta = with_lists.agents(), &tb = query_only.agents();
    EXPECT_EQ(ta.stall_action, tb.stall_action) << "trial " << trial;
    EXPECT_EQ(ta.stall_dir_x, tb.stall_dir_x);
    EXPECT_EQ(ta.stall_dir_y, tb.stall_dir_y);
    EXPECT_EQ(ta.stall_until, tb.stall_until);
    EXPECT_EQ(ta.stall_ticks, tb.stall_ticks);
    EXPECT_EQ(a.by_lists + a.by_scan + a.by_query, b.by_query);
    acted += a.yielding + a.sidestepping;
    by_lists += a.by_lists;
    by_scan += a.by_scan;
    by_query += a.by_query;
  }
  EXPECT_GT(by_lists, 0u);
  EXPECT_GT(by_scan, 0u);
  EXPECT_GT(by_query, 0u);
  EXPECT_GT(acted, 100u);  // the blockers found decide actions
}

}  // namespace
}  // namespace crowddb::sim
