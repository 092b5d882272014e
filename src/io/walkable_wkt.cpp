// Boost.Geometry lives in this translation unit only: it is heavy to compile.
#include "io/walkable_wkt.hpp"

#include "world/geometry.hpp"
#include "world/obstacle_lookup.hpp"

// Boost 1.74's rescale policy trips GCC 12's -Wmaybe-uninitialized where it is inlined here.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <algorithm>
// Boost.Geometry's default rescaling to integers overflows long long (undefined behaviour) on
// rings whose coordinates differ by many orders of magnitude (found by fuzzing trajectory
// files' WKT): floating point throughout instead, as Boost.Geometry does by default since 1.77.
#define BOOST_GEOMETRY_NO_ROBUSTNESS
#include <boost/geometry.hpp>
#include <boost/geometry/geometries/multi_polygon.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>
#include <cctype>
#include <cmath>
#include <numbers>
#include <set>
#include <sstream>

namespace crowddb::io {
namespace bg = boost::geometry;
using Point = bg::model::d2::point_xy<double>;
using Polygon = bg::model::polygon<Point>;  // clockwise outer ring, closed
using Multi = bg::model::multi_polygon<Polygon>;
using Ring = Polygon::ring_type;

namespace {

Polygon ring_polygon(const std::vector<Vec2>& pts) {
  Polygon p;
  for (const Vec2& v : pts) bg::append(p.outer(), Point(v.x, v.y));
  bg::correct(p);  // orientation and closure as Boost expects
  return p;
}

}  // namespace

std::string walkable_area_wkt(const World& world) {
  const Bounds& b = world.bounds();
  Multi area;
  area.push_back(
      ring_polygon({{b.xmin, b.ymin}, {b.xmax, b.ymin}, {b.xmax, b.ymax}, {b.xmin, b.ymax}}));
  // The obstacles united pairwise, level by level, then taken from the bounds at once.
  // (Subtracting them one at a time from an area that gains a hole each time was quadratic in
  // the obstacles: 12 s before the first tick among 5,000 boxes, minutes among 10^4 circles.)
  std::vector<Multi> blocked;
  for (const CircleObstacle& c : world.circles()) {
    std::vector<Vec2> pts;
    for (int i = 0; i < 64; ++i) {
      const double a = 2 * std::numbers::pi * i / 64;
      pts.push_back({c.x + c.radius * std::cos(a), c.y + c.radius * std::sin(a)});
    }
    blocked.push_back(Multi{ring_polygon(pts)});
  }
  for (const PolygonObstacle& p : world.polygons())
    blocked.push_back(Multi{ring_polygon(p.vertices)});
  while (blocked.size() > 1) {
    std::vector<Multi> next((blocked.size() + 1) / 2);
    for (std::size_t i = 0; i + 1 < blocked.size(); i += 2)
      bg::union_(blocked[i], blocked[i + 1], next[i / 2]);
    if (blocked.size() % 2) next.back() = std::move(blocked.back());
    blocked = std::move(next);
  }
  if (!blocked.empty()) {
    Multi out;
    bg::difference(area, blocked.front(), out);
    area = std::move(out);
  }
  std::ostringstream os;
  os.precision(17);
  if (area.size() == 1)
    os << bg::wkt(area.front());
  else
    os << bg::wkt(area);
  return os.str();
}

namespace {

[[noreturn]] void invalid(const std::string& what) {
  throw Error(Error::Kind::input, what);
}

std::string pt(const Point& p) {
  std::ostringstream os;
  os.precision(15);
  os << "(" << p.x() << " " << p.y() << ")";
  return os.str();
}

// Closure, size and finiteness of one ring, as read (before any correction).
void check_ring(const Ring& r, const std::string& name) {
  for (const Point& p : r)
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()))
      invalid(name + " has a non-finite coordinate");
  if (r.size() < 4)
    invalid(name + " has " + std::to_string(r.size()) +
            " points; a closed ring needs at least 4 (the last repeating the first)");
  if (!bg::equals(r.front(), r.back()))
    invalid(name + " is not closed: it starts at " + pt(r.front()) + " but ends at " +
            pt(r.back()));
}

const char* failure_text(bg::validity_failure_type f) {
  switch (f) {
    case bg::failure_few_points:
      return "a ring has too few distinct points";
    case bg::failure_wrong_topological_dimension:
      return "it has zero area";
    case bg::failure_spikes:
      return "a ring has a spike (it doubles back on itself)";
    case bg::failure_not_closed:
      return "a ring is not closed";
    case bg::failure_self_intersections:
      return "it is self-intersecting";
    case bg::failure_interior_rings_outside:
      return "a hole lies outside its polygon";
    case bg::failure_nested_interior_rings:
      return "holes are nested inside holes";
    case bg::failure_disconnected_interior:
      return "its holes cut the walkable area apart (split it into a MULTIPOLYGON)";
    case bg::failure_intersecting_interiors:
      return "polygons of the MULTIPOLYGON overlap";
    case bg::failure_invalid_coordinate:
      return "a coordinate is not finite";
    default:
      return "it is not a valid polygon";
  }
}

Polygon box_polygon(double x0, double y0, double x1, double y1) {
  Polygon p;
  bg::append(p.outer(), Point(x0, y0));
  bg::append(p.outer(), Point(x0, y1));
  bg::append(p.outer(), Point(x1, y1));
  bg::append(p.outer(), Point(x1, y0));
  bg::append(p.outer(), Point(x0, y0));
  return p;  // clockwise, closed: Boost's default polygon
}

// A hole-free polygon's outer ring as a counter-clockwise vertex list without the closing
// point, consecutive duplicates or collinear vertices.
std::vector<Vec2> simple_ring(const Polygon& p) {
  std::vector<Vec2> v;
  for (const Point& q : p.outer()) {
    const Vec2 a{q.x(), q.y()};
    if (!v.empty() && v.back().x == a.x && v.back().y == a.y) continue;
    v.push_back(a);
  }
  if (v.size() > 1 && v.front().x == v.back().x && v.front().y == v.back().y) v.pop_back();
  bool changed = true;
  while (changed && v.size() >= 3) {
    changed = false;
    for (std::size_t i = 0; i < v.size() && v.size() >= 3; ++i) {
      const Vec2& a = v[(i + v.size() - 1) % v.size()];
      const Vec2& b = v[i];
      const Vec2& c = v[(i + 1) % v.size()];
      if ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) == 0) {
        v.erase(v.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
      }
    }
  }
  std::reverse(v.begin(), v.end());  // Boost's outer rings run clockwise
  return v;
}

}  // namespace

struct WalkableArea::Impl {
  Multi area;
  // covers() away from the boundary: every ring (outer and holes, without the closing point) in
  // an obstacle lookup, whose edge grids answer the point's parity and its distance to the rings.
  std::vector<PolygonObstacle> rings;
  std::unique_ptr<ObstacleLookup> lookup;
  double near = 0;  // [m] points closer than this to a ring are left to Boost.Geometry
};

WalkableArea::WalkableArea(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
WalkableArea::~WalkableArea() = default;
WalkableArea::WalkableArea(WalkableArea&&) noexcept = default;
WalkableArea& WalkableArea::operator=(WalkableArea&&) noexcept = default;

WalkableArea WalkableArea::parse(std::string_view wkt) {
  std::string s(wkt);
  const auto first = s.find_first_not_of(" \t\r\n");
  std::string head;
  for (std::size_t i = first == std::string::npos ? s.size() : first;
       i < s.size() && std::isalpha(static_cast<unsigned char>(s[i])); ++i)
    head += static_cast<char>(std::toupper(static_cast<unsigned char>(s[i])));
  auto impl = std::make_unique<Impl>();
  Multi& m = impl->area;
  try {
    if (head == "MULTIPOLYGON") {
      bg::read_wkt(s, m);
    } else if (head == "POLYGON") {
      Polygon p;
      bg::read_wkt(s, p);
      m.push_back(std::move(p));
    } else {
      invalid("expected a WKT POLYGON or MULTIPOLYGON, got '" +
              (head.empty() ? s.substr(0, 20) : head) + "'");
    }
  } catch (const bg::read_wkt_exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    invalid("malformed WKT: " + what);
  } catch (const std::exception& e) {  // e.g. a coordinate Boost cannot convert
    invalid(std::string("malformed WKT: ") + e.what());
  }
  if (m.empty()) invalid("the walkable area is empty");
  for (std::size_t i = 0; i < m.size(); ++i) {
    const std::string poly = m.size() > 1 ? "polygon " + std::to_string(i + 1) + ": " : "";
    check_ring(m[i].outer(), poly + "the outer ring");
    for (std::size_t k = 0; k < m[i].inners().size(); ++k)
      check_ring(m[i].inners()[k], poly + "hole " + std::to_string(k + 1));
  }
  // A ring that crosses itself has no orientation to correct; name the edges.
  for (std::size_t i = 0; i < m.size(); ++i) {
    const std::string poly = m.size() > 1 ? "polygon " + std::to_string(i + 1) + ": " : "";
    auto crossing = [&](const Ring& r, const std::string& name) {
      std::vector<Vec2> v;
      for (std::size_t k = 0; k + 1 < r.size(); ++k)
        if (v.empty() || v.back().x != r[k].x() || v.back().y != r[k].y())
          v.push_back({r[k].x(), r[k].y()});
      if (v.size() >= 3 && v.front().x == v.back().x && v.front().y == v.back().y) v.pop_back();
      if (v.size() < 3) return;
      if (auto bad = first_self_intersection(v)) {
        if (!bad->named) invalid("invalid walkable area: it is self-intersecting: in " + name);
        auto edge = [&](std::size_t e) {
          const Vec2 &a = v[e], &b = v[(e + 1) % v.size()];
          return "the edge from " + pt(Point(a.x, a.y)) + " to " + pt(Point(b.x, b.y));
        };
        invalid("invalid walkable area: it is self-intersecting: in " + name + ", " +
                edge(bad->first) + " meets " + edge(bad->second));
      }
    };
    crossing(m[i].outer(), poly + "the outer ring");
    for (std::size_t k = 0; k < m[i].inners().size(); ++k)
      crossing(m[i].inners()[k], poly + "hole " + std::to_string(k + 1));
  }
  try {
    bg::correct(m);  // either orientation is fine
    bg::validity_failure_type failure = bg::no_failure;
    if (!bg::is_valid(m, failure)) {
      if (failure == bg::failure_self_intersections && m.size() > 1)
        invalid("invalid walkable area: polygons of the MULTIPOLYGON overlap or cross each other");
      if (failure == bg::failure_wrong_orientation)  // still, after correct(): a figure of eight
        invalid("invalid walkable area: it is self-intersecting (a ring crosses itself)");
      std::string msg;
      bg::is_valid(m, msg);
      // Boost's message names the point of a self-intersection; keep its first sentence(s).
      const auto cut = msg.find("; method");
      if (cut != std::string::npos) msg.resize(cut);
      invalid(std::string("invalid walkable area: ") + failure_text(failure) + " (" + msg + ")");
    }
    if (!(bg::area(m) > 0)) invalid("invalid walkable area: it has zero area");
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {  // Boost.Geometry on extreme coordinates
    invalid(std::string("invalid walkable area: ") + e.what());
  }
  double largest = 1;  // the largest coordinate's magnitude, for the rounding margin
  const auto add_ring = [&](const Ring& r) {
    PolygonObstacle o;
    for (std::size_t k = 0; k + 1 < r.size(); ++k) {  // (the last point closes the ring)
      o.vertices.push_back({r[k].x(), r[k].y()});
      largest = std::max({largest, std::abs(r[k].x()), std::abs(r[k].y())});
    }
    impl->rings.push_back(std::move(o));
  };
  for (const Polygon& p : m) {
    add_ring(p.outer());
    for (const Ring& h : p.inners()) add_ring(h);
  }
  impl->lookup = std::make_unique<ObstacleLookup>(std::span<const CircleObstacle>{}, impl->rings);
  impl->near = 1e-9 * largest;
  return WalkableArea(std::move(impl));
}

Bounds WalkableArea::envelope() const {
  const auto e = bg::return_envelope<bg::model::box<Point>>(impl_->area);
  return {e.min_corner().x(), e.min_corner().y(), e.max_corner().x(), e.max_corner().y()};
}

double WalkableArea::area() const {
  return bg::area(impl_->area);
}

bool WalkableArea::covers(double x, double y) const {
  // A point farther than `near` from every ring is inside exactly when an odd number of rings
  // hold it (the rings of a valid area do not cross; holes lie inside their outer ring), and the
  // even-odd test cannot round the wrong way there: its crossings are accurate to ~1e-15 of the
  // coordinates, a millionth of `near`. Closer points, and only those, take Boost.Geometry's
  // covered_by, as every point did before. So each point costs the rings and edges near it, not
  // every vertex (the loader asks for every agent and goal).
  const Impl& a = *impl_;
  if (!(std::isfinite(x) && std::isfinite(y))) return covers_by_boost(x, y);
  thread_local std::vector<uint32_t> rings;
  a.lookup->candidates(x, y, a.near, rings);
  bool in = false;
  for (const uint32_t k : rings) {
    const std::vector<Vec2>& ring = a.rings[k].vertices;
    if (a.lookup->polygon_dist2(k, ring, x, y, a.near) <= a.near * a.near)
      return covers_by_boost(x, y);
    in ^= a.lookup->polygon_holds(k, ring, x, y);
  }
  return in;
}

bool WalkableArea::covers_by_boost(double x, double y) const {
  return bg::covered_by(Point(x, y), impl_->area);
}

bool WalkableArea::within(const Bounds& b) const {
  const Bounds e = envelope();
  return e.xmin >= b.xmin && e.ymin >= b.ymin && e.xmax <= b.xmax && e.ymax <= b.ymax;
}

std::vector<std::vector<Vec2>> WalkableArea::blocked_pieces(const Bounds& b) const {
  try {
    return split_blocked(b);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {  // Boost.Geometry's overlay on extreme coordinates
    invalid(std::string("walkable area: could not compute the blocked area: ") + e.what());
  }
}

std::vector<std::vector<Vec2>> WalkableArea::split_blocked(const Bounds& b) const {
  Multi rest;
  bg::difference(box_polygon(b.xmin, b.ymin, b.xmax, b.ymax), impl_->area, rest);
  std::vector<Polygon> work(rest.begin(), rest.end());
  std::vector<std::vector<Vec2>> out;
  const double tiny = 1e-12 * b.width() * b.height();
  std::size_t guard = 0;
  while (!work.empty()) {
    if (++guard > 100'000)
      invalid("walkable area: could not split the blocked area into simple polygons");
    Polygon p = std::move(work.back());
    work.pop_back();
    if (std::abs(bg::area(p)) <= tiny) continue;
    if (p.inners().empty()) {
      auto ring = simple_ring(p);
      if (ring.size() >= 3) out.push_back(std::move(ring));
      continue;
    }
    // Cut along y = c through the first hole, avoiding vertex heights: each half has fewer holes
    // (the cut hole opens onto the cut line).
    const Ring& hole = p.inners().front();
    double lo = INFINITY, hi = -INFINITY;
    for (const Point& q : hole) {
      lo = std::min(lo, q.y());
      hi = std::max(hi, q.y());
    }
    std::set<double> heights;
    for (const Point& q : p.outer()) heights.insert(q.y());
    for (const Ring& r : p.inners())
      for (const Point& q : r) heights.insert(q.y());
    double c = (lo + hi) / 2;
    if (heights.count(c)) {
      auto above = heights.upper_bound(c);
      c = (c + *above) / 2;  // `hi` is a vertex height above c, so `above` exists
    }
    const auto e = bg::return_envelope<bg::model::box<Point>>(p);
    const double x0 = e.min_corner().x() - 1, x1 = e.max_corner().x() + 1;
    for (const Polygon& half : {box_polygon(x0, e.min_corner().y() - 1, x1, c),
                                box_polygon(x0, c, x1, e.max_corner().y() + 1)}) {
      Multi part;
      bg::intersection(p, half, part);
      for (Polygon& q : part) work.push_back(std::move(q));
    }
  }
  // Deterministic order: by lowest-leftmost vertex.
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& c) {
    auto key = [](const std::vector<Vec2>& r) {
      Vec2 m = r[0];
      for (const Vec2& v : r)
        if (v.y < m.y || (v.y == m.y && v.x < m.x)) m = v;
      return std::pair{m.y, m.x};
    };
    return key(a) < key(c);
  });
  return out;
}

}  // namespace crowddb::io
