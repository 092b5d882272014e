// The nearest of a list of points to a query, as a loop over the list that keeps the first point
// strictly nearer by std::hypot gives it, without that loop: a scenario group's "nearest" goal
// assignment looped over every goal for every agent, and a group's goals default to all the
// world's (one per agent after a group with "targets"): 10^5 agents over 10^5 goals made 10^10
// distances before the first tick.
//
// The points go into a k-d tree: median splits on the longer side of each node's box, leaves of
// at most kLeaf points, each node's box the exact bounds of its points. A query walks it nearer
// child first and skips a node when the distance from the query to the node's box exceeds the
// best distance found by more than any rounding could make up: the box's distance is computed
// from the same differences, rounded the same way, never larger per axis than a point's inside
// it, and std::hypot is accurate to about an ulp, so a relative 1e-12 covers it. Every point
// that could equal or beat the loop's answer is read, and among them the least (distance, list
// position) pair is the loop's choice: bit for bit, ties included. Clusters and queries far from
// every point cost a walk down the tree like any other (a grid of cells sized for the mean
// spacing, used until 2026-12-06, read all the points for both). Lists of few points, and
// queries or points that are not finite, take the loop itself. The loop stays as the oracle
// (tests/world/nearest_point_test.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

#include "world/geometry.hpp"

namespace crowddb {

class NearestPoint {
 public:
  // Fewer points are cheaper to loop over than to index.
  static constexpr std::size_t kMinPoints = 64;
  static constexpr std::size_t kNone = SIZE_MAX;

  explicit NearestPoint(std::vector<Vec2> points) : points_(std::move(points)) {
    if (points_.size() < kMinPoints || points_.size() > UINT32_MAX) return;
    for (const Vec2& p : points_)
      if (!(std::isfinite(p.x) && std::isfinite(p.y))) return;  // the loop answers
    order_.resize(points_.size());
    std::iota(order_.begin(), order_.end(), 0u);
    nodes_.reserve(4 * (points_.size() / kLeaf) + 1);
    nodes_.resize(1);
    build(0, 0, static_cast<uint32_t>(points_.size()));
  }

  // The loop's answer: the position in the list of the first point p with the least
  // std::hypot(p.x - x, p.y - y), among distances below infinity; kNone where there is none
  // (no points, or every distance infinite or NaN). `read`, when given, gets the number of
  // points whose distance was computed.
  std::size_t nearest(double x, double y, std::size_t* read = nullptr) const {
    if (nodes_.empty() || !(std::isfinite(x) && std::isfinite(y))) {
      if (read) *read = points_.size();
      return loop(x, y);
    }
    double best = INFINITY;
    std::size_t best_k = kNone, distances = 0;
    struct Pending {
      uint32_t node;
      double lower;  // the distance from the query to the node's box
    };
    // Each level pushes two and pops one: at most the tree's depth + 1 entries, and median
    // splits of fewer than 2^32 points into leaves of 8 are at most 30 levels deep.
    std::array<Pending, 64> stack;
    std::size_t top = 0;
    stack[top++] = {0, box_distance(nodes_[0], x, y)};
    while (top > 0) {
      const Pending at = stack[--top];
      if (cannot_reach(at.lower, best)) continue;
      const Node& node = nodes_[at.node];
      if (node.left == kLeafNode) {
        for (uint32_t a = node.begin; a < node.end; ++a) {
          const uint32_t p = order_[a];
          const double d = std::hypot(points_[p].x - x, points_[p].y - y);
          if (d < best || (d == best && best_k != kNone && p < best_k)) {
            best = d;
            best_k = p;
          }
        }
        distances += node.end - node.begin;
        continue;
      }
      const uint32_t l = node.left, r = node.left + 1;
      const double dl = box_distance(nodes_[l], x, y), dr = box_distance(nodes_[r], x, y);
      // The nearer child on top: it is read first and tightens the bound for the other.
      if (dl <= dr) {
        stack[top++] = {r, dr};
        stack[top++] = {l, dl};
      } else {
        stack[top++] = {l, dl};
        stack[top++] = {r, dr};
      }
    }
    if (read) *read = distances;
    return best_k;
  }

  // The loop itself: the oracle, and the answer for few points.
  std::size_t loop(double x, double y) const {
    double best = INFINITY;
    std::size_t best_k = kNone;
    for (std::size_t p = 0; p < points_.size(); ++p) {
      const double d = std::hypot(points_[p].x - x, points_[p].y - y);
      if (d < best) {
        best = d;
        best_k = p;
      }
    }
    return best_k;
  }

  // Whether queries walk the tree (else the loop): for tests.
  bool indexed() const { return !nodes_.empty(); }

 private:
  static constexpr uint32_t kLeaf = 8;      // points per leaf, at most
  static constexpr uint32_t kLeafNode = 0;  // Node::left of a leaf (the root is no one's child)

  struct Node {
    BoxBounds box;        // the exact bounds of the node's points
    uint32_t begin, end;  // its points: order_[begin, end)
    uint32_t left;        // children at left and left + 1; kLeafNode for a leaf
  };

  // No point in a box at distance `lower` (as box_distance computes it) can come within `best`:
  // its own distance is at least lower less hypot's rounding (and a subnormal's ulp). glibc's
  // hypot is monotone (10^8 random pairs of neighbouring doubles, 2026-12-06), so the margin
  // never decides there and no test can make it; it is kept for C libraries whose hypot is not.
  static bool cannot_reach(double lower, double best) {
    return lower * (1 - 1e-12) > best + 1e-300;
  }

  // The distance from (x, y) to the box: each axis's difference from the nearer side, rounded
  // as a point's difference inside the box would be, so never above it (rounding is monotone).
  static double box_distance(const Node& n, double x, double y) {
    const double dx = x < n.box.x0 ? n.box.x0 - x : x > n.box.x1 ? x - n.box.x1 : 0;
    const double dy = y < n.box.y0 ? n.box.y0 - y : y > n.box.y1 ? y - n.box.y1 : 0;
    return std::hypot(dx, dy);
  }

  // Fills nodes_[at] with the node over order_[begin, end) and builds its subtree: children
  // side by side at the end of nodes_ (the left one's subtree follows both).
  void build(uint32_t at, uint32_t begin, uint32_t end) {
    BoxBounds box;  // (empty)
    for (uint32_t a = begin; a < end; ++a) {
      const Vec2& p = points_[order_[a]];
      box = {std::min(box.x0, p.x), std::min(box.y0, p.y), std::max(box.x1, p.x),
             std::max(box.y1, p.y)};
    }
    nodes_[at] = {box, begin, end, kLeafNode};
    if (end - begin <= kLeaf) return;
    // Split at the median of the longer side (ties by list position: the same tree every run).
    const bool by_x = box.x1 - box.x0 >= box.y1 - box.y0;
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](uint32_t a, uint32_t b) {
                       const double ca = by_x ? points_[a].x : points_[a].y;
                       const double cb = by_x ? points_[b].x : points_[b].y;
                       return ca < cb || (ca == cb && a < b);
                     });
    const auto left = static_cast<uint32_t>(nodes_.size());
    nodes_[at].left = left;
    nodes_.resize(nodes_.size() + 2);
    build(left, begin, mid);
    build(left + 1, mid, end);
  }

  std::vector<Vec2> points_;
  std::vector<uint32_t> order_;  // the points, leaf by leaf
  std::vector<Node> nodes_;      // the root first; empty: the loop answers
};

}  // namespace crowddb
