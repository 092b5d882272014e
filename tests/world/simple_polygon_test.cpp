// The simplicity test of polygon rings (world/geometry.hpp): CGAL's exact sweep against a naive
// oracle on every pair of edges, on rings with integer coordinates where the oracle's arithmetic
// is exact; and the edges it names on long rings.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "world/geometry.hpp"

namespace crowddb {
namespace {

// Exact for integer coordinates below 2^25.
long long orient(const Vec2& a, const Vec2& b, const Vec2& c) {
  const auto v = static_cast<long long>((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
  return (v > 0) - (v < 0);
}
bool within(const Vec2& a, const Vec2& b, const Vec2& p) {
  return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
         p.y <= std::max(a.y, b.y);
}
bool closed_segments_meet(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const auto o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) ||
         (o3 == 0 && within(c, d, a)) || (o4 == 0 && within(c, d, b));
}

// Edges i < j meet as a simple polygon forbids: non-adjacent edges at all, adjacent edges
// beyond their shared vertex (overlapping along a line), or either has zero length.
bool edges_meet(const std::vector<Vec2>& r, std::size_t i, std::size_t j) {
  const std::size_t n = r.size();
  const Vec2 &a = r[i], &b = r[(i + 1) % n], &c = r[j], &d = r[(j + 1) % n];
  if ((a.x == b.x && a.y == b.y) || (c.x == d.x && c.y == d.y)) return true;
  if (j == i + 1 || (i == 0 && j == n - 1)) {
    const Vec2& s = j == i + 1 ? b : a;  // shared vertex
    const Vec2& p = j == i + 1 ? a : b;
    const Vec2& q = j == i + 1 ? d : c;
    return orient(p, s, q) == 0 && (p.x - s.x) * (q.x - s.x) + (p.y - s.y) * (q.y - s.y) > 0;
  }
  return closed_segments_meet(a, b, c, d);
}

// The definition, pair by pair: no repeated vertex and no two edges meeting.
bool simple_by_definition(const std::vector<Vec2>& r) {
  const std::size_t n = r.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = i + 1; k < n; ++k)
      if (r[i].x == r[k].x && r[i].y == r[k].y) return false;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if (edges_meet(r, i, j)) return false;
  return true;
}

TEST(SimplePolygon, HandMadeRings) {
  const std::vector<std::pair<std::vector<Vec2>, bool>> cases = {
      {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, true},
      {{{0, 0}, {1, 1}, {1, 0}, {0, 1}}, false},                  // bow tie
      {{{0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 1}}, false},          // repeated vertex
      {{{0, 0}, {2, 0}, {1, 0}, {1, 1}}, false},                  // folds back along a line
      {{{0, 0}, {1, 0}, {2, 0}, {2, 1}}, true},                   // straight angle is fine
      {{{0, 0}, {4, 0}, {4, 4}, {2, 0}, {0, 4}}, false},          // vertex on an edge
      {{{0, 0}, {2, 0}, {4, 0}, {4, 4}, {2, 0}, {0, 4}}, false},  // vertex on a vertex
  };
  for (const auto& [ring, simple] : cases) {
    EXPECT_EQ(simple_by_definition(ring), simple);
    EXPECT_EQ(is_simple_polygon(ring), simple);
    const auto bad = first_self_intersection(ring);
    ASSERT_EQ(bad.has_value(), !simple);
    if (bad) {
      EXPECT_TRUE(bad->named);
      EXPECT_TRUE(edges_meet(ring, bad->first, bad->second));
    }
  }
}

// Random rings on a small grid: collinear edges, touching vertices and overlaps abound.
TEST(SimplePolygon, AgreesWithTheDefinitionOnRandomRings) {
  std::mt19937_64 rng(20261124);
  int simple = 0, not_simple = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    std::uniform_int_distribution<int> size(3, trial % 2 ? 6 : 12), coord(0, trial % 3 ? 4 : 40);
    std::vector<Vec2> ring(static_cast<std::size_t>(size(rng)));
    for (Vec2& v : ring) v = {static_cast<double>(coord(rng)), static_cast<double>(coord(rng))};
    const bool want = simple_by_definition(ring);
    ASSERT_EQ(is_simple_polygon(ring), want) << "trial " << trial;
    const auto bad = first_self_intersection(ring);
    ASSERT_EQ(bad.has_value(), !want) << "trial " << trial;
    if (bad) {
      // A named pair that really meets (or a vertex repeated further round the ring, which
      // only the vertex check sees).
      ASSERT_TRUE(bad->named) << "trial " << trial;
      bool repeated = false;
      for (std::size_t i = 0; i < ring.size(); ++i)
        for (std::size_t k = i + 1; k < ring.size(); ++k)
          repeated |= ring[i].x == ring[k].x && ring[i].y == ring[k].y;
      ASSERT_TRUE(repeated || edges_meet(ring, bad->first, bad->second)) << "trial " << trial;
    }
    (want ? simple : not_simple)++;
  }
  EXPECT_GT(simple, 1000);  // both outcomes are well represented
  EXPECT_GT(not_simple, 1000);
}

std::vector<Vec2> circle(std::size_t n, double r) {
  std::vector<Vec2> ring(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
    ring[i] = {std::round(r * std::cos(a)), std::round(r * std::sin(a))};
  }
  return ring;
}

// Rings far beyond the quadratic scan (issue 13: 200k vertices took 33 s): the exact decision,
// and a pair named by the sweep that really meets.
TEST(SimplePolygon, LongRingsAreDecidedAndTheirCrossingNamed) {
  const std::vector<Vec2> ring = circle(100000, 1e7);
  EXPECT_TRUE(is_simple_polygon(ring));
  EXPECT_FALSE(first_self_intersection(ring).has_value());
  for (std::size_t at : {std::size_t{5}, std::size_t{50000}, std::size_t{99990}}) {
    std::vector<Vec2> bent = ring;
    bent[at] = {-1.5 * bent[at].x, -1.5 * bent[at].y};  // a spike out through the far side
    const auto bad = first_self_intersection(bent);
    ASSERT_TRUE(bad.has_value()) << at;
    ASSERT_TRUE(bad->named) << at;
    const std::size_t i = bad->first, j = bad->second;
    EXPECT_TRUE(edges_meet(bent, i, j)) << at << ": edges " << i << " and " << j;
  }
}

// A star whose long spikes all overlap in their boxes: the naming sweep may give up (its work is
// bounded), but the ring is still refused.
TEST(SimplePolygon, AStarOfOverlappingBoxesIsStillRefused) {
  const std::size_t n = 200000;
  std::vector<Vec2> star(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
    const double r = i % 2 ? 1e6 : 1e7;
    star[i] = {std::round(r * std::cos(a)), std::round(r * std::sin(a))};
  }
  if (!is_simple_polygon(star)) GTEST_SKIP() << "rounding made the star itself not simple";
  star[n - 2] = {-1.5 * star[n - 2].x, -1.5 * star[n - 2].y};  // flung out through the far side
  const auto bad = first_self_intersection(star);
  ASSERT_TRUE(bad.has_value());
  if (bad->named) {
    const std::size_t i = bad->first, j = bad->second;
    EXPECT_TRUE(edges_meet(star, i, j));
  }
}

// A comb of 50,000 long teeth: every tooth's box overlaps every other's in x, so naming the
// crossing would take ~10^9 box tests. The sweep stops at its budget and the ring is refused
// unnamed (World says "polygon is not simple: it crosses or touches itself").
TEST(SimplePolygon, ACombBeyondTheNamingBudgetIsRefusedUnnamed) {
  const int teeth = 50000;
  const double width = 1e6;
  std::vector<Vec2> comb;
  for (int k = 0; k < teeth; ++k) {
    const double y = 4.0 * k;
    comb.insert(comb.end(), {{1, y}, {width, y}, {width, y + 2}, {1, y + 2}});
  }
  comb.insert(comb.end(), {{0, 4.0 * teeth}, {0, 0}});
  ASSERT_TRUE(is_simple_polygon(comb));
  EXPECT_FALSE(first_self_intersection(comb).has_value());
  comb[comb.size() - 2] = {width / 2, 1};  // the top corner pulled down into the first tooth
  const auto bad = first_self_intersection(comb);
  ASSERT_TRUE(bad.has_value());
  EXPECT_FALSE(bad->named);
}

}  // namespace
}  // namespace crowddb
