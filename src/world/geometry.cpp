#include "world/geometry.hpp"

#include <algorithm>

namespace crowddb {
namespace {

int orientation(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double v = cross(b.x - a.x, b.y - a.y, c.x - a.x, c.y - a.y);
  return (v > 0) - (v < 0);
}

bool on_segment(const Vec2& a, const Vec2& b, const Vec2& p) {
  return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
         p.y <= std::max(a.y, b.y);
}

bool segments_touch(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const int o1 = orientation(a, b, c), o2 = orientation(a, b, d);
  const int o3 = orientation(c, d, a), o4 = orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
         (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b));
}

}  // namespace

std::optional<std::pair<std::size_t, std::size_t>> first_self_intersection(
    std::span<const Vec2> ring) {
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = ring[i];
    const Vec2& b = ring[(i + 1) % n];
    if (a.x == b.x && a.y == b.y) return std::pair{i, (i + 1) % n};  // repeated vertex
    for (std::size_t j = i + 1; j < n; ++j) {
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      const Vec2& c = ring[j];
      const Vec2& d = ring[(j + 1) % n];
      if (adjacent) {
        // Adjacent edges share one vertex; they may not fold back onto each other.
        const Vec2& shared = (j == i + 1) ? b : a;
        const Vec2& p = (j == i + 1) ? a : b;
        const Vec2& q = (j == i + 1) ? d : c;
        if (orientation(p, shared, q) == 0 &&
            (p.x - shared.x) * (q.x - shared.x) + (p.y - shared.y) * (q.y - shared.y) > 0)
          return std::pair{i, j};
        continue;
      }
      if (segments_touch(a, b, c, d)) return std::pair{i, j};
    }
  }
  return std::nullopt;
}

}  // namespace crowddb
