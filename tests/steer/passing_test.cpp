// Who is passing whom (src/steer/passing.*): the grid's look-ahead against its naive twin (every
// row asked) on random and adversarial crowds, on 1 and 2 threads' builds.
#include "steer/passing.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <random>
#include <tuple>

#include "util/executor.hpp"

namespace crowddb::steer {
namespace {

struct Crowd {
  std::vector<double> x, y, radius, wish_x, wish_y, target_x, target_y;

  std::size_t size() const { return x.size(); }
  // A row walking with wish (wx, wy) towards a target `ahead` metres along it.
  void add(double px, double py, double wx, double wy, double r = 0.25, double ahead = 30) {
    x.push_back(px);
    y.push_back(py);
    radius.push_back(r);
    wish_x.push_back(wx);
    wish_y.push_back(wy);
    const double w = std::hypot(wx, wy);
    target_x.push_back(w > 0 ? px + wx / w * ahead : px);
    target_y.push_back(w > 0 ? py + wy / w * ahead : py);
  }
  PassingView view() const { return {x, y, radius, wish_x, wish_y, target_x, target_y}; }
};

struct Tally {
  std::size_t yes = 0, no = 0;
};

// Every row with a wish asks both, for each look-ahead; the answers must be equal.
Tally compare(const Crowd& c, const std::vector<double>& looks) {
  Tally tally;
  for (int threads : {1, 2}) {
    Executor ex(threads);
    PassingLookahead grid;
    grid.build(c.view(), ex);
    for (double look : looks)
      for (std::size_t i = 0; i < c.size(); ++i) {
        const double w = std::hypot(c.wish_x[i], c.wish_y[i]);
        if (w == 0) continue;
        const double ux = c.wish_x[i] / w, uy = c.wish_y[i] / w;
        uint64_t tests = 0;
        const bool want = passing_ahead_naive(c.view(), i, ux, uy, look);
        const bool got = grid.ahead(c.view(), i, ux, uy, look, tests);
        EXPECT_EQ(got, want) << "row " << i << " of " << c.size() << ", look " << look << " at ("
                             << c.x[i] << ", " << c.y[i] << ") wish (" << ux << ", " << uy << ")";
        if (got != want) return tally;
        // With any hint (none, the row itself, rows out of range, a random row, the answer
        // itself): the same answer, and a row returned is one passing.
        const uint32_t n = static_cast<uint32_t>(c.size());
        const uint32_t own = grid.find(c.view(), i, ux, uy, look, tests);
        for (uint32_t hint : {PassingLookahead::kNobody, static_cast<uint32_t>(i), n, n + 1000,
                              static_cast<uint32_t>((i * 7919 + 13) % std::max(n, 1u)), own}) {
          const uint32_t j = grid.find(c.view(), i, ux, uy, look, tests, hint);
          EXPECT_EQ(j != PassingLookahead::kNobody, want) << "row " << i << ", hint " << hint;
          if (j != PassingLookahead::kNobody) {
            EXPECT_TRUE(j != i && passing(c.view(), i, j, ux, uy, look)) << "row " << i;
          }
        }
        ++(want ? tally.yes : tally.no);
      }
  }
  return tally;
}

const std::vector<double> kLooks = {0, 0.4, 2, 5, 10, 37.5, 1e9, INFINITY};

// Two streams crossing a square at every angle, wishes of any length (some standing), radii
// 0.1-0.6 m: many rows see someone passing, many do not.
TEST(PassingLookahead, AnswersAsTheNaiveTwinOnRandomCrowds) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int round = 0; round < 12; ++round) {
    Crowd c;
    const double side = 5 + 60 * u(rng);
    const int n = 20 + static_cast<int>(400 * u(rng));
    const double heading = 2 * M_PI * u(rng);
    for (int k = 0; k < n; ++k) {
      // Half one way, half the other, each turned up to +-40 degrees; one in ten stands.
      const double a = heading + (k % 2 ? M_PI : 0) + (u(rng) - 0.5) * 1.4;
      const double s = k % 10 == 0 ? 0 : 0.3 + 1.2 * u(rng);
      c.add(side * u(rng), side * u(rng), s * std::cos(a), s * std::sin(a), 0.1 + 0.5 * u(rng),
            1 + 40 * u(rng));
    }
    const Tally t = compare(c, kLooks);
    EXPECT_GT(t.yes, 50u) << "round " << round;  // both answers are tested
    EXPECT_GT(t.no, 50u) << "round " << round;
  }
}

// The grid's cells are about 1 m: rows exactly on cell corners and edges, wishes along the axes
// and diagonals, the one passing row exactly at the end of the look-ahead or at the edge of the
// lane (the widest radius sets the cells scanned), far from the origin, piled on one point.
TEST(PassingLookahead, AnswersAsTheNaiveTwinOnAdversarialCrowds) {
  {  // a lattice of integer positions, wishes of 8 headings
    Crowd c;
    for (int gx = 0; gx < 14; ++gx)
      for (int gy = 0; gy < 14; ++gy) {
        const double a = M_PI / 4 * ((gx * 3 + gy * 5) % 8);
        c.add(gx, gy, std::cos(a), std::sin(a), 0.25);
      }
    const Tally t = compare(c, kLooks);
    EXPECT_GT(t.yes, 100u);
    EXPECT_GT(t.no, 100u);
  }
  for (double far : {0.0, 1e6, -3.7e5}) {  // one row coming head-on at the edge of reach
    for (double along : {0.5, 3.0, 9.999, 10.0, 10.001}) {
      for (double lateral : {0.0, 0.9, 1.1, 1.0999999, 1.1000001}) {
        for (double a : {0.0, M_PI / 4, M_PI / 2, 2.1, M_PI}) {
          Crowd c;
          const double ux = std::cos(a), uy = std::sin(a);
          c.add(far + 0.5, far + 0.5, ux, uy, 0.25);
          c.add(far + 0.5 + along * ux - lateral * uy, far + 0.5 + along * uy + lateral * ux, -ux,
                -uy, 0.25);
          c.add(far - 4, far + 7, 0, 0, 0.25);  // stands: widens the grid
          compare(c, {10.0, 5.0, INFINITY});
        }
      }
    }
  }
  for (int q = 0; q < 16; ++q) {  // the cells' compass eighths: wishes on their edges, and
    // coming towards the query at exactly 120 degrees from its wish (the passing test's edge)
    const double a = M_PI / 8 * q;
    for (double off : {0.0, 15.0, 45.0, 59.99, 60.0, 60.01, 90.0, -45.0, -60.0, -60.01}) {
      Crowd c;
      const double ux = std::cos(a), uy = std::sin(a), b = a + M_PI + off * M_PI / 180;
      c.add(0, 0, ux, uy, 0.25);
      c.add(3 * ux, 3 * uy, std::cos(b), std::sin(b), 0.25, 30);
      c.add(-5, 9, 0, 1, 0.25);  // widens the grid
      compare(c, {10.0});
    }
  }
  {  // a wide row among narrow ones: every lane is r_i + 3 + 0.6 wide
    Crowd c;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0, 20);
    for (int k = 0; k < 200; ++k) c.add(u(rng), u(rng), k % 2 ? 1 : -1, 0, 0.2);
    c.add(10, 10, 0, 1, 3.0);
    c.add(10, 14, 0, -1, 0.2);
    const Tally t = compare(c, kLooks);
    EXPECT_GT(t.yes, 10u);
  }
  {  // everyone on one point, or nearly
    Crowd c;
    for (int k = 0; k < 30; ++k) c.add(2 + 1e-12 * (k % 3), 2, k % 2 ? 1 : -1, 0.01 * k);
    compare(c, kLooks);
  }
  {  // one row, and two
    Crowd c;
    c.add(1, 1, 1, 0);
    compare(c, kLooks);
    c.add(3, 1, -1, 0);
    EXPECT_GT(compare(c, kLooks).yes, 0u);
  }
}

// Wishes whose squares leave the doubles' range (the angle test then accepts any direction),
// rows spread along one line or across a billion metres (the grid stays small: at most about
// 10n + 4 cells), and a table large enough to build on two threads.
TEST(PassingLookahead, AnswersAsTheNaiveTwinOnExtremeInputs) {
  {
    Crowd c;
    c.add(0, 0, 1, 0, 0.25);
    c.add(3, 0, -1e-200, 9e-200, 0.25);  // tiny wish, pointing up and back: heading class 4
    c.target_x[1] = -20;
    c.target_x[0] = 30;
    c.add(3, 0.5, 1e200, -1e200, 0.25);  // huge wish
    c.add(-4, 6, 0, 1, 0.25);
    EXPECT_TRUE(passing_ahead_naive(c.view(), 0, 1, 0, 10));  // the tiny wish counts as towards
    compare(c, kLooks);
  }
  for (double spread : {1e3, 1e6, 1e8, 1e9}) {
    Crowd c;
    for (int k = 0; k < 40; ++k) {
      const double x = (k % 2 ? spread : 0) + 0.6 * (k / 2);
      c.add(x - 1e9 * (spread == 1e9), 5, k % 4 < 2 ? 1 : -1, 0, 0.25);
    }
    compare(c, kLooks);
  }
  {
    Crowd c;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    for (int k = 0; k < 9000; ++k) {
      const double a = (k % 2 ? M_PI : 0) + (u(rng) - 0.5);
      c.add(100 * u(rng), 100 * u(rng), 1.3 * std::cos(a), 1.3 * std::sin(a), 0.25,
            5 + 30 * u(rng));
    }
    Executor one(1), two(2);
    PassingLookahead g1, g2;
    g1.build(c.view(), one);
    g2.build(c.view(), two);
    std::size_t yes = 0;
    for (std::size_t i = 0; i < c.size(); i += 37) {
      const double w = std::hypot(c.wish_x[i], c.wish_y[i]);
      const double ux = c.wish_x[i] / w, uy = c.wish_y[i] / w;
      uint64_t t1 = 0, t2 = 0;
      const bool want = passing_ahead_naive(c.view(), i, ux, uy, 10);
      EXPECT_EQ(g1.ahead(c.view(), i, ux, uy, 10, t1), want) << "row " << i;
      EXPECT_EQ(g2.ahead(c.view(), i, ux, uy, 10, t2), want) << "row " << i;
      EXPECT_EQ(t1, t2);
      yes += want;
    }
    EXPECT_GT(yes, 20u);
  }
}

// The lane's outline over each band of cells (two chains from its lowest corner to its highest):
// someone passing at each corner of the lane and at the middle of each side, among people
// standing who make the cells about 1 m, for headings along the axes and diagonals, a few ulps
// off them, exactly on the axes and with a subnormal component across them, and at random. One
// chain read where the other belongs, or a band cut at the wrong corner's height, leaves someone
// at a corner unseen.
TEST(PassingLookahead, AnswersAsTheNaiveTwinAtTheLanesCorners) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> angles;
  for (int k = 0; k < 8; ++k) {
    const double a = std::numbers::pi / 4 * k;
    angles.insert(angles.end(), {a, std::nextafter(a, 10.0), std::nextafter(a, -10.0), a + 1e-9});
  }
  for (int k = 0; k < 16; ++k) angles.push_back(2 * std::numbers::pi * u(rng));
  // Standing (never passing) on a lattice of 0.5 m over 40 x 40 m: cells of about 1 m, so that
  // a lane crosses many. Rows i and j, the two walkers, are set for each case.
  Crowd c;
  for (int gx = 0; gx <= 80; ++gx)
    for (int gy = 0; gy <= 80; ++gy) c.add(0.5 * gx + 0.13, 0.5 * gy + 0.29, 0, 0, 0.1);
  const std::size_t i = c.size(), j = i + 1;
  c.add(0, 0, 0, 0, 0.25);
  c.add(0, 0, 0, 0, 0.4);
  Executor ex(1);
  PassingLookahead grid;
  std::size_t cases = 0, seen = 0;
  for (const double a : angles)
    for (const int axis : {0, 1, 2, 3}) {
      double wx = std::cos(a), wy = std::sin(a);
      if (axis > 0) {  // the nearest axis, with a subnormal component across it or none
        const double tiny = axis == 1 ? 1e-310 : (axis == 2 ? -1e-310 : 0.0);
        wx = std::abs(wx) >= std::abs(wy) ? (wx < 0 ? -1.0 : 1.0) : tiny;
        wy = std::abs(wx) == 1 ? tiny : (wy < 0 ? -1.0 : 1.0);
      }
      const double w = std::hypot(wx, wy), ux = wx / w, uy = wy / w;
      for (const double ox : {0.0, 0.37, 1.0})
        for (const double along : {1e-6, 5.0, 10 * (1 - 1e-12)})
          for (const double side : {-1.0, 0.0, 1.0}) {
            const double px = 20 + ox, py = 20 + ox * 0.5;
            c.x[i] = px;
            c.y[i] = py;
            c.wish_x[i] = wx;
            c.wish_y[i] = wy;
            c.target_x[i] = px + 60 * ux;
            c.target_y[i] = py + 60 * uy;
            // At the lane's edge: r_i + r_j + kSideReach across (r_j the widest radius), a
            // hair inside.
            const double lateral = side * (0.25 + 0.4 + kSideReach) * (1 - 1e-12);
            c.x[j] = px + along * ux - lateral * uy;
            c.y[j] = py + along * uy + lateral * ux;
            c.wish_x[j] = -wx;
            c.wish_y[j] = -wy;
            c.target_x[j] = c.x[j] - 60 * ux;
            c.target_y[j] = c.y[j] - 60 * uy;
            grid.build(c.view(), ex);
            for (const auto& [q, sx, sy] : {std::tuple{i, ux, uy}, std::tuple{j, -ux, -uy}}) {
              uint64_t tests = 0;
              const bool want = passing_ahead_naive(c.view(), q, sx, sy, 10);
              ASSERT_EQ(grid.ahead(c.view(), q, sx, sy, 10, tests), want)
                  << "heading " << a << " (" << ux << ", " << uy << "), along " << along
                  << ", side " << side << ", from " << ox << ", row " << q - i;
              seen += want;
            }
            ++cases;
          }
    }
  EXPECT_EQ(seen, 2 * cases);  // each of the two sees the other in every case
}

// A radius or a look that is not a number: the lane has no shape and every row is asked, as the
// naive twin does (a row whose radius is NaN passes the test across at any distance).
TEST(PassingLookahead, AnswersAsTheNaiveTwinWithRadiiOrLookNotANumber) {
  Crowd c;
  c.add(0, 0, 1, 0, 0.25, 30);
  c.add(6, 8, -1, 0, NAN, 30);  // 8 m across: passing only because its radius is NaN
  c.add(-5, 9, 0, 1, 0.25);
  c.add(19, -13, -1, 0.2, 0.25, 30);
  Crowd d;  // the query's own radius NaN, someone passing 7 m across
  d.add(0, 0, 1, 0, NAN, 30);
  d.add(6, -7, -1, 0, 0.25, 30);
  d.add(-5, 9, 0, 1, 0.25);
  d.add(19, 13, 0, -1, 0.25);
  for (Crowd* crowd : {&c, &d})  // people standing, who make the cells small
    for (int k = 0; k < 900; ++k) crowd->add(-15 + k % 30, -15 + k / 30 + 0.5, 0, 0, 0.1);
  Executor ex(1);
  for (const Crowd* crowd : {&c, &d}) {
    PassingLookahead grid;
    grid.build(crowd->view(), ex);
    for (std::size_t i = 0; i < crowd->size(); ++i) {
      const double w = std::hypot(crowd->wish_x[i], crowd->wish_y[i]);
      const double ux = crowd->wish_x[i] / w, uy = crowd->wish_y[i] / w;
      for (const double look : {10.0, double{INFINITY}, double{NAN}}) {
        uint64_t tests = 0;
        EXPECT_EQ(grid.ahead(crowd->view(), i, ux, uy, look, tests),
                  passing_ahead_naive(crowd->view(), i, ux, uy, look))
            << "row " << i << ", look " << look;
      }
    }
  }
  EXPECT_TRUE(passing_ahead_naive(c.view(), 0, 1, 0, 10));
  EXPECT_TRUE(passing_ahead_naive(d.view(), 0, 1, 0, 10));
}

// Converging on one point from its two sides is not passing (each one's target lies in front of
// the other), and nobody behind or standing is.
TEST(PassingLookahead, ConvergingBehindOrStandingIsNotPassing) {
  Crowd c;
  c.add(0, 0, 1, 0, 0.25, 5);    // target (5, 0)
  c.add(10, 0, -1, 0, 0.25, 5);  // target (5, 0): converging
  c.add(-3, 0, -1, 0, 0.25);     // behind row 0, walking away
  c.add(6, 0.2, 0, 0, 0.25);     // stands ahead
  const PassingView v = c.view();
  EXPECT_FALSE(passing_ahead_naive(v, 0, 1, 0, 10));
  Crowd d = c;
  d.target_x[0] = 30;  // each now bound past the other: passing
  d.target_x[1] = -20;
  EXPECT_TRUE(passing_ahead_naive(d.view(), 0, 1, 0, 10));
  EXPECT_FALSE(passing_ahead_naive(d.view(), 0, 1, 0, 9.99));  // beyond the look-ahead
  compare(c, kLooks);
  compare(d, kLooks);
}

// The branch-free heading class is the quadrant-by-quadrant one: on the axes and diagonals (and
// their -0 twins), at the sixteen class boundaries and a few ulps either side, and on random
// directions of every scale the build lets through (squares within 1e-280 .. 1e280).
TEST(HeadingClass, EqualsTheReferenceEverywhere) {
  std::vector<std::pair<double, double>> dirs;
  for (double x : {-1.0, -0.0, 0.0, 1.0})
    for (double y : {-1.0, -0.0, 0.0, 1.0})
      if (x != 0 || y != 0) dirs.push_back({x, y});
  for (int k = 0; k < 16; ++k) {
    // The boundary k / 4 of the diamond angle: quadrant k / 4, numerator share (k % 4) / 4.
    const double f = (k % 4) / 4.0, g = 1 - f;
    const std::pair<double, double> q[4] = {{g, f}, {-f, g}, {-g, -f}, {f, -g}};
    auto [x, y] = q[k / 4];
    for (int u = 0; u < 4; ++u) {
      dirs.push_back({x, y});
      x = std::nextafter(x, -x), y = std::nextafter(y, y + 1);
    }
  }
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(0, 2 * std::numbers::pi), scale(-130, 130);
  for (int n = 0; n < 200000; ++n) {
    const double a = angle(rng), m = std::pow(10.0, scale(rng));
    dirs.push_back({m * std::cos(a), m * std::sin(a)});
  }
  for (auto [x, y] : dirs)
    ASSERT_EQ(heading_class(x, y), heading_class_reference(x, y)) << x << " " << y;
  // Every class is met.
  std::vector<int> seen(16, 0);
  for (auto [x, y] : dirs) seen[static_cast<std::size_t>(heading_class(x, y))] = 1;
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), 16);
}

// The table's classes hold the exact ones, and at most two more: at random directions of lengths
// 10^-3 to 10^3, the axes and diagonals, and the directions on each of the table's 256 bin
// boundaries (diamond angle b / 64) and a few ulps turned either way, where rounding picks the
// bin. (The table's margin of a bin on either side is a defence against rounding that no
// direction here is known to need.)
TEST(OppositeClasses, TheTableHoldsTheExactClassesAndLittleMore) {
  std::vector<std::pair<double, double>> dirs = {{1, 0},  {0, 1},   {-1, 0}, {0, -1},    {1, 1},
                                                 {-1, 1}, {-1, -1}, {1, -1}, {1, 1e-300}};
  for (int b = 0; b < 256; ++b) {
    const int q = b / 64;
    const double f = (b % 64) / 64.0, g = 1 - f;
    const std::pair<double, double> on[4] = {{g, f}, {-f, g}, {-g, -f}, {f, -g}};
    auto [x, y] = on[q];
    const double len = std::hypot(x, y);
    x /= len, y /= len;
    // Turned counter-clockwise (x away from y's side, y towards x's) and clockwise.
    double cx = x, cy = y, wx = x, wy = y;
    for (int u = 0; u < 4; ++u) {
      dirs.push_back({cx, cy});
      dirs.push_back({wx, wy});
      cx = std::nextafter(cx, -std::copysign(2.0, cy)),
      cy = std::nextafter(cy, std::copysign(2.0, cx));
      wx = std::nextafter(wx, std::copysign(2.0, wy)),
      wy = std::nextafter(wy, -std::copysign(2.0, wx));
    }
  }
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> angle(0, 2 * std::numbers::pi), scale(-3, 3);
  for (int n = 0; n < 200000; ++n) {
    const double a = angle(rng), m = n % 2 ? 1.0 : std::pow(10.0, scale(rng));
    dirs.push_back({m * std::cos(a), m * std::sin(a)});
  }
  for (auto [x, y] : dirs) {
    const uint16_t exact = opposite_classes_exact(x, y), table = opposite_classes(x, y);
    ASSERT_EQ(table & exact, exact) << x << " " << y;
    ASSERT_LE(std::popcount(table), std::popcount(exact) + 2) << x << " " << y;
  }
}

// Keeping to one side stops near a sharp bend only: a route's corners round a pillar (15-25
// degrees each) are gentle, a corridor's mouth or a door (90 degrees) is sharp, and so is a
// waypoint with nothing after it. The test turns a leg by every angle, at any length and in any
// direction, against the angle computed with a root.
TEST(BendsSharply, AtMoreThan45DegreesOrWithNothingAfter) {
  EXPECT_NEAR(std::cos(kSharpBend * std::numbers::pi / 180), kSharpBendCos, 1e-15);
  EXPECT_FALSE(bends_sharply(1, 0, 1, 0));        // straight on
  EXPECT_FALSE(bends_sharply(1, 0, 0.94, 0.34));  // 20 degrees: round a pillar
  EXPECT_TRUE(bends_sharply(1, 0, 0, 1));         // 90: a corridor's mouth
  EXPECT_TRUE(bends_sharply(1, 0, -1, 0));        // back the way it came
  EXPECT_TRUE(bends_sharply(1, 0, 0, 0));         // the last point
  EXPECT_TRUE(bends_sharply(0, 0, 1, 0));         // on the waypoint
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int k = 0; k < 20000; ++k) {
    const double heading = 2 * std::numbers::pi * unit(rng);
    const double turn = std::numbers::pi * (2 * unit(rng) - 1);
    const double a = 0.01 + 10 * unit(rng), b = 0.01 + 10 * unit(rng);
    const double degrees = std::abs(turn) * 180 / std::numbers::pi;
    if (std::abs(degrees - kSharpBend) < 1e-6) continue;  // rounding decides on the boundary
    EXPECT_EQ(bends_sharply(a * std::cos(heading), a * std::sin(heading),
                            b * std::cos(heading + turn), b * std::sin(heading + turn)),
              degrees > kSharpBend)
        << degrees << " degrees";
  }
}

}  // namespace
}  // namespace crowddb::steer
