#include "index/neighbour_grid.hpp"

#include <gtest/gtest.h>

#include "query/naive_paths.hpp"
#include "support/random_tables.hpp"
#include "util/rng.hpp"

namespace crowddb::index {
namespace {

NeighbourLists run(NeighbourPath& p, const DiscView& d, double range, uint32_t k,
                   std::span<const uint32_t> q = {}, int threads = 1, bool with_dist2 = true) {
  Executor ex(threads);
  QueryStats st;
  NeighbourLists out;
  out.with_dist2 = with_dist2;
  p.run(d, q, range, k, out, ex, st);
  return out;
}

// Removes up to `count` random rows the way the world does (the last row moves into the hole),
// keeping at least 20.
void remove_rows(DiscTable& t, Rng& rng, int count) {
  for (int j = 0; j < count && t.size() > 20; ++j) {
    const std::size_t i = rng.below(t.size());
    for (auto* col : {&t.x, &t.y, &t.vx, &t.vy, &t.radius, &t.charge}) {
      (*col)[i] = col->back();
      col->pop_back();
    }
    t.id[i] = t.id.back();
    t.id.pop_back();
  }
}

// A random order of n rows (order[new row] = old row).
std::vector<uint32_t> shuffled_rows(std::size_t n, Rng& rng) {
  std::vector<uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<uint32_t>(i);
  for (std::size_t i = n; i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);
  return order;
}

DiscTable permuted(const DiscTable& t, std::span<const uint32_t> order) {
  DiscTable p;
  for (uint32_t r : order) p.push_back(t.id[r], t.x[r], t.y[r], t.vx[r], t.vy[r], t.radius[r]);
  return p;
}

void expect_same(const NeighbourLists& a, const NeighbourLists& b) {
  ASSERT_EQ(a.offset, b.offset);
  EXPECT_EQ(a.row, b.row);
  EXPECT_EQ(a.dist2, b.dist2);  // bit for bit
}

// Every table shape of the property tests, every k from "all" to more than the table holds, and
// ranges from below the typical spacing to beyond the world.
TEST(NeighbourGrid, EqualsNaiveOnRandomShapes) {
  Rng rng(5);
  NeighbourNaive naive;
  NeighbourGrid grid;
  for (int c = 0; c < 60; ++c) {
    const std::size_t n = 1 + rng.below(600);
    const double side = rng.uniform(5, 500);
    const DiscTable t = test::random_shape_table(rng, n, side, 100 + static_cast<uint64_t>(c));
    const DiscView d = t.view();
    const double range = side * std::pow(10, rng.uniform(-2.5, 0.5));
    const uint32_t k = rng.below(3) == 0 ? 0 : static_cast<uint32_t>(1 + rng.below(40));
    SCOPED_TRACE("case " + std::to_string(c) + " n " + std::to_string(n) + " k " +
                 std::to_string(k) + " range " + std::to_string(range));
    const NeighbourLists want = run(naive, d, range, k);
    expect_same(run(grid, d, range, k), want);
    expect_same(run(grid, d, range, k, {}, 3), want);  // threads change nothing
    // A subset of query rows, in an arbitrary order.
    std::vector<uint32_t> q;
    for (std::size_t i = 0; i < n; i += 1 + rng.below(5)) q.push_back(static_cast<uint32_t>(i));
    std::reverse(q.begin(), q.end());
    expect_same(run(grid, d, range, k, q), run(naive, d, range, k, q));
  }
}

// Lists asked for without their distances (ORCA recomputes them from the positions): the same
// rows, no distances, for the grid (spatial order with hints, and query order) and the naive
// twin; and every stored distance is the one recomputed from the positions, bit for bit.
TEST(NeighbourGrid, ListsWithoutDistancesAreTheSameLists) {
  Rng rng(17);
  NeighbourNaive naive;
  NeighbourGrid grid;
  for (int c = 0; c < 30; ++c) {
    const std::size_t n = 1 + rng.below(500);
    const double side = rng.uniform(5, 200);
    const DiscTable t = test::random_shape_table(rng, n, side, 300 + static_cast<uint64_t>(c));
    const DiscView d = t.view();
    const double range = side * std::pow(10, rng.uniform(-2, 0.3));
    const uint32_t k = rng.below(4) == 0 ? 0 : static_cast<uint32_t>(1 + rng.below(12));
    SCOPED_TRACE("case " + std::to_string(c) + " n " + std::to_string(n) + " k " +
                 std::to_string(k));
    const NeighbourLists want = run(naive, d, range, k);
    ASSERT_EQ(want.dist2.size(), want.row.size());
    for (std::size_t i = 0; i < want.queries(); ++i)
      for (uint32_t a = want.offset[i]; a < want.offset[i + 1]; ++a) {
        const uint32_t j = want.row[a];
        const double dx = d.x[j] - d.x[i], dy = d.y[j] - d.y[i];
        ASSERT_EQ(want.dist2[a], dx * dx + dy * dy);
      }
    std::vector<uint32_t> q;
    for (std::size_t i = 0; i < n; i += 1 + rng.below(4)) q.push_back(static_cast<uint32_t>(i));
    for (int pass = 0; pass < 2; ++pass) {  // the second pass is seeded with the first's hints
      for (NeighbourPath* path :
           {static_cast<NeighbourPath*>(&grid), static_cast<NeighbourPath*>(&naive)}) {
        const NeighbourLists bare = run(*path, d, range, k, {}, 2, false);
        EXPECT_EQ(bare.offset, want.offset);
        EXPECT_EQ(bare.row, want.row);
        EXPECT_TRUE(bare.dist2.empty());
        const NeighbourLists some = run(*path, d, range, k, q, 1, false);
        const NeighbourLists some_want = run(naive, d, range, k, q);
        EXPECT_EQ(some.offset, some_want.offset);
        EXPECT_EQ(some.row, some_want.row);
        EXPECT_TRUE(some.dist2.empty());
      }
    }
  }
}

// Ties: a square lattice (equal distances everywhere), coincident discs (distance 0), and
// neighbours at exactly the range (excluded: strictly closer only).
TEST(NeighbourGrid, TiesCoincidentPointsAndTheRangeBoundary) {
  DiscTable t;
  for (int i = 0; i < 15; ++i)
    for (int j = 0; j < 15; ++j)
      t.push_back(static_cast<uint64_t>(1000 - 15 * i - j), i * 0.5, j * 0.5, 0, 0, 0.2);
  for (int r = 0; r < 6; ++r) t.push_back(static_cast<uint64_t>(5000 + r), 3.0, 3.0, 0, 0, 0.2);
  NeighbourNaive naive;
  NeighbourGrid grid;
  for (double range : {0.5, 0.50000000001, 1.0, 1.5, 100.0})
    for (uint32_t k : {0u, 1u, 3u, 4u, 5u, 8u, 12u}) {
      SCOPED_TRACE("range " + std::to_string(range) + " k " + std::to_string(k));
      const NeighbourLists want = run(naive, t.view(), range, k);
      expect_same(run(grid, t.view(), range, k), want);
      expect_same(run(grid, t.view(), range, k), want);  // again, seeded with exact hints
    }
  // At range 0.5 the lattice neighbours (0.5 away) are out; only discs at distance 0 are in:
  // the five other coincident discs and the lattice node under them at (3, 3).
  const NeighbourLists at = run(grid, t.view(), 0.5, 0);
  const std::size_t dup = 15 * 15;  // first coincident disc
  EXPECT_EQ(at.offset[dup + 1] - at.offset[dup], 6u);
  EXPECT_EQ(at.offset[1] - at.offset[0], 0u);
}

// A dense knot in a sparse world (a circle swap's middle, with those who arrived standing on
// the far rim): the cells are sized by the mean density (and at most ~4 per disc), so a short
// range (the stalemate stage's blockers) lies within a fraction of a cell, and a cell holds
// dozens of discs. Knot centres anywhere in their cells, ranges from below the spacing to a few
// cells, k from 1 to more than the range holds, every row (then seeded by hints) and subsets.
TEST(NeighbourGrid, ShortRangesInADenseKnotOfASparseWorld) {
  Rng rng(23);
  NeighbourNaive naive;
  NeighbourGrid grid;
  for (int c = 0; c < 40; ++c) {
    DiscTable t;
    const double cx = rng.uniform(-5, 5), cy = rng.uniform(-5, 5), half = rng.uniform(1, 8);
    const std::size_t knot = 50 + rng.below(600);
    for (std::size_t i = 0; i < knot; ++i)
      t.push_back(i, cx + rng.uniform(-half, half), cy + rng.uniform(-half, half), 0, 0, 0.25);
    const std::size_t rim = 10 + rng.below(200);
    for (std::size_t i = 0; i < rim; ++i) {
      const double a = rng.uniform(0, 2 * 3.141592653589793);
      t.push_back(knot + i, 100 * std::cos(a), 100 * std::sin(a), 0, 0, 0.25);
    }
    if (rng.below(2)) build::shuffle_ids(t, 900 + static_cast<uint64_t>(c));
    const DiscView d = t.view();
    const double range = rng.uniform(0.05, 6);
    const uint32_t k = static_cast<uint32_t>(1 + rng.below(12));
    SCOPED_TRACE("case " + std::to_string(c) + " range " + std::to_string(range) + " k " +
                 std::to_string(k));
    expect_same(run(grid, d, range, k), run(naive, d, range, k));
    expect_same(run(grid, d, range, k, {}, 2), run(naive, d, range, k));  // seeded by hints
    std::vector<uint32_t> q;
    for (std::size_t i = 0; i < t.size(); i += 1 + rng.below(3))
      q.push_back(static_cast<uint32_t>(i));
    expect_same(run(grid, d, range, k, q, 2), run(naive, d, range, k, q));
  }
}

// A row with no list of the last call (the first call, a subset's new rows) takes its bound from
// the density of the cells around it, gathers and ranks at once: one visit (no rings) for most
// rows of an even crowd, the naive twin's answer for all of them, and where the crowd is uneven
// (a knot beside empty space: fewer than k within the bound) the usual search.
TEST(NeighbourGrid, RowsWithoutHintsTakeABoundFromTheDensity) {
  NeighbourNaive naive;
  const DiscTable even = build::uniform(4000, {0, 0, 100, 100}, 1.3, 0.25, 0.25, 7);
  std::vector<uint32_t> every_seventh;
  for (uint32_t i = 0; i < even.size(); i += 7) every_seventh.push_back(i);
  for (const std::vector<uint32_t>& q : {std::vector<uint32_t>{}, every_seventh}) {
    NeighbourGrid grid;
    Executor ex(1);
    QueryStats st;
    NeighbourLists got;
    grid.run(even.view(), q, 5, 10, got, ex, st);
    const std::size_t rows = q.empty() ? even.size() : q.size();
    EXPECT_LT(st.nodes_visited, rows * 11 / 10);  // the ring search visits two or more a row
    expect_same(got, run(naive, even.view(), 5, 10, q));
  }
  Rng rng(31);
  for (int c = 0; c < 20; ++c) {
    DiscTable t;
    const std::size_t knot = 30 + rng.below(300);
    for (std::size_t i = 0; i < knot; ++i)  // a tight knot ...
      t.push_back(i, rng.uniform(0, 2), rng.uniform(0, 2), 0, 0, 0.25);
    for (std::size_t i = 0; i < 400; ++i)  // ... beside a sparse field
      t.push_back(knot + i, rng.uniform(0, 60), rng.uniform(0, 60), 0, 0, 0.25);
    const uint32_t k = static_cast<uint32_t>(1 + rng.below(NearestK::kInline));
    const double range = rng.uniform(0.5, 20);
    SCOPED_TRACE("case " + std::to_string(c) + " k " + std::to_string(k));
    NeighbourGrid grid;
    expect_same(run(grid, t.view(), range, k), run(naive, t.view(), range, k));
  }
}

TEST(NeighbourGrid, HugeAndSparseWorlds) {
  NeighbourNaive naive;
  NeighbourGrid grid;
  for (double offset : {0.0, 1e6, -3e9}) {
    DiscTable t = build::uniform(300, {offset, offset, offset + 1e6, offset + 1e6}, 1, 0.5, 2, 9);
    t.push_back(77777, offset, offset, 0, 0, 1);  // a far corner
    for (double range : {10.0, 5e4, 3e6}) {
      SCOPED_TRACE("offset " + std::to_string(offset) + " range " + std::to_string(range));
      const NeighbourLists want = run(naive, t.view(), range, 10);
      expect_same(run(grid, t.view(), range, 10), want);
      expect_same(run(grid, t.view(), range, 10), want);  // again, seeded with exact hints
      expect_same(run(grid, t.view(), range, 0), run(naive, t.view(), range, 0));
    }
  }
}

// One grid queried again and again as its table changes, as a tick does: each call is seeded
// with the lists of the call before (the hints), which must change nothing. Small moves (the
// usual tick), jumps across the world, rows swapped and shuffled (the hints then name other
// discs), rows removed and added, discs stacked on one point (ties on distance and on the hints'
// own distances), k changed, calls for a subset of rows (their lists kept as the hints of those
// rows), rows asked twice and out of order (the hints dropped), rows permuted with the grid told,
// and the grid told of a permutation that did not happen.
TEST(NeighbourGrid, ListsOfTheCallBeforeChangeNothing) {
  Rng rng(17);
  NeighbourNaive naive;
  NeighbourGrid grid;
  for (int c = 0; c < 8; ++c) {
    DiscTable t = build::uniform(200 + rng.below(1500), {0, 0, 40, 40}, 1.3, 0.25, 0.25,
                                 300 + static_cast<uint64_t>(c));
    uint32_t k = c == 7 ? 40 : static_cast<uint32_t>(1 + rng.below(16));  // 40: beyond the hints
    const double range = rng.uniform(1, 8);
    const int threads = 1 + static_cast<int>(rng.below(3));
    uint64_t next_id = 1'000'000;
    // Cases 1 and 4 ask for most rows, as the stalemate stage does: a subset that changes a
    // little from call to call (the rows left out keep older hints).
    const bool subsets = c == 1 || c == 4;
    for (int call = 0; call < 40; ++call) {
      SCOPED_TRACE("case " + std::to_string(c) + " call " + std::to_string(call) + " n " +
                   std::to_string(t.size()) + " k " + std::to_string(k));
      std::vector<uint32_t> asked;
      if (subsets)
        for (std::size_t i = 0; i < t.size(); ++i)
          if (rng.below(5) != 0) asked.push_back(static_cast<uint32_t>(i));
      const NeighbourLists want = run(naive, t.view(), range, k, asked);
      expect_same(run(grid, t.view(), range, k, asked, threads), want);
      if (::testing::Test::HasFailure()) return;
      const std::size_t n = t.size();
      for (std::size_t i = 0; i < n; ++i) {  // a tick's walk
        t.x[i] += rng.uniform(-0.13, 0.13);
        t.y[i] += rng.uniform(-0.13, 0.13);
      }
      switch (rng.below(13)) {
        case 0:  // a few jump anywhere
          for (int j = 0; j < 10; ++j) {
            const std::size_t i = rng.below(n);
            t.x[i] = rng.uniform(0, 40);
            t.y[i] = rng.uniform(0, 40);
          }
          break;
        case 1:  // rows swapped: the hints of both now name other discs
          for (int j = 0; j < 50; ++j) {
            const std::size_t a = rng.below(n), b = rng.below(n);
            std::swap(t.x[a], t.x[b]);
            std::swap(t.y[a], t.y[b]);
            std::swap(t.id[a], t.id[b]);
          }
          break;
        case 2:  // rows removed from the end and the middle
          remove_rows(t, rng, 30);
          break;
        case 3:  // rows added
          for (int j = 0; j < 30; ++j)
            t.push_back(next_id++, rng.uniform(0, 40), rng.uniform(0, 40), 0, 0, 0.25);
          break;
        case 4:  // a stack of discs on one point, and their neighbours at equal distances
          for (int j = 0; j < 12; ++j) {
            const std::size_t i = rng.below(n);
            t.x[i] = 20 + (j % 3 == 0 ? 0.5 : 0);
            t.y[i] = 20;
          }
          break;
        case 7: {  // rows permuted, as the tick's curve order does, and the grid told
          const std::vector<uint32_t> order = shuffled_rows(t.size(), rng);
          t = permuted(t, order);
          grid.rows_permuted(order);
          break;
        }
        case 9: {  // the tick's order: rows removed (arrivals), then the reorder, then the query
          remove_rows(t, rng, 15);
          const std::vector<uint32_t> order = shuffled_rows(t.size(), rng);
          t = permuted(t, order);
          grid.rows_permuted(order);
          break;
        }
        case 10: {  // not a permutation: the grid must drop its hints, not trust them
          std::vector<uint32_t> order(t.size(), 0);
          grid.rows_permuted(order);
          break;
        }
        case 8: {  // told of a permutation that did not happen: every row's hints name other
                   // discs (a row's own list never names the row, so neither does a permuted one)
          std::vector<uint32_t> order(t.size());
          for (std::size_t i = 0; i < order.size(); ++i)
            order[i] = static_cast<uint32_t>((i + 1) % order.size());
          grid.rows_permuted(order);
          break;
        }
        case 11: {  // a crowd packs into a 1.5 m square: rows near it find more discs within
                    // their hints' bound than are ranked at once (64), and search the usual way
          const double cx = rng.uniform(5, 35), cy = rng.uniform(5, 35);
          for (std::size_t i = 0; i < n; i += 2) {
            t.x[i] = cx + rng.uniform(0, 1.5);
            t.y[i] = cy + rng.uniform(0, 1.5);
          }
          break;
        }
        case 5:  // another k: the slots no longer hold lists of this k (40: too long for hints)
          k = rng.below(4) == 0 ? 40 : static_cast<uint32_t>(1 + rng.below(16));
          break;
        case 6: {  // a subset of rows in between
          std::vector<uint32_t> q;
          for (std::size_t i = 0; i < t.size(); i += 3) q.push_back(static_cast<uint32_t>(i));
          expect_same(run(grid, t.view(), range, k, q), run(naive, t.view(), range, k, q));
          break;
        }
        case 12: {  // rows asked twice and out of order: the hints dropped
          std::vector<uint32_t> q;
          for (std::size_t i = t.size(); i-- > 0;) q.push_back(static_cast<uint32_t>(i / 2));
          expect_same(run(grid, t.view(), range, k, q, threads), run(naive, t.view(), range, k, q));
          break;
        }
        default:
          break;
      }
    }
  }
}

// Told of a permutation of the rows, the grid carries each row's hints to its new place: the
// permuted table's search then does exactly the work of the unpermuted one (the same cells and
// bounds); without the hints carried along it would not.
TEST(NeighbourGrid, CarriesTheHintsThroughAPermutation) {
  const DiscTable t = build::uniform(3000, {0, 0, 80, 80}, 1.3, 0.25, 0.25, 41);
  Executor ex(1);
  auto tests_of = [&](NeighbourGrid& g, const DiscTable& d) {
    QueryStats st;
    NeighbourLists out;
    g.run(d.view(), {}, 5, 10, out, ex, st);
    return st.pair_tests;
  };
  NeighbourGrid grid;
  tests_of(grid, t);
  const uint64_t hinted = tests_of(grid, t);  // every hint exact
  Rng rng(3);
  const std::vector<uint32_t> order = shuffled_rows(t.size(), rng);
  const DiscTable p = permuted(t, order);
  NeighbourGrid untold;
  tests_of(untold, t);
  EXPECT_NE(tests_of(untold, p), hinted);  // the test can tell
  grid.rows_permuted(order);
  EXPECT_EQ(tests_of(grid, p), hinted);
  // Twice more without a query between (the grid reuses its buffers from one permutation to the
  // next): the hints still come along.
  const std::vector<uint32_t> second = shuffled_rows(t.size(), rng),
                              third = shuffled_rows(t.size(), rng);
  const DiscTable q = permuted(permuted(p, second), third);
  grid.rows_permuted(second);
  grid.rows_permuted(third);
  EXPECT_EQ(tests_of(grid, q), hinted);
  NeighbourNaive naive;
  NeighbourLists a, b;
  QueryStats st;
  grid.run(p.view(), {}, 5, 10, a, ex, st);
  naive.run(p.view(), {}, 5, 10, b, ex, st);
  expect_same(a, b);
}

// A subset's hints are dropped at a permutation (not carried: that takes lists for every row of
// the table): the next call searches as a grid told nothing, with the naive twin's answer.
TEST(NeighbourGrid, DropsASubsetsHintsAtAPermutation) {
  const DiscTable t = build::uniform(3000, {0, 0, 80, 80}, 1.3, 0.25, 0.25, 43);
  Executor ex(1);
  std::vector<uint32_t> subset;
  for (uint32_t i = 0; i < t.size(); i += 7) subset.push_back(i);
  auto run = [&](NeighbourGrid& g, const DiscTable& d, NeighbourLists& out) {
    QueryStats st;
    g.run(d.view(), subset, 1.1, 6, out, ex, st);
    return st.pair_tests;
  };
  NeighbourLists out;
  NeighbourGrid grid;
  run(grid, t, out);
  const uint64_t hinted = run(grid, t, out);
  Rng rng(9);
  const std::vector<uint32_t> order = shuffled_rows(t.size(), rng);
  const DiscTable p = permuted(t, order);
  NeighbourGrid untold;
  const uint64_t cold = run(untold, p, out);
  NeighbourGrid warm;
  run(warm, p, out);
  EXPECT_NE(run(warm, p, out), cold);  // the test can tell hints from none
  grid.rows_permuted(order);
  NeighbourLists a, b;
  EXPECT_EQ(run(grid, p, a), cold);
  EXPECT_NE(cold, hinted);
  NeighbourNaive naive;
  QueryStats st;
  naive.run(p.view(), subset, 1.1, 6, b, ex, st);
  expect_same(a, b);
}

TEST(NeighbourQuery, PublicFunctionChecksItsArguments) {
  const DiscTable t = build::uniform(10, {0, 0, 10, 10}, 1, 0.2, 0.3, 1);
  EXPECT_THROW(neighbours(t.view(), 0, 3), Error);
  EXPECT_THROW(neighbours(t.view(), NAN, 3), Error);
  const uint32_t bad[] = {10};
  EXPECT_THROW(neighbours(t.view(), 1, 3, bad), Error);
  EXPECT_THROW(neighbours(t.view(), 1, 3, {}, "kd"), Error);
  for (const std::string& m : neighbour_methods()) {
    const NeighbourLists l = neighbours(t.view(), 4, 2, {}, m);
    EXPECT_EQ(l.queries(), 10u);
  }
}

}  // namespace
}  // namespace crowddb::index
