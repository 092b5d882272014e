#include "io/import/builder.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "world/geometry.hpp"

namespace crowddb::io {
std::string fmt(double v) {
  std::ostringstream os;
  os.precision(15);
  os << v;
  return os.str();
}

DocBuilder::DocBuilder() {
  doc_ = nlohmann::json::object();
  doc_["goals"] = nlohmann::json::array();
  doc_["obstacles"] = nlohmann::json::array();
  doc_["agents"] = nlohmann::json::array();
}

std::string DocBuilder::disc_goal(Vec2 c, double arrival_radius, const std::string& origin,
                                  const nlohmann::json& wait) {
  extent_.add(c.x - arrival_radius, c.y - arrival_radius);
  extent_.add(c.x + arrival_radius, c.y + arrival_radius);
  nlohmann::json g = {{"x", c.x}, {"y", c.y}, {"arrival_radius", arrival_radius}};
  if (!wait.is_null()) g["wait"] = wait;
  return named_goal(std::move(g), origin);
}

std::string DocBuilder::named_goal(nlohmann::json g, const std::string& origin) {
  const std::string key = g.dump();
  if (auto it = goal_names_.find(key); it != goal_names_.end()) return it->second;
  const std::string name = "g" + std::to_string(doc_["goals"].size());
  g["name"] = name;
  origins_["/goals/" + std::to_string(doc_["goals"].size())] = origin;
  doc_["goals"].push_back(std::move(g));
  goal_names_[key] = name;
  return name;
}

std::string DocBuilder::area_goal(const std::vector<Vec2>& polygon, const std::string& origin,
                                  const nlohmann::json& wait) {
  nlohmann::json area = nlohmann::json::array();
  for (const Vec2& v : polygon) {
    area.push_back({v.x, v.y});
    extent_.add(v.x, v.y);
  }
  nlohmann::json g = {{"area", area}};
  if (!wait.is_null()) g["wait"] = wait;
  return named_goal(std::move(g), origin);
}

void DocBuilder::polygon(const std::vector<Vec2>& vertices, const std::string& origin) {
  nlohmann::json vs = nlohmann::json::array();
  for (const Vec2& v : vertices) {
    vs.push_back({v.x, v.y});
    extent_.add(v.x, v.y);
  }
  origins_["/obstacles/" + std::to_string(doc_["obstacles"].size())] = origin;
  doc_["obstacles"].push_back({{"type", "polygon"}, {"vertices", vs}});
  polygons_.push_back({vertices, 1});
}

void DocBuilder::circle(Vec2 c, double r, const std::string& origin) {
  origins_["/obstacles/" + std::to_string(doc_["obstacles"].size())] = origin;
  doc_["obstacles"].push_back({{"type", "circle"}, {"x", c.x}, {"y", c.y}, {"radius", r}});
  extent_.add(c.x - r, c.y - r);
  extent_.add(c.x + r, c.y + r);
  circles_.push_back({c.x, c.y, r, 1});
}

std::size_t DocBuilder::agent(nlohmann::json row, const std::string& origin) {
  const std::size_t i = doc_["agents"].size();
  origins_["/agents/" + std::to_string(i)] = origin;
  const double x = row.value("x", 0.0), y = row.value("y", 0.0), r = row.value("radius", 0.25);
  extent_.add(x - r, y - r);
  extent_.add(x + r, y + r);
  doc_["agents"].push_back(std::move(row));
  return i;
}

void DocBuilder::source(nlohmann::json src, const std::string& origin) {
  if (!doc_.contains("sources")) doc_["sources"] = nlohmann::json::array();
  origins_["/sources/" + std::to_string(doc_["sources"].size())] = origin;
  doc_["sources"].push_back(std::move(src));
}

void DocBuilder::warn(const std::string& kind, const std::string& text) {
  if (auto it = warning_index_.find(kind); it != warning_index_.end()) {
    ++warning_repeats_[it->second];
    return;
  }
  warning_index_[kind] = warnings_.size();
  warnings_.emplace_back(kind, text);
  warning_repeats_.push_back(0);
}

namespace {
constexpr std::size_t kScanned = 16;  // obstacles tested one by one before a lookup pays
}  // namespace

bool DocBuilder::touches_obstacle_by_scan(double x, double y, double r, std::size_t circles_from,
                                          std::size_t polygons_from) const {
  for (std::size_t k = circles_from; k < circles_.size(); ++k) {
    const CircleObstacle& c = circles_[k];
    if (discs_overlap(c.x - x, c.y - y, c.radius + r)) return true;
  }
  for (std::size_t k = polygons_from; k < polygons_.size(); ++k)
    if (disc_overlaps_polygon(polygons_[k].vertices, x, y, r)) return true;
  return false;
}

bool DocBuilder::free_by_scan(double x, double y, double r, bool agents) const {
  return !touches_obstacle_by_scan(x, y, r, 0, 0) && (!agents || !agents_.any_overlap(x, y, r, 0));
}

bool DocBuilder::free(double x, double y, double r, bool agents) const {
  Indexed& ix = indexed_;
  const std::size_t scanned = circles_.size() - ix.circles + polygons_.size() - ix.polygons;
  // Rebuilt when the scanned ones outnumber four times the root of the indexed ones: m obstacles
  // added one at a time between placements then cost O(m^1.5) tests and builds in all, not m^2
  // (rebuilding only when they doubled left half of them scanned at each placement).
  if (scanned > kScanned && scanned * scanned > 16 * (ix.circles + ix.polygons)) {
    ix.lookup = std::make_unique<ObstacleLookup>(circles_, polygons_);
    ix.circles = circles_.size();
    ix.polygons = polygons_.size();
  }
  if (ix.lookup) {
    // Obstacle k of the lookup: circle k below ix.circles, else polygon k - ix.circles.
    ix.lookup->candidates(x, y, std::max(r, 0.0), near_);
    for (const uint32_t k : near_) {
      if (k < ix.circles) {
        const CircleObstacle& c = circles_[k];
        if (discs_overlap(c.x - x, c.y - y, c.radius + r)) return false;
      } else if (const std::size_t p = k - ix.circles;
                 ix.lookup->disc_overlaps_polygon(p, polygons_[p].vertices, x, y, r)) {
        return false;
      }
    }
  }
  if (touches_obstacle_by_scan(x, y, r, ix.circles, ix.polygons)) return false;
  return !agents || !agents_.any_overlap(x, y, r, 0);
}

void DocBuilder::occupy(double x, double y, double r) {
  agents_.add(x, y, r);
}

Imported DocBuilder::finish() {
  Imported im;
  im.doc = std::move(doc_);
  im.origins = std::move(origins_);
  for (std::size_t k = 0; k < warnings_.size(); ++k) {
    std::string w = warnings_[k].second;
    if (warning_repeats_[k]) w += " (and " + std::to_string(warning_repeats_[k]) + " more like it)";
    im.warnings.push_back(std::move(w));
  }
  return im;
}

}  // namespace crowddb::io
