// Boost.Geometry lives in this translation unit only: it is heavy to compile.
#include "io/walkable_wkt.hpp"

// Boost 1.74's rescale policy trips GCC 12's -Wmaybe-uninitialized where it is inlined here.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/geometry.hpp>
#include <boost/geometry/geometries/multi_polygon.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>
#include <cmath>
#include <numbers>
#include <sstream>

namespace crowddb::io {
namespace bg = boost::geometry;
using Point = bg::model::d2::point_xy<double>;
using Polygon = bg::model::polygon<Point>;  // clockwise outer ring, closed
using Multi = bg::model::multi_polygon<Polygon>;

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
  auto subtract = [&](const Polygon& hole) {
    Multi out;
    bg::difference(area, hole, out);
    area = std::move(out);
  };
  for (const CircleObstacle& c : world.circles()) {
    std::vector<Vec2> pts;
    for (int i = 0; i < 64; ++i) {
      const double a = 2 * std::numbers::pi * i / 64;
      pts.push_back({c.x + c.radius * std::cos(a), c.y + c.radius * std::sin(a)});
    }
    subtract(ring_polygon(pts));
  }
  for (const PolygonObstacle& p : world.polygons()) subtract(ring_polygon(p.vertices));
  std::ostringstream os;
  os.precision(17);
  if (area.size() == 1)
    os << bg::wkt(area.front());
  else
    os << bg::wkt(area);
  return os.str();
}

}  // namespace crowddb::io
