// Keeping to a side's filter four rows at a time (passing_filter_lanes: AVX2, chosen at run time in
// a default build) against the reference (passing_filter): the same places in the same order for
// every length of run (whole vectors and tails, whose lanes past the run's end would pass), rows
// exactly on each test's edge (along 0 and the look, the side's reach, the same-way cone), NaN,
// infinite and zero columns, and every mask of passing lanes.
#include "steer/passing_lanes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <numbers>
#include <vector>

#include "steer/passing.hpp"  // kSideReach
#include "util/rng.hpp"

namespace crowddb::steer {
namespace {

constexpr double kSameWay2 = kSameWay * kSameWay;

struct Rows {
  std::vector<double> x, y, r, wx, wy;
  void resize(std::size_t n, double fill) {
    for (auto* c : {&x, &y, &r, &wx, &wy}) c->resize(n, fill);
  }
  PassingColumns columns() const { return {x.data(), y.data(), r.data(), wx.data(), wy.data()}; }
};

std::vector<uint32_t> filter_run(Rows rows, uint32_t lo, uint32_t hi, const LaneQuery& q,
                                 PassingLanes lanes) {
  // The lanes read past the run's end: what lies there would pass (ahead, on the line, coming
  // straight towards the query).
  const std::size_t n = std::max<std::size_t>(rows.x.size(), hi + kPassingPad);
  rows.x.resize(n, q.px + 0.5 * q.ux);
  rows.y.resize(n, q.py + 0.5 * q.uy);
  rows.r.resize(n, 0.25);
  rows.wx.resize(n, -q.ux);
  rows.wy.resize(n, -q.uy);
  // Filled with a marker past the room it may use: nothing is written there.
  const uint32_t room = hi - lo + kPassingPad;
  std::vector<uint32_t> pick(room + 1, 0xdeadbeef);
  const uint32_t m =
      lanes == PassingLanes::scalar
          ? passing_filter(rows.columns(), lo, hi, q, kSameWay2, kSideReach, pick.data())
          : passing_filter_lanes(rows.columns(), lo, hi, q, kSameWay2, kSideReach, pick.data(),
                                 lanes);
  EXPECT_LE(m, hi - lo);
  EXPECT_EQ(pick[room], 0xdeadbeef) << "wrote past its room";
  pick.resize(m);
  return pick;
}

TEST(PassingLanes, FilterMatchesTheReferenceBitForBit) {
  Rng rng(20261204);
  uint64_t compared = 0, passed = 0, masks = 0, edges = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const auto n = static_cast<uint32_t>(rng.below(40));
    // The query: an axis (exact edges below) or any direction; a look of 10 m or random.
    LaneQuery q{};
    q.px = rng.below(3) ? 0.0 : rng.uniform(-50, 50);
    q.py = rng.below(3) ? 0.0 : rng.uniform(-50, 50);
    if (rng.below(2)) {
      const int axis = static_cast<int>(rng.below(4));
      q.ux = axis == 0 ? 1.0 : (axis == 1 ? -1.0 : 0.0);
      q.uy = axis == 2 ? 1.0 : (axis == 3 ? -1.0 : 0.0);
    } else {
      const double a = rng.uniform(0, 2 * std::numbers::pi);
      q.ux = std::cos(a);
      q.uy = std::sin(a);
    }
    q.look = rng.below(4) ? 10.0 : rng.uniform(0, 12);
    q.ri = rng.below(4) ? 0.25 : rng.uniform(0, 0.5);
    if (rng.below(50) == 0) q.ri = NAN;  // (find() asks every row then; the filter still agrees)
    Rows rows;
    rows.resize(n, 0.0);
    for (uint32_t a = 0; a < n; ++a) {
      // Along and across the lane, then a wish.
      double along = rng.uniform(-2, 12), across = rng.uniform(-2, 2);
      rows.r[a] = rng.below(4) ? 0.25 : rng.uniform(0, 0.5);
      switch (rng.below(7)) {
        case 0:  // on an edge of the along test (0 or the look)
          along = rng.below(2) ? 0.0 : q.look;
          ++edges;
          break;
        case 1:  // on the side's edge: r_i + r_j + kSideReach across
          across = (rng.below(2) ? 1 : -1) * (q.ri + rows.r[a] + kSideReach);
          ++edges;
          break;
        default:
          break;
      }
      rows.x[a] = q.px + along * q.ux - across * q.uy;
      rows.y[a] = q.py + along * q.uy + across * q.ux;
      switch (rng.below(8)) {
        case 0:  // straight towards the query
          rows.wx[a] = -q.ux * 1.3;
          rows.wy[a] = -q.uy * 1.3;
          break;
        case 1: {  // near the cone's edge, 120 degrees away (either side of it after rounding)
          const double t =
              std::atan2(q.uy, q.ux) + (rng.below(2) ? 1 : -1) * 2 * std::numbers::pi / 3;
          rows.wx[a] = std::cos(t);
          rows.wy[a] = std::sin(t);
          ++edges;
          break;
        }
        case 2:  // standing, or signed zeros
          rows.wx[a] = rng.below(2) ? 0.0 : -0.0;
          rows.wy[a] = rng.below(2) ? 0.0 : -0.0;
          break;
        case 3:  // not a number, or infinite, somewhere
          switch (rng.below(6)) {
            case 0:
              rows.wx[a] = NAN;
              break;
            case 1:
              rows.wy[a] = -INFINITY;
              break;
            case 2:
              rows.x[a] = NAN;
              break;
            case 3:
              rows.r[a] = NAN;
              break;
            case 4:
              rows.wx[a] = -q.ux;  // coming straight towards it, its place not a number
              rows.wy[a] = -q.uy;
              rows.y[a] = NAN;
              break;
            default:
              rows.r[a] = INFINITY;
          }
          break;
        default:
          rows.wx[a] = rng.uniform(-1.5, 1.5);
          rows.wy[a] = rng.uniform(-1.5, 1.5);
      }
    }
    const auto lo = static_cast<uint32_t>(rng.below(n / 2 + 1));
    const auto hi = lo + static_cast<uint32_t>(rng.below(n - lo + 1));
    const std::vector<uint32_t> want = filter_run(rows, lo, hi, q, PassingLanes::scalar);
    const std::vector<uint32_t> got = filter_run(rows, lo, hi, q, PassingLanes::widest);
    ASSERT_EQ(got, want) << "trial " << trial;
    ++compared;
    passed += want.size();
    // Runs of at least a vector in which some but not all are kept: the packing's permutations.
    masks += hi - lo >= 4 && !want.empty() && want.size() < hi - lo;
  }
  // The trials reach what they are meant to (not all empty, not all full, edges hit).
  EXPECT_GT(passed, compared / 2);
  EXPECT_GT(masks, compared / 4);
  EXPECT_GT(edges, compared);
}

// Every one of the sixteen masks of a vector of four, in runs of every length up to 8 from every
// start in the vector: the lanes past the run's end are dropped whatever they hold.
TEST(PassingLanes, EveryMaskAndRunEnd) {
  const LaneQuery q{0, 0, 1, 0, 10, 0.25};
  for (uint32_t mask = 0; mask < 16; ++mask)
    for (uint32_t lo = 0; lo < 4; ++lo)
      for (uint32_t hi = lo; hi <= 8; ++hi) {
        Rows rows;
        rows.resize(8, 0.0);
        for (uint32_t a = 0; a < 8; ++a) {
          rows.x[a] = mask >> (a % 4) & 1 ? 5.0 : -5.0;  // ahead passes, behind does not
          rows.r[a] = 0.25;
          rows.wx[a] = -1.3;
        }
        const std::vector<uint32_t> want = filter_run(rows, lo, hi, q, PassingLanes::scalar);
        const std::vector<uint32_t> got = filter_run(rows, lo, hi, q, PassingLanes::widest);
        EXPECT_EQ(got, want) << "mask " << mask << " run " << lo << ".." << hi;
        std::size_t in = 0;
        for (uint32_t a = lo; a < hi; ++a) in += mask >> (a % 4) & 1;
        EXPECT_EQ(want.size(), in);
      }
}

// The filter keeps every row passing() accepts, and more (it leaves the targets' tests to
// passing()), also where a row's radius or place is not a number.
TEST(PassingLanes, FilterIsPassingsFirstTests) {
  Rng rng(20261206);
  uint64_t kept = 0, accepted = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const std::size_t n = 33;  // row 0 is the query
    std::vector<double> x(n), y(n), r(n), wx(n), wy(n), tx(n), ty(n);
    for (std::size_t j = 0; j < n; ++j) {
      x[j] = rng.uniform(-6, 6);
      y[j] = rng.uniform(-6, 6);
      r[j] = j > 0 && rng.below(10) == 0 ? NAN : rng.uniform(0.2, 0.3);
      wx[j] = rng.uniform(-1.5, 1.5);
      wy[j] = rng.uniform(-1.5, 1.5);
      tx[j] = rng.uniform(-20, 20);
      ty[j] = rng.uniform(-20, 20);
    }
    const double w = std::sqrt(wx[0] * wx[0] + wy[0] * wy[0]);
    const double ux = wx[0] / w, uy = wy[0] / w;
    const PassingView view{x, y, r, wx, wy, tx, ty};
    const Rows rows{x, y, r, wx, wy};
    const LaneQuery q{x[0], y[0], ux, uy, 5.0, r[0]};
    const std::vector<uint32_t> pick =
        filter_run(rows, 1, static_cast<uint32_t>(n), q, PassingLanes::widest);
    for (uint32_t j = 1; j < n; ++j) {
      const bool in = std::find(pick.begin(), pick.end(), j) != pick.end();
      if (passing(view, 0, j, ux, uy, 5.0)) {
        EXPECT_TRUE(in) << "trial " << trial << " row " << j;
        ++accepted;
      }
      kept += in;
    }
  }
  EXPECT_GT(accepted, 100u);
  EXPECT_GT(kept, accepted);  // the filter leaves the targets' tests to passing()
}

TEST(PassingLanes, WidestIsChosenWhereTheCpuHasIt) {
  if (!passing_lanes_avx2()) std::cout << "[ note ] filtering one at a time on this CPU\n";
#if CROWDDB_TEST_AVX2_DISPATCH
  EXPECT_EQ(passing_lanes_avx2(), __builtin_cpu_supports("avx2") != 0);
#endif
}

}  // namespace
}  // namespace crowddb::steer
