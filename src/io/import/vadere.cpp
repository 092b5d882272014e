// Vadere .scenario files (JSON; releases 0.1 to 2.4), read the way Vadere reads them after its own
// migration chain (VadereSimulator/src/org/vadere/simulator/projects/migration): the release
// number is not trusted, each element is recognised by its keys (a source with "spawner" is 2.4,
// one whose "interSpawnTimeDistribution" is a class name is 1.16 or older, a root "vadere" is
// 0.1). Vadere's locomotion models (OSM, SFM, GNM, CA, BHM ...) do not exist here: the geometry,
// the agents, their target lists and the spawn schedule are imported, crowddb's orca steers, and
// the path service walks around obstacles where Vadere's floor field would.
// docs/importers/vadere.md lists every element and key and what becomes of it; every drop or
// approximation is also a one-line warning "file:LINE: /json/pointer: what".
//
// nlohmann::json keeps no positions, so a second pass over the (valid) text records the line
// where every value starts, keyed by a hash of its JSON pointer (LineIndex); errors, warnings and
// the origins handed to the scenario reader all name that line. Both passes, and everything after
// them, are linear in the input (spawn counts are computed, never simulated, and capped at 10^7).
#include "io/import/vadere.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <unordered_set>

#include "crowddb/error.hpp"
#include "io/import/builder.hpp"
#include "util/utf8.hpp"
#include "world/geometry.hpp"

namespace crowddb::io {
namespace {

using nlohmann::json;

constexpr double kDeletionDistance = 0.1;  // [m] AttributesTarget: reach tolerance
constexpr double kBoundingBoxWidth = 0.5;  // [m] AttributesTopography: the border walls
constexpr double kBorderGrow = 0.0001;     // [m] Topography.createObstacleBoundary's overlap
constexpr double kFinishTime = 500;        // [s] AttributesSimulation
constexpr double kStepLength = 0.4;        // [s] AttributesSimulation
constexpr double kMaxDt = 0.1;             // [s] crowddb's tick for Vadere's larger model steps
constexpr double kBurstRate = 1e9;         // [1/s] one spawn event: all its agents due at once
constexpr double kMaxSourceAgents = 1e7;   // the scenario reader's bound per source
constexpr double kMinSpeed = 0.05;         // [m/s] lowest preferred speed of a speed range
constexpr int kCircleSides = 32;           // a CIRCLE source as a polygon

// -- JSON pointers and lines --------------------------------------------------------------------

constexpr uint64_t kFnvBasis = 14695981039346656037ull;
constexpr uint64_t kFnvPrime = 1099511628211ull;

// RFC 6901: "~" -> "~0", "/" -> "~1".
std::string escape_token(std::string_view key) {
  std::string out;
  for (char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

// FNV-1a of the pointer text, extended by one token: hash(parent + "/" + token).
uint64_t child_hash(uint64_t h, std::string_view escaped_token) {
  h = (h ^ static_cast<unsigned char>('/')) * kFnvPrime;
  for (char c : escaped_token) h = (h ^ static_cast<unsigned char>(c)) * kFnvPrime;
  return h;
}

uint32_t hex4(std::string_view t, std::size_t i) {
  uint32_t v = 0;
  for (std::size_t k = i; k < i + 4 && k < t.size(); ++k) {
    const char c = t[k];
    const uint32_t d = c >= '0' && c <= '9'   ? static_cast<uint32_t>(c - '0')
                       : c >= 'a' && c <= 'f' ? static_cast<uint32_t>(c - 'a' + 10)
                       : c >= 'A' && c <= 'F' ? static_cast<uint32_t>(c - 'A' + 10)
                                              : 0;
    v = v * 16 + d;
  }
  return v;
}

// The string starting at t[i] == '"', decoded into `out` (when given) as nlohmann decodes it.
// Returns the index after the closing quote.
std::size_t read_string(std::string_view t, std::size_t i, std::string* out) {
  ++i;
  while (i < t.size() && t[i] != '"') {
    if (t[i] != '\\') {
      if (out) *out += t[i];
      ++i;
      continue;
    }
    if (i + 1 >= t.size()) return t.size();
    const char e = t[i + 1];
    i += 2;
    if (e != 'u') {
      if (out)
        *out += e == 'n'   ? '\n'
                : e == 't' ? '\t'
                : e == 'r' ? '\r'
                : e == 'b' ? '\b'
                : e == 'f' ? '\f'
                           : e;
      continue;
    }
    uint32_t cp = hex4(t, i);
    i += 4;
    if (cp >= 0xD800 && cp < 0xDC00 && i + 6 <= t.size() && t[i] == '\\' && t[i + 1] == 'u') {
      const uint32_t lo = hex4(t, i + 2);
      if (lo >= 0xDC00 && lo < 0xE000) {
        cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
        i += 6;
      }
    }
    if (out) append_utf8(*out, cp);
  }
  return std::min(i + 1, t.size());
}

// The line where each value of a JSON text starts, by the hash of its pointer. One pass with an
// explicit stack (deep nesting costs heap, not call stack). Repeated keys in an object are an
// error here, as in Vadere (Jackson's STRICT_DUPLICATE_DETECTION); nlohmann keeps the last.
class LineIndex {
 public:
  // `text` has been accepted by nlohmann (so it is valid JSON); the scan still never reads past
  // its end.
  LineIndex(std::string_view t, const std::string& file) {
    // A frame keeps only its own pointer token, not its pointer: copies of the pointer in every
    // frame took memory quadratic in the depth (a 2 MB file of nested arrays ran out of 24 GB).
    struct Frame {
      bool object;
      uint64_t h;
      std::string token;  // how the parent reaches this container (for the message only)
      std::size_t index = 0;
      std::unordered_set<std::string> keys;
    };
    std::vector<Frame> stack;
    // The pointer of the innermost container, built only for the duplicate-key message.
    const auto pointer_of_stack = [&] {
      std::string p;
      for (std::size_t k = 1; k < stack.size(); ++k) p += "/" + stack[k].token;
      return p.empty() ? std::string("/") : p;
    };
    std::size_t i = 0;
    uint32_t ln = 1;
    if (t.substr(0, 3) == "\xEF\xBB\xBF") i = 3;
    const auto ws = [&] {
      while (i < t.size() && (t[i] == ' ' || t[i] == '\t' || t[i] == '\n' || t[i] == '\r')) {
        if (t[i] == '\n') ++ln;
        ++i;
      }
    };
    uint64_t h = kFnvBasis;
    std::string current;  // the pointer token of the value at i
    // Positions i at the next member's value (h, pointer set); false when the text ends.
    const auto next_member = [&](Frame& f) {
      std::string token;
      if (f.object) {
        if (i >= t.size() || t[i] != '"') return false;
        std::string key;
        i = read_string(t, i, &key);
        if (!f.keys.insert(key).second)
          throw Error(Error::Kind::input, file + ":" + std::to_string(ln) + ": " +
                                              pointer_of_stack() + ": duplicate key \"" + key +
                                              "\" (Vadere rejects repeated keys)");
        ws();
        if (i >= t.size() || t[i] != ':') return false;
        ++i;
        ws();
        token = escape_token(key);
      } else {
        token = std::to_string(f.index);
      }
      h = child_hash(f.h, token);
      current = std::move(token);
      return true;
    };
    ws();
    bool more = i < t.size();
    while (more) {
      lines_.emplace_back(h, ln);
      const char c = t[i];
      bool descended = false;
      if (c == '{' || c == '[') {
        stack.push_back(Frame{c == '{', h, std::move(current), 0, {}});
        ++i;
        ws();
        if (i < t.size() && (t[i] == '}' || t[i] == ']')) {
          ++i;
          stack.pop_back();
        } else {
          if (!next_member(stack.back())) break;
          descended = true;
        }
      } else if (c == '"') {
        i = read_string(t, i, nullptr);
      } else {
        while (i < t.size() && t[i] != ',' && t[i] != ']' && t[i] != '}' && t[i] != ' ' &&
               t[i] != '\t' && t[i] != '\n' && t[i] != '\r')
          ++i;
      }
      if (descended) continue;
      // After a value: the next member, or the end of one or more containers.
      more = false;
      while (!stack.empty()) {
        ws();
        if (i >= t.size()) break;
        if (t[i] == ',') {
          ++i;
          ws();
          ++stack.back().index;
          more = next_member(stack.back()) && i < t.size();
          break;
        }
        ++i;  // '}' or ']'
        stack.pop_back();
      }
    }
    std::sort(lines_.begin(), lines_.end());
  }

  // The line of the value whose pointer hashes to `h`; 0 when unknown.
  uint32_t line(uint64_t h) const {
    const auto it =
        std::lower_bound(lines_.begin(), lines_.end(), std::pair<uint64_t, uint32_t>{h, 0});
    return it != lines_.end() && it->first == h ? it->second : 0;
  }

 private:
  std::vector<std::pair<uint64_t, uint32_t>> lines_;  // (pointer hash, line), sorted
};

// A value of the document and where it is.
struct Val {
  const json* j = nullptr;
  std::string ptr;  // JSON pointer; "" is the root
  uint64_t h = kFnvBasis;
  uint32_t line = 1;
};

// -- geometry -----------------------------------------------------------------------------------

struct VadereShape {
  enum class Kind { rectangle, polygon, circle };
  Kind kind = Kind::polygon;
  std::vector<Vec2> points;  // a rectangle's four corners, a polygon's points (implicitly closed)
  Vec2 centre{};
  double radius = 0;
  Box box;
};

struct Rect {
  double x0, y0, x1, y1;
  bool contains(const Box& b, double tol = 0) const {
    return b.x0 >= x0 - tol && b.y0 >= y0 - tol && b.x1 <= x1 + tol && b.y1 <= y1 + tol;
  }
  bool contains(Vec2 p) const { return p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1; }
  bool misses(const Box& b) const { return b.x1 <= x0 || b.x0 >= x1 || b.y1 <= y0 || b.y0 >= y1; }
};

// Sutherland-Hodgman: the part of the polygon inside the rectangle (for a concave polygon that
// leaves the rectangle more than once, edges along the border may overlap: the scenario reader
// then names it).
std::vector<Vec2> clip(const std::vector<Vec2>& poly, const Rect& r) {
  std::vector<Vec2> out = poly;
  for (int side = 0; side < 4 && !out.empty(); ++side) {
    const auto inside = [&](Vec2 p) {
      switch (side) {
        case 0:
          return p.x >= r.x0;
        case 1:
          return p.x <= r.x1;
        case 2:
          return p.y >= r.y0;
        default:
          return p.y <= r.y1;
      }
    };
    const auto cut = [&](Vec2 a, Vec2 b) {
      const bool vertical = side < 2;
      const double edge = side == 0 ? r.x0 : side == 1 ? r.x1 : side == 2 ? r.y0 : r.y1;
      const double s = vertical ? (edge - a.x) / (b.x - a.x) : (edge - a.y) / (b.y - a.y);
      return vertical ? Vec2{edge, a.y + s * (b.y - a.y)} : Vec2{a.x + s * (b.x - a.x), edge};
    };
    std::vector<Vec2> in;
    in.swap(out);
    for (std::size_t k = 0; k < in.size(); ++k) {
      const Vec2 a = in[(k + in.size() - 1) % in.size()], b = in[k];
      if (inside(b)) {
        if (!inside(a)) out.push_back(cut(a, b));
        out.push_back(b);
      } else if (inside(a)) {
        out.push_back(cut(a, b));
      }
    }
  }
  std::vector<Vec2> dedup;
  for (const Vec2& p : out)
    if (dedup.empty() || dedup.back().x != p.x || dedup.back().y != p.y) dedup.push_back(p);
  while (dedup.size() > 1 && dedup.front().x == dedup.back().x && dedup.front().y == dedup.back().y)
    dedup.pop_back();
  if (dedup.size() < 3 || signed_area(dedup) == 0) return {};
  return dedup;
}

// A polygon whose edges cross or touch, cut into simple pieces at the first crossing until none
// is left (each cut leaves both pieces with fewer vertices, so it ends). Vadere fills such a
// polygon by the non-zero winding rule; the pieces do not cross each other, so the winding number
// inside a piece is the sum of the orientations of the pieces around it, and the pieces cover
// the filled area exactly when none of them encloses a winding number of 0 (a hole, which simple
// polygons cannot leave open): `holes` says whether one does. Polygons of more than `kMaxSplit`
// vertices are not split (the scenario reader then names them).
constexpr std::size_t kMaxSplit = 256;

bool strictly_inside(const std::vector<Vec2>& ring, Vec2 p) {
  return point_in_polygon(ring, p.x, p.y) && dist2_to_boundary(ring, p.x, p.y) > 0;
}

bool holes(const std::vector<std::vector<Vec2>>& pieces) {
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    double winding = signed_area(pieces[i]) > 0 ? 1 : -1;
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      if (k == i) continue;
      bool inside = false;
      for (const Vec2& v : pieces[i]) inside = inside || strictly_inside(pieces[k], v);
      if (inside) winding += signed_area(pieces[k]) > 0 ? 1 : -1;
    }
    if (winding == 0) return true;
  }
  return false;
}

std::vector<std::vector<Vec2>> simple_pieces(const std::vector<Vec2>& ring) {
  std::vector<std::vector<Vec2>> todo = {ring}, out;
  if (ring.size() > kMaxSplit) return {};
  const auto clean = [](std::vector<Vec2> r) {
    std::vector<Vec2> c;
    for (const Vec2& p : r)
      if (c.empty() || c.back().x != p.x || c.back().y != p.y) c.push_back(p);
    while (c.size() > 1 && c.front().x == c.back().x && c.front().y == c.back().y) c.pop_back();
    return c;
  };
  while (!todo.empty()) {
    std::vector<Vec2> r = clean(std::move(todo.back()));
    todo.pop_back();
    if (r.size() < 3) continue;
    const auto bad = first_self_intersection(r);
    if (!bad || !bad->named) {  // unnamed crossings: the world refuses the ring, naming it
      if (signed_area(r) != 0) out.push_back(std::move(r));
      continue;
    }
    const std::size_t n = r.size(), i = bad->first, j = bad->second;
    if (j == (i + 1) % n || (i == 0 && j == n - 1)) {  // a spike: drop its tip
      r.erase(r.begin() + static_cast<std::ptrdiff_t>(j == (i + 1) % n ? j : 0));
      todo.push_back(std::move(r));
      continue;
    }
    const Vec2 a = r[i], b = r[i + 1], c = r[j], d = r[(j + 1) % n];
    const double den = cross(b.x - a.x, b.y - a.y, d.x - c.x, d.y - c.y);
    Vec2 x = c;  // where they meet
    if (den != 0) {
      const double t =
          std::clamp(cross(c.x - a.x, c.y - a.y, d.x - c.x, d.y - c.y) / den, 0.0, 1.0);
      x = {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
    } else if (dist2_to_segment(a, b, c.x, c.y) > 0) {  // overlapping on one line
      x = dist2_to_segment(a, b, d.x, d.y) == 0 ? d : dist2_to_segment(c, d, a.x, a.y) == 0 ? a : b;
    }
    std::vector<Vec2> one = {x}, two(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(i + 1));
    one.insert(one.end(), r.begin() + static_cast<std::ptrdiff_t>(i + 1),
               r.begin() + static_cast<std::ptrdiff_t>(j + 1));
    two.push_back(x);
    two.insert(two.end(), r.begin() + static_cast<std::ptrdiff_t>(j + 1), r.end());
    todo.push_back(std::move(one));
    todo.push_back(std::move(two));
  }
  return out;
}

std::string exact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

// A key equal for equal obstacles, whatever the starting vertex and orientation.
std::string obstacle_key(const VadereShape& s) {
  if (s.kind == VadereShape::Kind::circle)
    return "c " + exact(s.centre.x) + " " + exact(s.centre.y) + " " + exact(s.radius);
  std::vector<Vec2> v = s.points;
  if (signed_area(v) < 0) std::reverse(v.begin(), v.end());
  std::rotate(
      v.begin(),
      std::min_element(v.begin(), v.end(),
                       [](Vec2 a, Vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }),
      v.end());
  std::string k = "p";
  for (const Vec2& p : v) k += " " + exact(p.x) + " " + exact(p.y);
  return k;
}

json point_list(const std::vector<Vec2>& pts) {
  json a = json::array();
  for (const Vec2& p : pts) a.push_back({p.x, p.y});
  return a;
}

// -- Vadere's vocabulary ------------------------------------------------------------------------

// AttributesAgent (the defaults are Java's).
struct AgentAttrs {
  double radius = 0.2;
  double mean = 1.34, sd = 0.26, min = 0.5, max = 2.2;  // free-flow speed distribution [m/s]
  Val where;
};

struct Target {
  Val where;
  int64_t id = -1;
  VadereShape shape;
  bool absorbing = true;
  double deletion = kDeletionDistance;
  json wait;         // the goal's "wait" (null: none)
  std::string goal;  // the crowddb goal, made when an agent first heads for it
};

// A target list from some index on: the goals in order, up to the first absorbing target.
struct Route {
  std::vector<std::string> goals;
  bool absorbed = true;  // Vadere removes the agent at the last one
  json goal() const { return goals.size() == 1 ? json(goals[0]) : json(goals); }
};

// "org.vadere.simulator.models.osm.OptimalStepsModel" -> "OptimalStepsModel (OSM)".
std::string model_name(const std::string& fqcn) {
  static const std::map<std::string, std::string> kShort = {
      {"OptimalStepsModel", "OSM"},          {"CellularAutomaton", "CA"},
      {"GradientNavigationModel", "GNM"},    {"SocialForceModel", "SFM"},
      {"BehaviouralHeuristicsModel", "BHM"}, {"OptimalVelocityModel", "OVM"},
      {"ReynoldsSteeringModel", "RSM"}};
  const auto dot = fqcn.rfind('.');
  const std::string cls = dot == std::string::npos ? fqcn : fqcn.substr(dot + 1);
  const auto it = kShort.find(cls);
  return it == kShort.end() ? cls : cls + " (" + it->second + ")";
}

// Keys Vadere has written for each element in some release (0.1 to 2.4), space-separated.
constexpr std::string_view kRootKeys =
    "name description release commithash processWriters scenario vadere topographyhash "
    "attributeshash";
constexpr std::string_view kScenarioKeys =
    "mainModel attributesModel attributesSimulation attributesPsychology topography stimulusInfos "
    "eventInfos reactionProbabilities attributesPedestrian attributesCar";
constexpr std::string_view kSimulationKeys =
    "finishTime simTimeStepLength realTimeSimTimeRatio writeSimulationData visualizationEnabled "
    "printFPS digitsPerCoordinate useFixedSeed fixedSeed simulationSeed needsBoundary "
    "useRandomSeed randomSeed useSalientBehavior";
constexpr std::string_view kTopographyKeys =
    "attributes obstacles measurementAreas stairs targets targetChangers absorbingAreas "
    "aerosolClouds droplets sources dynamicElements attributesPedestrian teleporter attributesCar "
    "pedestrians";
constexpr std::string_view kTopoAttributesKeys =
    "bounds boundingBoxWidth bounded referenceCoordinateSystem finishTime";
constexpr std::string_view kObstacleKeys = "id shape visible";
constexpr std::string_view kTargetKeys =
    "id shape visible absorber waiter leavingSpeed parallelEvents absorbing deletionDistance "
    "waitingTime waitingTimeYellowPhase parallelWaiters individualWaiting startingWithRedLight "
    "nextSpeed waitingTimeDistribution distributionParameters waitingBehaviour";
constexpr std::string_view kSourceKeys =
    "id shape visible targetIds spawner groupSizeDistribution interSpawnTimeDistribution "
    "distributionParameters spawnNumber maxSpawnNumberTotal startTime endTime "
    "spawnAtRandomPositions spawnAtGridPositionsCA useFreeSpaceOnly dynamicElementType "
    "attributesPedestrian spawnDelay";
constexpr std::string_view kSpawnerKeys =
    "type constraintsElementsMax constraintsTimeStart constraintsTimeEnd eventPositionRandom "
    "eventPositionGridCA eventPositionFreeSpace eventElementCount eventElement distribution";
constexpr std::string_view kPedestrianKeys =
    "attributes source targetIds nextTargetListIndex nextTargetListPosition isCurrentTargetAnAgent "
    "position velocity freeFlowSpeed followers idAsTarget isChild isLikelyInjured psychologyStatus "
    "healthStatus infectionStatus groupIds groupSizes agentsInGroup trajectory modelPedestrianMap "
    "type mostImportantEvent salientBehavior psychology";
constexpr std::string_view kAgentKeys =
    "id shape visible radius densityDependentSpeed speedDistributionMean "
    "speedDistributionStandardDeviation minimumSpeed maximumSpeed acceleration footstepHistorySize "
    "footStepsToStore searchRadius walkingDirectionSameIfAngleLessOrEqual "
    "targetOrientationAngleThreshold walkingDirectionCalculation angleCalculationType length width "
    "direction";

// -- the reader ---------------------------------------------------------------------------------

class VadereReader {
 public:
  VadereReader(const std::filesystem::path& path, std::string_view text)
      : file_(path.string()), text_(text) {}

  Imported run() {
    parse();
    const Val root{&doc_, "", kFnvBasis, 1};
    if (!doc_.is_object()) fail(root, "expected an object (a Vadere scenario)");
    known(root, kRootKeys);
    name_ = string(root, "name", std::nullopt);
    description_ = string(root, "description", std::string());
    read_release(root);

    const auto scenario = object(root, "scenario"), vadere = object(root, "vadere");
    if (scenario && vadere) fail(root, "both \"scenario\" and \"vadere\" (the name before 0.2)");
    if (!scenario && !vadere) fail(root, "missing \"scenario\" (or \"vadere\" before release 0.2)");
    const Val sc = scenario ? *scenario : *vadere;
    known(sc, kScenarioKeys);
    const auto topo = object(sc, "topography");
    if (!topo) fail(sc, "missing \"topography\"");
    known(*topo, kTopographyKeys);

    read_simulation(sc, *topo);
    read_model(sc);
    read_psychology(sc);
    read_world(*topo);
    read_obstacles(*topo);
    read_targets(*topo);
    // Spawned agents take topography.attributesPedestrian (before 0.1: scenario's).
    AgentAttrs defaults;
    if (const auto a = object(*topo, "attributesPedestrian")) {
      defaults = agent_attrs(*a);
    } else if (const auto a0 = object(sc, "attributesPedestrian")) {
      defaults = agent_attrs(*a0);
    } else {
      defaults.where = *topo;
    }
    read_pedestrians(*topo);
    read_sources(*topo, defaults);
    read_others(*topo);
    finish();
    return b_.finish();
  }

 private:
  // -- values -----------------------------------------------------------------------------------

  void parse() {
    try {
      doc_ = json::parse(text_);
    } catch (const json::parse_error& e) {
      const std::size_t byte = e.byte ? e.byte - 1 : 0;
      std::size_t line = 1, col = 1;
      for (std::size_t k = 0; k < byte && k < text_.size(); ++k) {
        if (text_[k] == '\n') {
          ++line;
          col = 1;
        } else {
          ++col;
        }
      }
      std::string what = e.what();
      const auto colon = what.rfind(": ");
      throw Error(
          Error::Kind::input,
          file_ + ":" + std::to_string(line) + ":" + std::to_string(col) +
              ": malformed JSON: " + (colon == std::string::npos ? what : what.substr(colon + 2)));
    } catch (const json::exception& e) {
      throw Error(Error::Kind::input, file_ + ": malformed JSON: " + e.what());
    }
    lines_.emplace(text_, file_);
  }

  Val make(const Val& parent, const std::string& token, const json& j) const {
    const std::string esc = escape_token(token);
    Val v{&j, parent.ptr + "/" + esc, child_hash(parent.h, esc), 0};
    v.line = lines_->line(v.h);
    if (v.line == 0) v.line = parent.line;
    return v;
  }

  std::string where(const Val& v) const {
    return file_ + ":" + std::to_string(v.line) + ": " + (v.ptr.empty() ? "/" : v.ptr);
  }
  [[noreturn]] void fail(const Val& v, const std::string& what) const {
    throw Error(Error::Kind::input, where(v) + ": " + what);
  }
  void warn(const std::string& kind, const Val& v, const std::string& what) {
    b_.warn(kind, where(v) + ": " + what);
  }

  // A member; absent when missing or null (Vadere writes null for unset objects).
  std::optional<Val> get(const Val& obj, const std::string& key) const {
    const auto it = obj.j->find(key);
    if (it == obj.j->end() || it->is_null()) return std::nullopt;
    return make(obj, key, *it);
  }
  Val item(const Val& arr, std::size_t i) const {
    return make(arr, std::to_string(i), (*arr.j)[i]);
  }

  std::optional<Val> object(const Val& obj, const std::string& key) const {
    auto v = get(obj, key);
    if (v && !v->j->is_object())
      fail(*v, std::string("expected an object, got ") + v->j->type_name());
    return v;
  }
  Val required_object(const Val& obj, const std::string& key) const {
    const auto v = object(obj, key);
    if (!v) fail(obj, "missing \"" + key + "\"");
    return *v;
  }
  std::optional<Val> array(const Val& obj, const std::string& key) const {
    auto v = get(obj, key);
    if (v && !v->j->is_array())
      fail(*v, std::string("expected an array, got ") + v->j->type_name());
    return v;
  }

  // A number; Jackson also writes and reads "NaN", "Infinity" and "-Infinity" as strings.
  double any_number(const Val& v) const {
    if (v.j->is_string()) {
      const std::string& s = v.j->get_ref<const std::string&>();
      if (s == "NaN") return std::numeric_limits<double>::quiet_NaN();
      if (s == "Infinity") return std::numeric_limits<double>::infinity();
      if (s == "-Infinity") return -std::numeric_limits<double>::infinity();
    }
    if (!v.j->is_number()) fail(v, std::string("expected a number, got ") + v.j->type_name());
    return v.j->get<double>();
  }
  double num(const Val& v) const {
    const double d = any_number(v);
    if (!std::isfinite(d)) fail(v, "must be finite");
    return d;
  }
  double number(const Val& obj, const std::string& key, double fallback) const {
    const auto v = get(obj, key);
    return v ? num(*v) : fallback;
  }
  double required_number(const Val& obj, const std::string& key) const {
    const auto v = get(obj, key);
    if (!v) fail(obj, "missing \"" + key + "\" (a number)");
    return num(*v);
  }
  // A whole number (Vadere's int and long fields).
  int64_t whole(const Val& v) const {
    const double d = num(v);
    if (d != std::floor(d) || std::abs(d) > 9007199254740992.0)
      fail(v, "expected a whole number, got " + fmt(d));
    return static_cast<int64_t>(d);
  }
  bool boolean(const Val& obj, const std::string& key, bool fallback) const {
    const auto v = get(obj, key);
    if (!v) return fallback;
    if (!v->j->is_boolean()) fail(*v, "expected true or false (Vadere does not read 0 and 1)");
    return v->j->get<bool>();
  }
  std::string string(const Val& obj, const std::string& key,
                     const std::optional<std::string>& fallback) const {
    const auto v = get(obj, key);
    if (!v) {
      if (!fallback) fail(obj, "missing \"" + key + "\" (a string)");
      return *fallback;
    }
    if (!v->j->is_string()) fail(*v, std::string("expected a string, got ") + v->j->type_name());
    return v->j->get<std::string>();
  }

  // Keys no release of Vadere writes: ignored with a warning (Vadere itself rejects them).
  void known(const Val& obj, std::string_view keys) {
    for (auto it = obj.j->begin(); it != obj.j->end(); ++it) {
      const std::string& key = it.key();
      bool found = false;
      for (std::size_t at = keys.find(key); at != std::string_view::npos && !found;
           at = keys.find(key, at + 1))
        found = (at == 0 || keys[at - 1] == ' ') &&
                (at + key.size() == keys.size() || keys[at + key.size()] == ' ');
      if (found) continue;
      warn("unknown-key", make(obj, it.key(), it.value()),
           "unknown key ignored (no release of Vadere writes it; Vadere itself rejects it)");
    }
  }

  // -- header -----------------------------------------------------------------------------------

  void read_release(const Val& root) {
    const auto rv = get(root, "release");
    if (!rv) return;  // before 0.1: read by its keys like every other file
    release_ = string(root, "release", std::string());
    if (release_ == "not a release") return;
    int major = 0, minor = 0;
    if (std::sscanf(release_.c_str(), "%d.%d", &major, &minor) == 2 &&
        (major > 2 || (major == 2 && minor > 4)))
      warn("release", *rv,
           "release " + release_ +
               " is newer than 2.4, the newest this importer knows: read by "
               "its keys as 2.4");
  }

  void read_simulation(const Val& sc, const Val& topo) {
    const auto sim = object(sc, "attributesSimulation");
    std::optional<Val> finish_at;
    if (sim) {
      known(*sim, kSimulationKeys);
      finish_at = get(*sim, "finishTime");
    }
    if (!finish_at) {  // before 0.1 it sat in topography.attributes
      if (const auto ta = object(topo, "attributes")) finish_at = get(*ta, "finishTime");
    }
    finish_time_ = finish_at ? num(*finish_at) : kFinishTime;
    if (finish_at && finish_time_ < 0) fail(*finish_at, "must be >= 0 s");
    const double step = sim ? number(*sim, "simTimeStepLength", kStepLength) : kStepLength;
    if (!(step > 0)) fail(*get(*sim, "simTimeStepLength"), "must be > 0 s");
    dt_ = std::min(step, kMaxDt);
    if (finish_time_ / dt_ > 1e9)
      fail(finish_at ? *finish_at : sc,
           "finishTime " + fmt(finish_time_) + " s is over 10^9 ticks of " + fmt(dt_) + " s");
    seed_ = 1;
    if (sim) {
      const bool fixed = get(*sim, "useFixedSeed") ? boolean(*sim, "useFixedSeed", true)
                                                   : boolean(*sim, "useRandomSeed", true);
      auto sv = get(*sim, "fixedSeed");
      if (!sv) sv = get(*sim, "randomSeed");
      if (fixed && sv) {
        seed_ = clamp_seed(*sv);
      } else if (!fixed) {
        warn("seed", *sim,
             "useFixedSeed is false (Vadere draws a new seed each run): crowddb uses seed 1");
      }
    }
  }

  // fixedSeed is a Java long: clamped to 0 .. 2^63 - 1.
  uint64_t clamp_seed(const Val& v) const {
    const json& j = *v.j;
    if (j.is_number_unsigned()) return std::min<uint64_t>(j.get<uint64_t>(), INT64_MAX);
    if (j.is_number_integer()) return static_cast<uint64_t>(std::max<int64_t>(j.get<int64_t>(), 0));
    if (j.is_string() && !std::isnan(any_number(v)))  // "Infinity"
      return any_number(v) > 0 ? static_cast<uint64_t>(INT64_MAX) : 0;
    const double d = num(v);
    if (d <= 0) return 0;
    if (d >= 9.2e18) return static_cast<uint64_t>(INT64_MAX);
    return static_cast<uint64_t>(d);
  }

  void read_model(const Val& sc) {
    // Submodels of the main model (AttributesOSM.submodels): the group model changes what a
    // source's count means.
    std::string submodels;
    if (const auto am = object(sc, "attributesModel")) {
      for (auto it = am->j->begin(); it != am->j->end(); ++it) {
        if (!it.value().is_object() || !it.value().contains("submodels")) continue;
        const json& subs = it.value()["submodels"];
        if (!subs.is_array()) continue;
        for (const json& s : subs) {
          if (!s.is_string()) continue;
          const std::string name = s.get<std::string>();
          if (name.ends_with("CentroidGroupModel")) group_model_ = true;
          submodels += (submodels.empty() ? "" : ", ") + model_name(name);
        }
      }
    }
    const std::string with = submodels.empty() ? "" : " with submodels " + submodels;
    const auto mm = get(sc, "mainModel");
    if (!mm) {
      warn("model", sc, "no mainModel" + with + ": agents steer with crowddb's orca");
      return;
    }
    const std::string main = string(sc, "mainModel", std::string());
    warn("model", *mm,
         "Vadere's " + model_name(main) + with +
             " is not available in crowddb: agents steer with orca (docs/steering.md), around "
             "obstacles with the path service");
  }

  void read_psychology(const Val& sc) {
    const auto ap = object(sc, "attributesPsychology");
    if (ap && boolean(*ap, "usePsychologyLayer", false))
      warn("psychology", *ap,
           "the psychology layer (perception, cognition, stimuli) is not supported: agents walk "
           "their target lists unperturbed");
  }

  // -- the world ----------------------------------------------------------------------------------

  void read_world(const Val& topo) {
    Val attrs = topo;
    double x = 0, y = 0, w = 10, h = 10, bw = kBoundingBoxWidth;  // AttributesTopography
    bool bounded = true;
    if (const auto a = object(topo, "attributes")) {
      attrs = *a;
      known(attrs, kTopoAttributesKeys);
      if (const auto b = object(attrs, "bounds")) {
        known(*b, "x y width height type");
        x = required_number(*b, "x");
        y = required_number(*b, "y");
        w = required_number(*b, "width");
        h = required_number(*b, "height");
        if (!(w > 0 && h > 0))
          fail(*b,
               "the bounds need width > 0 and height > 0 (got " + fmt(w) + " x " + fmt(h) + ")");
        if (!std::isfinite(x + w) || !std::isfinite(y + h)) fail(*b, "must be finite");
      }
      bw = number(attrs, "boundingBoxWidth", kBoundingBoxWidth);
      if (bw < 0) fail(*get(attrs, "boundingBoxWidth"), "must be >= 0");
      bounded = boolean(attrs, "bounded", true);
    }
    world_ = {x, y, x + w, y + h};
    if (!bounded || bw == 0) return;
    // Topography.createObstacleBoundary: VPolygon.borderAsShapes(bw, bw / 2, 0.0001) over the
    // bounds' edges (counter-clockwise): each strip reaches bw inside, 0.0001 outside and past
    // both corners.
    const Vec2 corners[4] = {{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}};
    const double g = kBorderGrow;
    for (int e = 0; e < 4; ++e) {
      const Vec2 a = corners[e], c = corners[(e + 1) % 4];
      const double len = std::hypot(c.x - a.x, c.y - a.y);
      const Vec2 d{(c.x - a.x) / len, (c.y - a.y) / len}, n{-d.y, d.x};  // n points inside
      const std::vector<Vec2> strip = {
          {a.x - d.x * g + n.x * (bw + g), a.y - d.y * g + n.y * (bw + g)},
          {a.x - d.x * g - n.x * g, a.y - d.y * g - n.y * g},
          {c.x + d.x * g - n.x * g, c.y + d.y * g - n.y * g},
          {c.x + d.x * g + n.x * (bw + g), c.y + d.y * g + n.y * (bw + g)}};
      Box box;
      for (const Vec2& p : strip) box.add(p.x, p.y);
      strips_.push_back({box.x0, box.y0, box.x1, box.y1});
      b_.polygon(strip, where(attrs) + " (bounded: the border wall Vadere adds)");
    }
  }

  VadereShape shape(const Val& owner) {
    const auto sv = object(owner, "shape");
    if (!sv) fail(owner, "missing \"shape\"");
    const std::string type = string(*sv, "type", std::nullopt);
    const Val tv = *get(*sv, "type");
    VadereShape s;
    if (type == "RECTANGLE") {
      known(*sv, "type x y width height");
      const double x = required_number(*sv, "x"), y = required_number(*sv, "y");
      const double w = required_number(*sv, "width"), h = required_number(*sv, "height");
      if (!(w > 0 && h > 0))
        fail(*sv,
             "a rectangle needs width > 0 and height > 0 (got " + fmt(w) + " x " + fmt(h) + ")");
      s.kind = VadereShape::Kind::rectangle;
      s.points = {{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}};
    } else if (type == "POLYGON") {
      known(*sv, "type points");
      const auto pts = array(*sv, "points");
      if (!pts) fail(*sv, "missing \"points\"");
      for (std::size_t k = 0; k < pts->j->size(); ++k) {
        const Val p = item(*pts, k);
        if (!p.j->is_object()) fail(p, "expected a point {\"x\": .., \"y\": ..}");
        const Vec2 q{required_number(p, "x"), required_number(p, "y")};
        if (s.points.empty() || s.points.back().x != q.x || s.points.back().y != q.y)
          s.points.push_back(q);
      }
      while (s.points.size() > 1 && s.points.front().x == s.points.back().x &&
             s.points.front().y == s.points.back().y)
        s.points.pop_back();
      if (s.points.size() < 3)
        fail(*pts, "a polygon needs at least 3 distinct points (got " +
                       std::to_string(s.points.size()) + ")");
      s.kind = VadereShape::Kind::polygon;
    } else if (type == "CIRCLE") {
      known(*sv, "type center radius");
      const Val c = required_object(*sv, "center");
      s.kind = VadereShape::Kind::circle;
      s.centre = {required_number(c, "x"), required_number(c, "y")};
      s.radius = required_number(*sv, "radius");
      if (!(s.radius > 0)) fail(*get(*sv, "radius"), "must be > 0 (got " + fmt(s.radius) + ")");
      s.box.add(s.centre.x - s.radius, s.centre.y - s.radius);
      s.box.add(s.centre.x + s.radius, s.centre.y + s.radius);
    } else if (type == "RING") {
      fail(tv, "RING shapes are not usable in files (Vadere neither writes nor reads them)");
    } else {
      fail(tv, "unknown shape type '" + type + "' (Vadere's are RECTANGLE, POLYGON and CIRCLE)");
    }
    for (const Vec2& p : s.points) s.box.add(p.x, p.y);
    if (!std::isfinite(s.box.x0) || !std::isfinite(s.box.x1) || !std::isfinite(s.box.y0) ||
        !std::isfinite(s.box.y1))
      fail(*sv, "must be finite");
    return s;
  }

  // Explicit obstacles. Files often repeat Vadere's border walls (sometimes twice): an obstacle
  // inside one of them, or equal to an earlier one, changes nothing and is dropped.
  void read_obstacles(const Val& topo) {
    const auto obs = array(topo, "obstacles");
    if (!obs) return;
    std::set<std::string> seen;
    for (std::size_t k = 0; k < obs->j->size(); ++k) {
      const Val o = item(*obs, k);
      if (!o.j->is_object()) fail(o, "expected an object");
      known(o, kObstacleKeys);
      const VadereShape s = shape(o);
      bool in_border = false;
      for (const Rect& r : strips_) in_border |= r.contains(s.box, 1e-9);
      if (in_border) {
        warn("border-copy", o,
             "lies within the border walls Vadere adds for 'bounded' (files often repeat them): "
             "dropped");
        continue;
      }
      if (!seen.insert(obstacle_key(s)).second) {
        warn("duplicate-obstacle", o, "repeats an earlier obstacle: dropped");
        continue;
      }
      ++explicit_obstacles_;
      if (s.kind == VadereShape::Kind::circle) {
        b_.circle(s.centre, s.radius, where(o));
        continue;
      }
      if (s.points.size() <= kMaxSplit && first_self_intersection(s.points)) {
        const auto pieces = simple_pieces(s.points);
        if (holes(pieces))
          fail(o,
               "a polygon whose edges cross and enclose a hole (Vadere's non-zero winding "
               "rule leaves it open; crowddb's obstacles are simple polygons): draw it as "
               "simple polygons");
        warn("not-simple", o,
             "a polygon whose edges cross (Vadere fills it by the non-zero winding rule): "
             "imported as " +
                 std::to_string(pieces.size()) + " simple pieces");
        for (const auto& piece : pieces) b_.polygon(piece, where(o));
        continue;
      }
      b_.polygon(s.points, where(o));
    }
  }

  // -- targets ----------------------------------------------------------------------------------

  void read_targets(const Val& topo) {
    const auto arr = array(topo, "targets");
    if (!arr) return;
    for (std::size_t k = 0; k < arr->j->size(); ++k) {
      const Val t = item(*arr, k);
      if (!t.j->is_object()) fail(t, "expected an object");
      known(t, kTargetKeys);
      Target tg;
      tg.where = t;
      tg.shape = shape(t);
      if (const auto idv = get(t, "id")) tg.id = whole(*idv);
      std::optional<Val> dd;
      if (const auto ab = object(t, "absorber")) {  // 2.4
        known(*ab, "enabled deletionDistance");
        tg.absorbing = boolean(*ab, "enabled", true);
        dd = get(*ab, "deletionDistance");
      } else {
        tg.absorbing = boolean(t, "absorbing", true);
        dd = get(t, "deletionDistance");
      }
      if (dd) {
        tg.deletion = num(*dd);
        if (tg.deletion < 0) fail(*dd, "must be >= 0");
      }
      const Waiting wait = waiting(t);
      if (!wait.unsupported.empty())
        warn("waiting", t,
             "this kind of waiting at targets is not supported (" + wait.unsupported +
                 "): agents pass without waiting");
      tg.wait = wait.wait;
      std::optional<Val> lv = get(t, "leavingSpeed");
      if (!lv) lv = get(t, "nextSpeed");
      if (lv && num(*lv) >= 0 && !tg.absorbing)
        warn("leaving-speed", *lv,
             "leavingSpeed " + fmt(num(*lv)) +
                 " m/s (the speed after this target) is not supported: agents keep their speed");
      std::optional<Val> pv = get(t, "parallelEvents");
      if (!pv) pv = get(t, "parallelWaiters");
      if (pv && num(*pv) > 0)
        warn("parallel-events", *pv,
             "parallelEvents " + fmt(num(*pv)) +
                 " (how many agents a target serves at once) is not supported: it serves all");
      target_ids_[tg.id].push_back(targets_.size());
      targets_.push_back(std::move(tg));
    }
  }

  // How a target makes agents wait: a goal's "wait" (a fixed time, or an exponential
  // distribution's mean), or a kind crowddb does not model (a description for the warning), or
  // neither.
  struct Waiting {
    json wait;
    std::string unsupported;
  };
  Waiting waiting(const Val& t) {
    if (const auto w = object(t, "waiter")) {  // 2.4
      known(*w, "enabled distribution");
      if (!boolean(*w, "enabled", false)) return {};
      const auto d = object(*w, "distribution");
      std::string type = d ? string(*d, "type", std::string("?")) : std::string("none");
      const auto dot = type.rfind('.');
      if (dot != std::string::npos) type = type.substr(dot + 1);
      // A constant distribution's one parameter is its value, whatever it is used for.
      if (type == "AttributesConstantDistribution")
        if (const auto v = get(*d, "updateFrequency")) return fixed_wait(*v);
      if (type == "AttributesNegativeExponentialDistribution")
        if (const auto v = get(*d, "mean")) {
          const double mean = num(*v);
          if (!(mean > 0 && mean <= Goal::kMaxWait))
            fail(*v, "a mean waiting time must be in (0, " + fmt(Goal::kMaxWait) + "] s");
          return {json{{"exponential", mean}}, ""};
        }
      return {nullptr, "waiter " + type};
    }
    if (t.j->contains("waitingTimeDistribution")) {  // 2.3
      const std::string behaviour = string(t, "waitingBehaviour", std::string("INDIVIDUAL"));
      if (behaviour == "NO_WAITING" || !get(t, "waitingTimeDistribution")) return {};
      return {nullptr, "waitingTimeDistribution " +
                           string(t, "waitingTimeDistribution", std::string()) +
                           (behaviour == "TRAFFIC_LIGHT" ? " as a traffic light" : "")};
    }
    const auto wv = get(t, "waitingTime");  // <= 2.2
    if (!wv || !(num(*wv) > 0)) return {};
    if (boolean(t, "individualWaiting", true)) return fixed_wait(*wv);
    return {nullptr, "a traffic light, green and red " + fmt(num(*wv)) + " s each"};
  }
  Waiting fixed_wait(const Val& v) {
    const double s = num(v);
    if (!(s >= 0 && s <= Goal::kMaxWait))
      fail(v, "a waiting time must be in [0, " + fmt(Goal::kMaxWait) + "] s");
    if (s == 0) return {};
    return {s, ""};
  }

  // The crowddb goal of a target, made on first use. Vadere reaches a target when the agent's
  // centre is inside it or within deletionDistance: a circle's disc grows by that distance; a
  // polygon's area is used as it is (docs/importers/vadere.md says why).
  const std::string& goal_of(Target& t) {
    if (!t.goal.empty()) return t.goal;
    make_goal(t);
    return t.goal;
  }
  void make_goal(Target& t) {
    const VadereShape& s = t.shape;
    const std::string origin = where(t.where);
    const std::string world = "[" + fmt(world_.x0) + ", " + fmt(world_.y0) + ", " + fmt(world_.x1) +
                              ", " + fmt(world_.y1) + "]";
    if (world_.misses(s.box))
      fail(t.where, "a target outside the world: target " + std::to_string(t.id) +
                        " lies outside the bounds " + world);
    if (s.kind == VadereShape::Kind::circle) {
      if (!world_.contains(s.centre))
        fail(t.where, "a target outside the world: the centre of target " + std::to_string(t.id) +
                          " lies outside the bounds " + world);
      t.goal = b_.disc_goal(s.centre, s.radius + t.deletion, origin, t.wait);
      return;
    }
    std::vector<Vec2> area = s.points;
    if (!world_.contains(s.box)) {
      area = clip(area, world_);
      if (area.empty())
        fail(t.where, "a target outside the world: target " + std::to_string(t.id) +
                          " lies outside the bounds " + world);
      warn("target-clipped", t.where,
           "target " + std::to_string(t.id) + " reaches beyond the bounds " + world +
               ": the part outside is dropped");
    }
    t.goal = b_.area_goal(area, origin, t.wait);
    if (pointed_.insert(t.goal).second)
      if (const auto p = area_point(area))
        for (json& g : b_.doc()["goals"])
          if (g["name"] == t.goal) {
            g["x"] = p->x;
            g["y"] = p->y;
          }
  }

  // The point of a goal area that navigation aims at (the reader's "x", "y"): its centroid when
  // that is inside the area and walkable, else the walkable point of a 16 x 16 grid over it
  // nearest to the centroid; none when the whole area is blocked (the reader then says so).
  // Computed around the first vertex, so that UTM-sized coordinates keep their precision.
  std::optional<Vec2> area_point(const std::vector<Vec2>& area) const {
    const Vec2 o = area[0];
    double a = 0, cx = 0, cy = 0;
    for (std::size_t i = 0, n = area.size(); i < n; ++i) {
      const Vec2 p{area[i].x - o.x, area[i].y - o.y};
      const Vec2 q{area[(i + 1) % n].x - o.x, area[(i + 1) % n].y - o.y};
      const double c = p.x * q.y - q.x * p.y;
      a += c;
      cx += (p.x + q.x) * c;
      cy += (p.y + q.y) * c;
    }
    if (a == 0) return std::nullopt;
    const Vec2 centroid{o.x + cx / (3 * a), o.y + cy / (3 * a)};
    const auto usable = [&](Vec2 p) {
      return point_in_polygon(area, p.x, p.y) && world_.contains(p) &&
             b_.free(p.x, p.y, 1e-9, /*agents=*/false);
    };
    if (usable(centroid)) return centroid;
    Box box;
    for (const Vec2& p : area) box.add(p.x, p.y);
    std::optional<Vec2> best;
    double best_d = INFINITY;
    constexpr int kGrid = 16;
    for (int i = 0; i < kGrid; ++i)
      for (int k = 0; k < kGrid; ++k) {
        const Vec2 p{box.x0 + (box.x1 - box.x0) * (i + 0.5) / kGrid,
                     box.y0 + (box.y1 - box.y0) * (k + 0.5) / kGrid};
        const double d = std::hypot(p.x - centroid.x, p.y - centroid.y);
        if (d < best_d && usable(p)) {
          best = p;
          best_d = d;
        }
      }
    return best;
  }

  static double distance(const VadereShape& s, Vec2 p) {
    if (s.kind == VadereShape::Kind::circle)
      return std::max(0.0, std::hypot(p.x - s.centre.x, p.y - s.centre.y) - s.radius);
    return point_in_polygon(s.points, p.x, p.y) ? 0
                                                : std::sqrt(dist2_to_boundary(s.points, p.x, p.y));
  }

  // The goals of a target list from index `from` on, for an agent starting at `at`; a missing id
  // is an error at its entry. Of several targets sharing an id, the nearest to where the agent
  // comes from.
  Route route(const std::optional<Val>& ids, std::size_t from, Vec2 at) {
    Route r;
    if (!ids) return r;
    const std::size_t n = ids->j->size();
    for (std::size_t k = 0; k < n; ++k) {
      const Val iv = item(*ids, k);
      const int64_t id = whole(iv);
      if (!target_ids_.count(id))
        fail(iv, "target " + std::to_string(id) + " does not exist (no target has this id)");
    }
    for (std::size_t k = from; k < n; ++k) {
      const Val iv = item(*ids, k);
      const auto it = target_ids_.find(whole(iv));
      const int64_t id = it->first;
      std::size_t best = it->second.front();
      for (std::size_t c : it->second)
        if (distance(targets_[c].shape, at) < distance(targets_[best].shape, at)) best = c;
      if (it->second.size() > 1)
        warn("shared-target-id", iv,
             std::to_string(it->second.size()) + " targets have id " + std::to_string(id) +
                 ": the agent heads for the one nearest to it in a straight line (Vadere's "
                 "floor field leads to the nearest by walking distance)");
      Target& t = targets_[best];
      at = {(t.shape.box.x0 + t.shape.box.x1) / 2, (t.shape.box.y0 + t.shape.box.y1) / 2};
      r.goals.push_back(goal_of(t));
      r.absorbed = t.absorbing;
      if (t.absorbing && k + 1 < n) {
        warn("after-absorbing", iv,
             "target " + std::to_string(id) +
                 " is absorbing (Vadere removes the agent there): the targets after it are "
                 "never visited and are dropped");
        break;
      }
    }
    return r;
  }

  void count_arrival(const Route& r, double agents, const Val& at) {
    if (r.absorbed) {
      removed_ += agents;
      if (!removed_at_) removed_at_ = at;
    } else {
      idle_ += agents;
      if (!idle_at_) idle_at_ = at;
    }
  }

  // -- agents -------------------------------------------------------------------------------------

  AgentAttrs agent_attrs(const Val& a) {
    known(a, kAgentKeys);
    AgentAttrs out;
    out.where = a;
    out.radius = number(a, "radius", out.radius);
    if (!(out.radius > 0)) fail(*get(a, "radius"), "must be > 0 (got " + fmt(out.radius) + ")");
    out.mean = number(a, "speedDistributionMean", out.mean);
    out.sd = number(a, "speedDistributionStandardDeviation", out.sd);
    out.min = number(a, "minimumSpeed", out.min);
    out.max = number(a, "maximumSpeed", out.max);
    if (out.sd < 0) fail(*get(a, "speedDistributionStandardDeviation"), "must be >= 0");
    return out;
  }

  // A spawned agent's preferred speed: Vadere draws it from N(mean, sd) truncated to
  // [minimumSpeed, maximumSpeed]; crowddb's sources draw uniformly from a range.
  json speed_of(const AgentAttrs& a) {
    if (a.sd == 0) {
      if (!(a.mean > 0))
        fail(a.where, "speedDistributionMean must be > 0 m/s (got " + fmt(a.mean) + ")");
      return a.mean;
    }
    double lo = std::max(a.min, a.mean - a.sd), hi = std::min(a.max, a.mean + a.sd);
    if (!(lo <= hi)) lo = hi = std::clamp(a.mean, std::min(a.min, a.max), std::max(a.min, a.max));
    if (!(hi > 0))
      fail(a.where, "the free-flow speeds (speedDistributionMean " + fmt(a.mean) +
                        ", minimumSpeed .. maximumSpeed " + fmt(a.min) + " .. " + fmt(a.max) +
                        ") are not > 0 m/s");
    lo = std::min(std::max(lo, kMinSpeed), hi);
    if (speed_warned_.insert(a.where.ptr).second)
      warn("speed-range", a.where,
           "Vadere draws free-flow speeds from a normal distribution (mean " + fmt(a.mean) +
               ", sd " + fmt(a.sd) + " m/s, truncated to [" + fmt(a.min) + ", " + fmt(a.max) +
               "]): imported as uniform in [" + fmt(lo) + ", " + fmt(hi) + "] m/s");
    if (lo == hi) return lo;
    return json::array({lo, hi});
  }

  void read_pedestrians(const Val& topo) {
    if (const auto old = array(topo, "pedestrians"); old && !old->j->empty())
      warn("pedestrians", *old,
           "the pre-0.1 \"pedestrians\" list is dropped (Vadere's migration drops it too)");
    const auto arr = array(topo, "dynamicElements");
    if (!arr) return;
    for (std::size_t k = 0; k < arr->j->size(); ++k) {
      const Val p = item(*arr, k);
      if (!p.j->is_object()) fail(p, "expected an object");
      known(p, kPedestrianKeys);
      const std::string type = string(p, "type", std::string("PEDESTRIAN"));
      if (type != "PEDESTRIAN") {
        warn("cars", p, "a dynamic element of type " + type + " is dropped (only pedestrians are)");
        continue;
      }
      // Each pedestrian has its own attributes (not topography's), and its own free-flow speed.
      AgentAttrs a;
      a.where = p;
      if (const auto at = object(p, "attributes")) a = agent_attrs(*at);
      const Val pos = required_object(p, "position");
      const double x = required_number(pos, "x"), y = required_number(pos, "y");
      std::optional<Val> iv = get(p, "nextTargetListIndex");
      if (!iv) iv = get(p, "nextTargetListPosition");  // before 0.1
      // -1 is Vadere's deprecated mode that pops the list's head: the same walk from the head.
      const int64_t from = iv ? std::max<int64_t>(whole(*iv), 0) : 0;
      const auto ids = array(p, "targetIds");
      const double speed = get(p, "freeFlowSpeed") ? number(p, "freeFlowSpeed", 0) : a.mean;
      const Route r = route(ids, static_cast<std::size_t>(from), {x, y});
      if (const auto g = array(p, "groupIds"); g && !g->j->empty() && group_model_)
        warn("groups", *g,
             "group membership (CentroidGroupModel) is not supported: members walk alone");
      if (r.goals.empty() || !(speed > 0)) {
        // Vadere's agents without a target (or speed) stand where they are for the whole run.
        warn("standing", p,
             std::string("a pedestrian with ") +
                 (r.goals.empty() ? "no target left" : "free-flow speed 0") +
                 " stands still in Vadere: imported as a circle obstacle of its radius");
        b_.circle({x, y}, a.radius, where(p));
        continue;
      }
      json row = {
          {"x", x}, {"y", y}, {"radius", a.radius}, {"pref_speed", speed}, {"goal", r.goal()}};
      if (const auto vel = object(p, "velocity")) {
        const auto vx = get(*vel, "x"), vy = get(*vel, "y");
        if (vx && vy) {
          const double dx = any_number(*vx), dy = any_number(*vy);
          if (std::isfinite(dx) && std::isfinite(dy) && (dx != 0 || dy != 0)) {
            row["vx"] = dx;
            row["vy"] = dy;
          }
        }
      }
      if (++explicit_ > kMaxScenarioAgents)
        fail(p, "more than " + std::to_string(kMaxScenarioAgents) +
                    " pedestrians placed at the start (crowddb's limit per scenario)");
      if (++agents_ > kMaxSourceAgents) fail(p, "more than 10^7 agents");
      b_.agent(std::move(row), where(p));
      b_.occupy(x, y, a.radius);
      count_arrival(r, 1, p);
    }
  }

  // -- sources ------------------------------------------------------------------------------------

  // The parameters of an inter-event distribution: named (2.0 on) or by position (<= 1.16).
  struct Params {
    Val where;
    bool positional = false;
  };

  double param(const Params& p, const char* name, std::size_t index, double fallback) const {
    if (!p.positional) return number(p.where, name, fallback);
    if (index >= p.where.j->size()) return fallback;
    return num(item(p.where, index));
  }

  // Mean time between spawn events [s] for a distribution of this kind ("constant",
  // "poisson", ...); warns when Vadere's events are not regular.
  double mean_interval(const std::string& kind, const Params& p, const Val& kind_at) {
    const auto positive = [&](double v, const char* what) {
      if (!(v > 0))
        fail(p.where, std::string(what) + " " + fmt(v) +
                          ": must be > 0 when constraintsTimeEnd != constraintsTimeStart (Vadere "
                          "would loop for ever)");
      return v;
    };
    const auto random = [&](const std::string& what) {
      warn("random-spawn", kind_at,
           what + ": imported at the mean rate with regular spacing, not at random times");
    };
    if (kind == "constant") return positive(param(p, "updateFrequency", 0, 0), "updateFrequency");
    if (kind == "linearInterpolation")  // Vadere ignores its x and y values too
      return positive(param(p, "spawnFrequency", 0, 0), "spawnFrequency");
    if (kind == "poisson") {
      const double rate = positive(param(p, "numberPedsPerSecond", 0, 0), "numberPedsPerSecond");
      random("Poisson spawn events (" + fmt(rate) + " per s)");
      return 1 / rate;
    }
    if (kind == "negativeExponential") {
      const double mean = positive(param(p, "mean", 0, 0), "mean");
      random("exponential times between spawn events (mean " + fmt(mean) + " s)");
      return mean;
    }
    if (kind == "normal") {
      const double mean = positive(param(p, "mean", 0, 0), "mean");
      random("normal times between spawn events (mean " + fmt(mean) + " s, sd " +
             fmt(param(p, "sd", 1, 0)) + " s)");
      return mean;
    }
    if (kind == "binomial") {
      const double mean = positive(param(p, "trials", 0, 0) * param(p, "p", 1, 0), "trials * p");
      random("binomial times between spawn events (mean " + fmt(mean) + " s)");
      return mean;
    }
    if (kind == "timeSeries") {
      const double len = positive(param(p, "intervalLength", 0, 0), "intervalLength");
      double events = 0;
      std::size_t intervals = 0;
      if (const auto s = array(p.where, "spawnsPerInterval")) {
        intervals = s->j->size();
        for (std::size_t k = 0; k < intervals; ++k) events += std::max(0.0, num(item(*s, k)));
      }
      warn("time-series", kind_at,
           "a time series of spawn counts is imported at its mean rate over all its intervals");
      if (!(events > 0)) return std::numeric_limits<double>::infinity();  // the first event only
      return len * static_cast<double>(intervals) / events;
    }
    if (kind == "mixed")
      fail(kind_at, "mixed distributions are not supported (no single mean time between events)");
    if (kind == "singleSpawn")
      fail(kind_at, "singleSpawn distributions are not supported (Vadere cannot read them either)");
    if (kind == "empirical")
      fail(kind_at, "empirical distributions are not supported (Vadere never loads their values)");
    fail(kind_at, "unknown distribution '" + kind + "'");
  }

  // The distribution's kind and parameters, in any release's form.
  double interval_of(const Val& s, const std::optional<Val>& spawner) {
    if (spawner) {  // 2.4: {"type": "...Attributes<Kind>Distribution", params ...}
      const auto d = object(*spawner, "distribution");
      if (!d) return 1;  // AttributesRegularSpawner's default: Constant, every 1 s
      std::string type = string(*d, "type", std::nullopt);
      const Val tv = *get(*d, "type");
      const std::string prefix = "org.vadere.state.attributes.distributions.Attributes";
      if (!type.starts_with(prefix) || !type.ends_with("Distribution") ||
          type.size() <= prefix.size() + 12)
        fail(tv, "unknown distribution type '" + type + "'");
      std::string kind = type.substr(prefix.size(), type.size() - prefix.size() - 12);
      kind[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(kind[0])));
      return mean_interval(kind, {*d, false}, tv);
    }
    // <= 2.3: a name and its parameters beside it.
    const auto nv = get(s, "interSpawnTimeDistribution");
    const std::string name =
        nv ? string(s, "interSpawnTimeDistribution", std::nullopt) : std::string("constant");
    const Val at = nv ? *nv : s;
    const auto pv = get(s, "distributionParameters");
    if (name.find('.') != std::string::npos) {  // <= 1.16: a class name, parameters by position
      static const std::map<std::string, std::string> kClasses = {
          {"org.vadere.state.scenario.ConstantDistribution", "constant"},
          {"org.vadere.state.scenario.NegativeExponentialDistribution", "negativeExponential"},
          {"org.vadere.state.scenario.PoissonDistribution", "poisson"}};
      const auto it = kClasses.find(name);
      if (it == kClasses.end())
        fail(at, "distribution class '" + name +
                     "' is not supported (Vadere's migration to 2.0 accepts only Constant, "
                     "NegativeExponential and Poisson)");
      // Before 0.2 a constant source's interval was "spawnDelay" (-1: unset).
      if (const auto sd = get(s, "spawnDelay"); sd && it->second == "constant" && num(*sd) != -1) {
        const json list = json::array({num(*sd)});
        const Val lv{&list, sd->ptr, sd->h, sd->line};
        return mean_interval("constant", {lv, true}, at);
      }
      if (!pv) {
        const json list = json::array({1.0});  // AttributesSource's default [1.0]
        return mean_interval(it->second, {Val{&list, s.ptr, s.h, s.line}, true}, at);
      }
      if (!pv->j->is_array()) fail(*pv, "expected a list of numbers (a class-name distribution)");
      return mean_interval(it->second, {*pv, true}, at);
    }
    if (!pv) {
      const json obj = {{"updateFrequency", 1.0}};  // AttributesSource's default
      return mean_interval(name, {Val{&obj, s.ptr, s.h, s.line}, false}, at);
    }
    if (!pv->j->is_object()) fail(*pv, "expected an object (parameters by name)");
    return mean_interval(name, {*pv, false}, at);
  }

  void read_sources(const Val& topo, const AgentAttrs& defaults) {
    const auto arr = array(topo, "sources");
    if (!arr) return;
    for (std::size_t k = 0; k < arr->j->size(); ++k) read_source(item(*arr, k), defaults);
  }

  void read_source(const Val& s, const AgentAttrs& defaults) {
    if (!s.j->is_object()) fail(s, "expected an object");
    known(s, kSourceKeys);
    const VadereShape sh = shape(s);
    const int64_t id = get(s, "id") ? whole(*get(s, "id")) : -1;
    // The schedule, in 2.4's names (older names in brackets).
    const auto spawner = object(s, "spawner");
    const Val sp = spawner ? *spawner : s;
    if (spawner) known(*spawner, kSpawnerKeys);
    const auto field = [&](const char* now, const char* old) {
      return spawner ? get(*spawner, now) : get(s, old);
    };
    const auto count_v = field("eventElementCount", "spawnNumber");
    const auto max_v = field("constraintsElementsMax", "maxSpawnNumberTotal");
    const auto start_v = field("constraintsTimeStart", "startTime");
    const auto end_v = field("constraintsTimeEnd", "endTime");
    const double n = count_v ? static_cast<double>(whole(*count_v)) : 1;
    const double max = max_v ? static_cast<double>(whole(*max_v)) : -1;
    const double start = start_v ? num(*start_v) : 0;
    const double end = end_v ? any_number(*end_v) : 0;  // "Infinity" is allowed
    if (std::isnan(end) || end == -std::numeric_limits<double>::infinity())
      fail(*end_v, "must be a number");
    if (n < 0) fail(*count_v, "must be >= 0");
    const bool random_pos = spawner ? boolean(sp, "eventPositionRandom", false)
                                    : boolean(s, "spawnAtRandomPositions", false);
    const bool grid_ca = spawner ? boolean(sp, "eventPositionGridCA", false)
                                 : boolean(s, "spawnAtGridPositionsCA", false);
    const bool free_space = spawner ? boolean(sp, "eventPositionFreeSpace", true)
                                    : boolean(s, "useFreeSpaceOnly", true);
    if (spawner) {
      const std::string type = string(sp, "type", std::string("AttributesRegularSpawner"));
      if (!type.ends_with("AttributesRegularSpawner"))
        warn("spawner-type", *get(sp, "type"),
             "spawner " + type.substr(type.rfind('.') + 1) +
                 " is read as a regular spawner: eventElementCount agents per event of its "
                 "distribution (Vadere 2.4's other spawners are hard-coded or unfinished)");
    } else if (string(s, "dynamicElementType", std::string("PEDESTRIAN")) != "PEDESTRIAN") {
      warn("cars", *get(s, "dynamicElementType"),
           "a source of cars is dropped (only pedestrians are)");
      return;
    }

    // Vadere's expected total (updates at t <= finishTime; events at start, start + interval, ...
    // while <= end; one event when start == end).
    double events = 0, interval = std::numeric_limits<double>::infinity();
    if (start == end) {
      events = start <= finish_time_ ? 1 : 0;
    } else if (start < end && start <= finish_time_) {
      interval = interval_of(s, spawner);
      const double span = std::min(end, finish_time_) - start;
      events = std::isinf(interval) ? 1 : std::floor(span / interval * (1 + 1e-12)) + 1;
    }
    // With the group model an event brings eventElementCount groups.
    double group = 1;
    if (const auto g = array(s, "groupSizeDistribution"); g && group_model_) {
      double mass = 0, size = 0;
      for (std::size_t k = 0; k < g->j->size(); ++k) {
        const double pk = num(item(*g, k));
        if (pk < 0) fail(item(*g, k), "must be >= 0");
        mass += pk;
        size += pk * static_cast<double>(k + 1);
      }
      if (mass > 0) group = size / mass;
      if (group > 1)
        warn("groups", *g,
             "groups of mean size " + fmt(group) +
                 " (CentroidGroupModel): each event's groups enter as single people who walk "
                 "alone");
    }
    double people = events * n * group;
    if (max >= 0) people = std::min(people, max);
    people = std::round(people);
    if (people > kMaxSourceAgents || agents_ + people > kMaxSourceAgents)
      fail(s, "would spawn " + fmt(people) + " agents, more than 10^7 in all");
    if (people < 1) {
      warn("no-spawn", s, "spawns nobody before finishTime " + fmt(finish_time_) + " s: dropped");
      return;
    }
    const Route r =
        route(array(s, "targetIds"), 0, {(sh.box.x0 + sh.box.x1) / 2, (sh.box.y0 + sh.box.y1) / 2});
    if (r.goals.empty())
      fail(s,
           "a source with no targets: its agents would stand where they appear in Vadere, but "
           "crowddb's agents need a goal");
    agents_ += people;

    if (!random_pos)
      warn("spawn-grid", sp,
           "agents enter at random free spots of the source, not on Vadere's grid of spots "
           "filled from the lower left");
    else if (grid_ca)
      warn("spawn-grid", sp,
           "agents enter at random free spots of the source, not on the cellular automaton's grid");
    if (!free_space)
      warn("spawn-overlap", sp,
           "Vadere may place agents overlapping others here (eventPositionFreeSpace false): "
           "crowddb's wait for a free spot");

    // Spawned agents: spawner.eventElement (<= 2.3: the source's attributesPedestrian), else
    // topography.attributesPedestrian.
    AgentAttrs a = defaults;
    if (const auto e = object(sp, spawner ? "eventElement" : "attributesPedestrian"))
      a = agent_attrs(*e);

    json src = {{"name", id >= 0 ? "source " + std::to_string(id) : "source " + s.ptr},
                {"count", static_cast<uint64_t>(people)},
                {"start", std::max(start, 0.0)},
                {"radius", a.radius},
                {"pref_speed", speed_of(a)},
                {"goal", r.goal()}};
    if (start < 0)
      warn("negative-start", *start_v,
           "a start before 0 s: its events are due from 0 s on (Vadere lets them all in at 0 s)");
    // One event (or one inside finishTime): every agent due at once; agents that do not fit
    // wait for a free spot, as Vadere's carry-over does. Otherwise agent k of n per event every
    // interval is due at start + k * interval / n.
    src["rate"] = events <= 1 ? kBurstRate : std::min(kBurstRate, n * group / interval);
    source_area(s, sh, src);
    b_.source(std::move(src), where(s));
    count_arrival(r, people, s);
  }

  void source_area(const Val& s, const VadereShape& sh, json& src) {
    std::vector<Vec2> area = sh.points;
    if (sh.kind == VadereShape::Kind::circle) {
      for (int k = 0; k < kCircleSides; ++k) {
        const double t = 2 * std::numbers::pi * k / kCircleSides;
        area.push_back(
            {sh.centre.x + sh.radius * std::cos(t), sh.centre.y + sh.radius * std::sin(t)});
      }
      warn("circle-source", s, "a circular source is imported as a 32-sided polygon inside it");
    }
    if (world_.misses(sh.box)) fail(s, "a source outside the world (outside the bounds)");
    if (!world_.contains(sh.box)) {
      area = clip(area, world_);
      if (area.empty()) fail(s, "a source outside the world (outside the bounds)");
      warn("source-clipped", s, "the part of the source outside the bounds is dropped");
    }
    if (sh.kind == VadereShape::Kind::rectangle) {
      Box b;
      for (const Vec2& p : area) b.add(p.x, p.y);
      src["area"] = {b.x0, b.y0, b.x1, b.y1};
    } else {
      src["polygon"] = point_list(area);
    }
  }

  // -- the rest -----------------------------------------------------------------------------------

  void read_others(const Val& topo) {
    const auto list = [&](const char* key, const char* kind, const std::string& what) {
      const auto v = array(topo, key);
      if (v && !v->j->empty()) warn(kind, *v, std::to_string(v->j->size()) + " " + what);
    };
    // measurementAreas only feed output processors: nothing to import.
    list("stairs", "stairs",
         "stairs: walkable like the floor; Vadere's shorter steps on stairs are not modelled");
    list("targetChangers", "target-changers",
         "target changers are not supported: agents keep their target lists");
    list("absorbingAreas", "absorbing-areas",
         "absorbing areas are not supported: agents crossing them are not removed");
    list("aerosolClouds", "infection", "aerosol clouds (infection model) are ignored");
    list("droplets", "infection", "droplets (infection model) are ignored");
    if (const auto tp = get(topo, "teleporter"))
      warn("teleporter", *tp, "the teleporter (a periodic boundary in x) is not supported");
  }

  void finish() {
    json& d = b_.doc();
    const std::string stem = std::filesystem::path(file_).stem().string();
    d["name"] = name_.empty() ? stem : name_;
    d["description"] = "Vadere scenario " + file_ +
                       (release_.empty() ? std::string() : " (release " + release_ + ")") +
                       (description_.empty() ? std::string() : ": " + description_);
    d["bounds"] = {world_.x0, world_.y0, world_.x1, world_.y1};
    d["dt"] = dt_;
    d["duration"] = finish_time_;
    d["seed"] = seed_;
    d["stop_when_all_arrived"] = false;  // Vadere runs to finishTime
    d["steering"] = {{"model", "orca"}};
    // Vadere's floor field leads around obstacles: the path service does that here.
    if (explicit_obstacles_ > 0) d["navigation"] = json::object();
    const bool idle = idle_ > removed_;
    d["arrival"] = idle ? "idle" : "remove";
    if (idle_ > 0 && removed_ > 0)
      warn("arrival", idle ? *removed_at_ : *idle_at_,
           fmt(removed_) + " agents end at an absorbing target (Vadere removes them) and " +
               fmt(idle_) +
               " at a non-absorbing one (Vadere lets them stand): crowddb has one "
               "arrival policy per world: '" +
               (idle ? "idle" : "remove") + "' for all");
  }

  std::string file_;
  std::string_view text_;
  json doc_;
  std::optional<LineIndex> lines_;
  DocBuilder b_;
  std::string name_, description_, release_;
  double finish_time_ = kFinishTime, dt_ = kMaxDt;
  uint64_t seed_ = 1;
  bool group_model_ = false;
  Rect world_{0, 0, 10, 10};
  std::vector<Rect> strips_;
  std::size_t explicit_obstacles_ = 0;
  std::vector<Target> targets_;
  std::set<std::string> pointed_;                           // goals given their point
  std::map<int64_t, std::vector<std::size_t>> target_ids_;  // id -> targets (ids may repeat)
  std::set<std::string> speed_warned_;                      // attribute objects warned about
  double agents_ = 0;              // explicit and spawned, for the 10^7 bound
  std::size_t explicit_ = 0;       // placed at the start, for kMaxScenarioAgents
  double removed_ = 0, idle_ = 0;  // agents whose last target is absorbing / not
  std::optional<Val> removed_at_, idle_at_;
};

}  // namespace

Imported import_vadere(const std::filesystem::path& path, std::string_view text,
                       const LoadOptions& options) {
  if (!options.behavior.empty())
    throw Error(
        Error::Kind::usage,
        path.string() + ": a behaviour file goes with a Menge scene, not a Vadere scenario");
  return VadereReader(path, text).run();
}

}  // namespace crowddb::io
