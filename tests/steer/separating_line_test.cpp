// The line an ORCA agent keeps from an obstacle edge (steer/separating_line.hpp) against its naive
// twin: the swept disc itself. Whatever line is picked, every velocity it permits keeps the disc
// clear of the edge for tau (checked by the distance between the path's segment and the edge),
// and it never leaves the wish less room than the tangent at the nearest point.
#include "steer/separating_line.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace crowddb::steer {
namespace {

constexpr double kLineSkin = 1e-6;

double turn_of(Vec2 a, Vec2 b, Vec2 c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Distance between segments p0-p1 and q0-q1, the naive way: zero when they cross, else the least
// of the four end-to-segment distances.
double swept_gap(Vec2 p0, Vec2 p1, Vec2 q0, Vec2 q1) {
  const double d1 = turn_of(q0, q1, p0), d2 = turn_of(q0, q1, p1);
  const double d3 = turn_of(p0, p1, q0), d4 = turn_of(p0, p1, q1);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return 0;
  return std::sqrt(
      std::min({dist2_to_segment(q0, q1, p0.x, p0.y), dist2_to_segment(q0, q1, p1.x, p1.y),
                dist2_to_segment(p0, p1, q0.x, q0.y), dist2_to_segment(p0, p1, q1.x, q1.y)}));
}

double line_room(const SeparatingLine& l, double wx, double wy, double r, double tau) {
  return wx * l.nx + wy * l.ny + (l.d - r) / tau;
}

// Permitted velocities (v . n >= -(d - r) / tau, up to 3 m/s), the wish among them when it is
// permitted: gap(q), how far the path p -> q of the next tau keeps the centre from the feature,
// stays at least `clear`.
template <class Gap>
void expect_permitted_clear(const SeparatingLine& l, Vec2 p, double r, double tau, double wx,
                            double wy, double clear, std::mt19937_64& rng, Gap gap) {
  std::uniform_real_distribution<double> ang(0, 2 * std::acos(-1.0)), mag(0, 3);
  const double bound = -(l.d - r) / tau;
  for (int k = 0; k < 64; ++k) {
    double vx = wx, vy = wy;
    if (k > 0) {
      const double a = ang(rng), m = mag(rng);
      vx = m * std::cos(a);
      vy = m * std::sin(a);
    }
    if (vx * l.nx + vy * l.ny < bound) continue;
    EXPECT_GE(gap(Vec2{p.x + vx * tau, p.y + vy * tau}), clear - 1e-9)
        << "velocity (" << vx << ", " << vy << ")";
  }
}

// One case: the line's own claims, then the swept disc for permitted velocities.
void check_line(Vec2 a0, Vec2 a1, Vec2 p, double r, double tau, double wx, double wy,
                std::mt19937_64& rng) {
  SCOPED_TRACE(testing::Message() << "edge (" << a0.x << ", " << a0.y << ")-(" << a1.x << ", "
                                  << a1.y << "), agent (" << p.x << ", " << p.y << ") r " << r
                                  << ", tau " << tau << ", wish (" << wx << ", " << wy << ")");
  const SeparatingLine l = separating_line(a0, a1, p.x, p.y, r, tau, wx, wy, kLineSkin);
  ASSERT_NEAR(std::hypot(l.nx, l.ny), 1.0, 1e-12);
  const double nearest = std::sqrt(dist2_to_segment(a0, a1, p.x, p.y));
  ASSERT_GE(nearest, r + kLineSkin);  // the cases below keep the disc clear
  // The agent is at d from the line, and the whole edge behind it.
  EXPECT_GE(l.d, r + kLineSkin - 1e-12);
  for (const Vec2& e : {a0, a1}) EXPECT_GE((p.x - e.x) * l.nx + (p.y - e.y) * l.ny, l.d - 1e-9);
  // Never less room for the wish than the tangent at the nearest point.
  const Vec2 c = closest_on_segment(a0, a1, p.x, p.y);
  const SeparatingLine tangent{(p.x - c.x) / nearest, (p.y - c.y) / nearest, nearest};
  EXPECT_GE(line_room(l, wx, wy, r, tau), line_room(tangent, wx, wy, r, tau) - 1e-12);
  // The disc stays clear of the edge for tau.
  expect_permitted_clear(l, p, r, tau, wx, wy, r, rng,
                         [&](Vec2 q) { return swept_gap(p, q, a0, a1); });
}

TEST(SeparatingLine, EveryPermittedVelocityKeepsTheDiscClearOfTheEdge) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-3, 3), len(0, 4), rad(0.05, 0.6), speed(0, 2),
      ang(0, 2 * std::acos(-1.0));
  const double taus[] = {0.1, 0.5, 2};
  int cases = 0;
  while (cases < 4000) {
    const Vec2 a0{u(rng), u(rng)};
    const double a = ang(rng), l = len(rng) * (cases % 10 == 0 ? 1e-3 : 1);  // some tiny edges
    const Vec2 a1{a0.x + l * std::cos(a), a0.y + l * std::sin(a)};
    const Vec2 p{u(rng), u(rng)};
    const double r = rad(rng);
    if (!(std::sqrt(dist2_to_segment(a0, a1, p.x, p.y)) >= r + kLineSkin)) continue;
    const double ws = speed(rng), wa = ang(rng);
    check_line(a0, a1, p, r, taus[cases % 3], ws * std::cos(wa), ws * std::sin(wa), rng);
    ++cases;
  }
}

// Adversarial placements: beside an end on the edge's own line, barely clear of an end or of the
// edge, a wish straight at the end or along the edge, no wish, a point edge.
TEST(SeparatingLine, HoldsAtTheEdgesOfItsCases) {
  std::mt19937_64 rng(11);
  const Vec2 a0{0, 0}, a1{2, 0};
  const double r = 0.25, tau = 0.5, clear = r + kLineSkin;
  const Vec2 places[] = {
      {-0.3, 0},   {2.3, 0},    {-clear, 0},  {2 + clear, 0}, {1, clear},
      {1, -clear}, {-0.2, 0.2}, {2.18, 0.18}, {0, clear},     {-clear * 0.8, clear * 0.6},
      {5, 0.01},   {-1e-3, 0.3}};
  const double wishes[][2] = {{0, 0},    {1.34, 0}, {-1.34, 0}, {0, -1.34},
                              {0, 1.34}, {1, -1},   {-1, -1},   {3, 0.5}};
  for (const Vec2& p : places)
    for (const auto& w : wishes) check_line(a0, a1, p, r, tau, w[0], w[1], rng);
  for (const Vec2& p : places)
    for (const auto& w : wishes) check_line(a0, a0, p, r, tau, w[0], w[1], rng);
}

// Walking diagonally towards a wall into the door beside it (a post's face from (10, 4.5) down to
// (10, 0), the door above): the tangent at the nearest point is the wall's whole line and forbids
// the wish; the line through the post's corner that lets the agent pass it permits it.
TEST(SeparatingLine, LetsAnAgentPassADoorPostsCorner) {
  const Vec2 a0{10, 4.5}, a1{10, 0};
  const double r = 0.25, tau = 0.5, wx = 1.34 * 0.732, wy = 1.34 * 0.681;
  const double px = 9.37, py = 4.28;
  const SeparatingLine tangent{-1, 0, 10 - px};
  EXPECT_LT(line_room(tangent, wx, wy, r, tau), 0);
  const SeparatingLine l = separating_line(a0, a1, px, py, r, tau, wx, wy, kLineSkin);
  EXPECT_GE(line_room(l, wx, wy, r, tau), 0);
  // The path it permits passes the corner at least r away.
  EXPECT_GE(swept_gap({px, py}, {px + wx * tau, py + wy * tau}, a0, a1), r - 1e-9);
}

// Circles: every permitted velocity keeps the disc clear of the circle for tau (the path's
// segment stays R + r from the centre), the whole circle is behind the line, and the wish never
// gets less room than under the tangent at the nearest point.
TEST(SeparatingLine, EveryPermittedVelocityKeepsTheDiscClearOfTheCircle) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-3, 3), rad(0.05, 0.6), big(0.01, 2), speed(0, 2),
      ang(0, 2 * std::acos(-1.0));
  const double taus[] = {0.1, 0.5, 2};
  int cases = 0;
  while (cases < 4000) {
    const Vec2 c{u(rng), u(rng)}, p{u(rng), u(rng)};
    const double R = big(rng), r = rad(rng), tau = taus[cases % 3];
    const double qx = p.x - c.x, qy = p.y - c.y, ql = std::hypot(qx, qy);
    // Some barely clear, some a wish straight at the centre.
    if (!(ql >= R + r + kLineSkin)) continue;
    const double ws = speed(rng), wa = ang(rng);
    double wx = ws * std::cos(wa), wy = ws * std::sin(wa);
    if (cases % 7 == 0) {
      wx = -ws * qx / ql;
      wy = -ws * qy / ql;
    }
    SCOPED_TRACE(testing::Message()
                 << "circle (" << c.x << ", " << c.y << ") R " << R << ", agent (" << p.x << ", "
                 << p.y << ") r " << r << ", tau " << tau << ", wish (" << wx << ", " << wy << ")");
    const SeparatingLine l = separating_line(c.x, c.y, R, p.x, p.y, r, tau, wx, wy, kLineSkin);
    ASSERT_NEAR(std::hypot(l.nx, l.ny), 1.0, 1e-12);
    EXPECT_GE(l.d, r + kLineSkin - 1e-12);
    EXPECT_NEAR(qx * l.nx + qy * l.ny - R, l.d, 1e-12);  // a tangent: the circle behind it
    const SeparatingLine tangent{qx / ql, qy / ql, ql - R};
    EXPECT_GE(line_room(l, wx, wy, r, tau), line_room(tangent, wx, wy, r, tau) - 1e-12);
    expect_permitted_clear(l, p, r, tau, wx, wy, R + r, rng,
                           [&](Vec2 q) { return std::sqrt(dist2_to_segment(p, q, c.x, c.y)); });
    ++cases;
  }
}

// Passing a pillar: the wish goes by it 0.05 m clear, which the tangent at the nearest point
// forbids (it only lets the gap close at (d - r) / tau) and a tangent further round permits.
TEST(SeparatingLine, LetsAnAgentGlidePastAPillar) {
  const double R = 0.5, r = 0.25, tau = 0.5;
  const double px = -0.9, py = 0.8, wx = 1.34, wy = 0;  // passes 0.8 from the centre: 0.05 clear
  const SeparatingLine tangent{px / std::hypot(px, py), py / std::hypot(px, py),
                               std::hypot(px, py) - R};
  EXPECT_LT(line_room(tangent, wx, wy, r, tau), 0);
  const SeparatingLine l = separating_line(0, 0, R, px, py, r, tau, wx, wy, kLineSkin);
  EXPECT_GE(line_room(l, wx, wy, r, tau), 0);
}

}  // namespace
}  // namespace crowddb::steer
