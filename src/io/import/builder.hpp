// What the importers share: building a crowddb scenario document element by element, remembering
// where each element came from, and placing agents at random without overlaps.
#pragma once

#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "crowddb/world.hpp"
#include "io/import/importer.hpp"
#include "util/rng.hpp"
#include "world/obstacle_lookup.hpp"
#include "world/placement_grid.hpp"

namespace crowddb::io {

struct Box {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  bool empty() const { return !(x0 <= x1 && y0 <= y1); }
  void add(double x, double y) {
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x);
    y1 = std::max(y1, y);
  }
  void add(const Box& b) {
    if (b.empty()) return;
    add(b.x0, b.y0);
    add(b.x1, b.y1);
  }
};

class DocBuilder {
 public:
  DocBuilder();

  nlohmann::json& doc() { return doc_; }

  // Goals. Identical goals share one entry (and name); `origin` is "file:LINE: <element>".
  // `wait` not null: the goal's "wait" (scenario-format.md; goals that differ in it are
  // different goals).
  std::string disc_goal(Vec2 c, double arrival_radius, const std::string& origin,
                        const nlohmann::json& wait = nullptr);
  std::string area_goal(const std::vector<Vec2>& polygon, const std::string& origin,
                        const nlohmann::json& wait = nullptr);

  // Obstacles (polygons in either orientation; the reader checks them).
  void polygon(const std::vector<Vec2>& vertices, const std::string& origin);
  void circle(Vec2 c, double r, const std::string& origin);

  // An explicit agent row (x, y, radius, goal ... as in the format); returns its index.
  std::size_t agent(nlohmann::json row, const std::string& origin);
  std::size_t agent_count() const { return doc_["agents"].size(); }

  // A source (the format's "sources" entry).
  void source(nlohmann::json src, const std::string& origin);

  // A warning about something dropped or approximated. Repeats of the same `kind` are counted
  // into the first one ("... (and 12 more like it)"), so a file with 400 unsupported elements of
  // one kind gives one line.
  void warn(const std::string& kind, const std::string& text);

  // Everything added so far (agents as discs, obstacles, goals).
  const Box& extent() const { return extent_; }

  // Is a disc free of the obstacles added so far and (with `agents`) of the discs occupied?
  // The obstacles through a lookup once there are many (SteerSuite's obstacle regions hold
  // thousands of boxes, each placed with this test, and then thousands of agents).
  bool free(double x, double y, double r, bool agents = true) const;
  // The same answer by testing every obstacle: free's oracle (tests).
  bool free_by_scan(double x, double y, double r, bool agents = true) const;
  // Remembers an agent disc for `free` (explicit agents too, so random ones avoid them).
  void occupy(double x, double y, double r);

  Imported finish();

 private:
  // The goal `g` under a new name, or the name of an identical goal added before.
  std::string named_goal(nlohmann::json g, const std::string& origin);
  nlohmann::json doc_;
  Origins origins_;
  std::vector<std::pair<std::string, std::string>> warnings_;  // kind, text
  std::map<std::string, std::size_t> warning_index_;
  std::vector<std::size_t> warning_repeats_;
  std::map<std::string, std::string> goal_names_;  // goal JSON text -> name
  Box extent_;
  bool touches_obstacle_by_scan(double x, double y, double r, std::size_t circles_from,
                                std::size_t polygons_from) const;
  std::vector<PolygonObstacle> polygons_;
  std::vector<CircleObstacle> circles_;
  // Circles [0, circles) and polygons [0, polygons) in a lookup, the ones added since scanned
  // (rebuilt as they grow: DocBuilder::free).
  struct Indexed {
    std::unique_ptr<ObstacleLookup> lookup;
    std::size_t circles = 0, polygons = 0;
  };
  mutable Indexed indexed_;
  mutable std::vector<uint32_t> near_;  // the lookup's candidates, kept between calls
  PlacementGrid agents_{2.0};           // agent discs (cells of 2 m: agents are 0.2-0.5 m)
};

// Distance formatting for messages: shortest form.
std::string fmt(double v);

}  // namespace crowddb::io
