// The line an ORCA agent keeps from an obstacle edge (src/steer/orca.cpp, "Obstacles"): a line
// with the whole edge on its far side; velocities v with v . n >= -(d - r) / tau keep the agent's
// disc (centre p, radius r, at distance d from the line along its unit normal n) on its side,
// hence clear of the edge, for tau.
//
// Any such line will do, and which one decides what the agent may do. The tangent at the nearest
// point is the one farthest from the agent, but it is the edge's whole line when that point is
// inside the edge: it forbids walking diagonally towards a wall into the door beside it, and
// past a door post's corner it forbids gliding by faster than the gap closes. Lines through one
// of the edge's ends can be turned so that the agent passes the end: of the candidates below,
// the one that leaves the agent's wish (its preferred velocity) the most room is taken, among
// those its disc is clear of (d >= r, so v = 0 stays permitted):
//   - the tangent at the nearest point (the only one when the disc overlaps the edge),
//   - the edge's own line,
//   - per end e, the line through e square to g = w + (p - e) / tau (the best of all lines
//     through e: room is g . n - r / tau), and the two through e that touch the disc.
// The candidates depend on the wish only through which one is picked: every one is valid. A
// circle's lines are its tangents, chosen the same way (the second overload).
#pragma once

#include <algorithm>
#include <cmath>

#include "world/geometry.hpp"

namespace crowddb::steer {

struct SeparatingLine {
  double nx = 0, ny = 0;  // unit normal, towards the agent
  double d = 0;           // the agent's centre's distance from the line
};

namespace detail {
// Lines through a point at q from the agent's centre (q = p - point, |q| = ql >= clear): the one
// square to g = w + q / tau (the most room for the wish among all lines through the point) and
// the two that touch the disc of radius `clear` around the agent; offer(nx, ny) for each.
template <class Offer>
void offer_through(double qx, double qy, double ql, double clear, double wx, double wy, double tau,
                   Offer&& offer) {
  const double gx = wx + qx / tau, gy = wy + qy / tau, gl = std::sqrt(gx * gx + gy * gy);
  if (gl > 0) offer(gx / gl, gy / gl);
  const double c = clear / ql, s = std::sqrt(std::max(0.0, 1 - c * c));
  const double hx = qx / ql, hy = qy / ql;
  offer(c * hx - s * hy, c * hy + s * hx);
  offer(c * hx + s * hy, c * hy - s * hx);
}
}  // namespace detail

// The line agent (px, py) of radius r with wish (wx, wy) keeps from the edge a0-a1 for tau.
// `skin` is added to r where a candidate must clear the disc.
inline SeparatingLine separating_line(const Vec2& a0, const Vec2& a1, double px, double py,
                                      double r, double tau, double wx, double wy, double skin) {
  const double u = segment_param(a0, a1, px, py);
  const double cx = a0.x + u * (a1.x - a0.x), cy = a0.y + u * (a1.y - a0.y);
  const double dx = px - cx, dy = py - cy, l = std::sqrt(dx * dx + dy * dy);
  const double ex = a1.x - a0.x, ey = a1.y - a0.y, el = std::sqrt(ex * ex + ey * ey);
  SeparatingLine best;
  if (l > 0) {
    best = {dx / l, dy / l, l};
  } else if (el > 0) {  // on the edge: its normal (either side; the caller skips back faces)
    best = {ey / el, -ex / el, 0};
  } else {
    return {1, 0, 0};  // a point edge with the centre on it: any direction, deterministic
  }
  const double clear = r + skin;
  if (!(l >= clear) || !(el > 0)) return best;
  auto room = [&](double nx, double ny, double d) { return wx * nx + wy * ny + (d - r) / tau; };
  double best_room = room(best.nx, best.ny, best.d);
  // A line through end e with normal n keeps the edge behind it when n . (other - e) <= 0, and
  // clears the disc when (p - e) . n >= r + skin.
  auto offer = [&](const Vec2& e, const Vec2& other, double nx, double ny) {
    const double d = (px - e.x) * nx + (py - e.y) * ny;
    if (!(d >= clear)) return;
    if ((other.x - e.x) * nx + (other.y - e.y) * ny > 1e-12 * el) return;
    const double w = room(nx, ny, d);
    if (w > best_room) {
      best_room = w;
      best = {nx, ny, d};
    }
  };
  // The edge's own line, normal on the agent's side.
  const double side = (px - a0.x) * ey - (py - a0.y) * ex;
  const double sn = side >= 0 ? 1.0 : -1.0;
  offer(a0, a1, sn * ey / el, -sn * ex / el);
  for (int k = 0; k < 2; ++k) {
    const Vec2& e = k == 0 ? a0 : a1;
    const Vec2& other = k == 0 ? a1 : a0;
    const double qx = px - e.x, qy = py - e.y, ql = std::sqrt(qx * qx + qy * qy);
    if (!(ql >= clear)) continue;
    detail::offer_through(qx, qy, ql, clear, wx, wy, tau,
                          [&](double nx, double ny) { offer(e, other, nx, ny); });
  }
  return best;
}

// The line agent (px, py) of radius r with wish (wx, wy) keeps from the circle (cx, cy) of radius
// R for tau: a tangent of the circle, so the whole circle is behind it. Of the one at the nearest
// point and the others the agent's disc is clear of, the one that leaves the wish the most room
// (room is g . m - (R + r) / tau, g = w + (p - c) / tau, m the normal): m along g when that clears
// the disc, else one of the two tangents whose lines touch the disc. Centre on the circle's
// centre: the normal (1, 0), deterministic.
inline SeparatingLine separating_line(double cx, double cy, double R, double px, double py,
                                      double r, double tau, double wx, double wy, double skin) {
  const double qx = px - cx, qy = py - cy, ql = std::sqrt(qx * qx + qy * qy);
  if (!(ql > 0)) return {1, 0, -R};
  SeparatingLine best{qx / ql, qy / ql, ql - R};
  const double clear = R + r + skin;
  if (!(ql >= clear)) return best;
  auto room = [&](double nx, double ny) { return wx * nx + wy * ny + (qx * nx + qy * ny) / tau; };
  double best_room = room(best.nx, best.ny);
  auto offer = [&](double nx, double ny) {
    const double d = qx * nx + qy * ny;
    if (!(d >= clear)) return;
    const double w = room(nx, ny);
    if (w > best_room) {
      best_room = w;
      best = {nx, ny, d - R};
    }
  };
  detail::offer_through(qx, qy, ql, clear, wx, wy, tau, offer);
  return best;
}

}  // namespace crowddb::steer
