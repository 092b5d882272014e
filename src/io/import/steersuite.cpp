// SteerSuite test cases, read the way SteerSuite's own TestCaseReader reads them
// (SteerSuite/Release, steerlib/src/TestCaseReader*.cpp): the ground plane is x-z (y is height),
// metres and seconds, and random placement follows SteerSuite's algorithm and generator
// (MT19937 seeded with 2, draws in SteerSuite's pass order), so randomly placed agents start
// where SteerSuite puts them. docs/importers.md lists every element and what becomes of it.
#include "io/import/steersuite.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include "crowddb/error.hpp"
#include "io/import/builder.hpp"
#include "io/import/xml.hpp"

namespace crowddb::io {
namespace {

using pugi::xml_node;

constexpr double kArrivalRadius = 0.5;  // PPR's ped_reached_target_distance_threshold
constexpr double kDefaultRadius = 0.5;  // every shipped test case
constexpr double kDefaultSpeed = 1.3;   // EXAMPLE.xml's recommendation
constexpr double kDt = 0.05;            // SteerSuite's default clock: 20 frames per second
constexpr double kDuration = 600;       // SteerSuite runs until every agent is done
constexpr int kAttempts = 10000;        // SteerSuite gives up placing after 10,000 tries
constexpr std::size_t kMaxAgents = kMaxScenarioAgents;

struct Xyz {
  double x = 0, y = 0, z = 0;
  bool random = false;
};

struct Bounds2 {  // an x-z box
  double x0 = 0, x1 = 0, z0 = 0, z1 = 0;
};

struct TargetSpec {
  xml_node node;
  bool box = false;  // seekAxisAlignedBoxRegion
  Xyz target;
  Bounds2 region;
  std::optional<double> speed;
};

struct RawAgent {
  xml_node node;  // <agent>, <agentRegion> or <agentEmitter>
  bool random_position = false;
  Xyz position;
  Bounds2 region;  // where a random position is drawn
  std::optional<Xyz> direction;
  double radius = kDefaultRadius;
  double speed = 0;
  std::vector<TargetSpec> goals;
};

// SteerSuite's MTRand::rand(n): a real in [0, n].
class SteerRng {
 public:
  explicit SteerRng(uint32_t seed) : mt_(seed) {}
  double rand(double n) { return static_cast<double>(mt_()) * (1.0 / 4294967295.0) * n; }

 private:
  std::mt19937 mt_;
};

class SteerSuiteReader {
 public:
  SteerSuiteReader(const std::filesystem::path& path, std::string_view text, std::size_t max_agents)
      : f_(text, path.string()), rng_(2), goal_rng_(2), max_agents_(max_agents) {}

  Imported run() {
    const xml_node root = f_.root();
    const std::string_view rname = XmlFile::local(root);
    if (rname == "SteerSuiteSubSpace")
      f_.fail(root, "SteerSuite sub-space files are not supported (only <SteerBenchTestCase>)");
    if (rname != "SteerBenchTestCase") f_.fail(root, "expected <SteerBenchTestCase>");

    const xml_node header = f_.only_child(root, "header");
    if (!header) f_.fail(root, "missing <header>");
    read_header(header);

    // Pass 1: fixed obstacles, in file order (SteerSuite's reader has the same passes).
    std::vector<xml_node> regions_of_obstacles;
    std::vector<RawAgent> fixed, emitted, random;
    for (xml_node c = root.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      const std::string_view n = XmlFile::local(c);
      if (n == "header" || n == "suggestedCameraView") continue;  // the camera is a viewer hint
      if (n == "obstacle") {
        box_obstacle(c);
      } else if (n == "circleObstacle") {
        circle_obstacle(c);
      } else if (n == "orientedBoxObstacle") {
        oriented_box(c);
      } else if (n == "polygonObstacle") {
        polygon_obstacle(c);
      } else if (n == "orientedWallObstacle") {
        f_.fail(c,
                "not supported (SteerSuite's own reader asserts on it and no test case uses it)");
      } else if (n == "obstacleRegion") {
        regions_of_obstacles.push_back(c);
      } else if (n == "agent") {
        RawAgent a = read_agent(c, false);
        (a.random_position ? random : fixed).push_back(std::move(a));
      } else if (n == "agentEmitter") {
        RawAgent a = read_agent(c, false);
        if (a.random_position) {
          b_.warn("emitter-random", f_.where(c) +
                                        ": an emitter with a random position is dropped "
                                        "(SteerSuite drops it too)");
          continue;
        }
        b_.warn("emitter", f_.where(c) +
                               ": respawning is not supported: imported as one agent (the first "
                               "the emitter lets in)");
        emitted.push_back(std::move(a));
      } else if (n == "agentRegion") {
        read_region(c, random);
      } else {
        f_.fail(c, "unknown element");
      }
    }
    // Pass 2 and 3: agents at given positions (their random directions are drawn now).
    for (RawAgent& a : fixed) emit(a);
    for (RawAgent& a : emitted) emit(a);
    // Pass 4: random boxes of the obstacle regions.
    for (const xml_node& r : regions_of_obstacles) obstacle_region(r);
    // Pass 5: agents at random positions.
    for (RawAgent& a : random) {
      place(a);
      emit(a);
    }
    finish_world();
    return b_.finish();
  }

 private:
  // -- values -------------------------------------------------------------------------------

  // An <x/><y/><z/> tuple or <random>true</random> (exactly one of the two).
  Xyz xyz(const xml_node& n, bool allow_random) {
    Xyz v;
    bool any = false, all = true;
    std::optional<bool> random;
    for (xml_node c = n.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      const std::string_view name = XmlFile::local(c);
      if (name != "x" && name != "y" && name != "z" && name != "random")
        f_.fail(c, "unknown element (expected <x>, <y>, <z> or <random>)");
    }
    for (const char* k : {"x", "y", "z"}) {
      const auto d = f_.child_number(n, k);
      any |= d.has_value();
      all &= d.has_value();
      if (d) (k[0] == 'x' ? v.x : k[0] == 'y' ? v.y : v.z) = *d;
    }
    if (const xml_node r = f_.only_child(n, "random")) {
      const std::string t = f_.text(r);
      if (t != "true" && t != "false") f_.fail(r, "expected true or false, got '" + t + "'");
      random = t == "true";
    }
    if (any && !all) f_.fail(n, "give all of <x>, <y>, <z> or none");
    if (random.value_or(false)) {
      if (any) f_.fail(n, "give either a point or <random>true</random>, not both");
      if (!allow_random) f_.fail(n, "cannot be random here");
      v.random = true;
      return v;
    }
    if (!any) f_.fail(n, "expected <x>, <y>, <z> (or <random>true</random>)");
    return v;
  }

  // A SteerSuite BoundingBox: six children, all required.
  Bounds2 bounding_box(const xml_node& n, bool sort, const char* what) {
    for (xml_node c = n.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      const std::string_view name = XmlFile::local(c);
      if (name != "xmin" && name != "xmax" && name != "ymin" && name != "ymax" && name != "zmin" &&
          name != "zmax")
        f_.fail(c, "unknown element (a box has <xmin> <xmax> <ymin> <ymax> <zmin> <zmax>)");
    }
    double v[6];
    const char* keys[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
    for (int k = 0; k < 6; ++k) {
      const auto d = f_.child_number(n, keys[k]);
      if (!d) f_.fail(n, std::string("missing <") + keys[k] + ">");
      v[k] = *d;
    }
    Bounds2 b{v[0], v[1], v[4], v[5]};
    if (b.x0 > b.x1 || b.z0 > b.z1) {
      if (!sort)
        f_.fail(n, std::string("min > max in ") + (b.x0 > b.x1 ? "x" : "z") + " (" + what + ")");
      b_.warn(std::string("inverted-") + what,
              f_.where(n) + ": min > max: read as the box between the two (" + what + ")");
      if (b.x0 > b.x1) std::swap(b.x0, b.x1);
      if (b.z0 > b.z1) std::swap(b.z0, b.z1);
    }
    return b;
  }

  void only(const xml_node& n, std::initializer_list<std::string_view> allowed) {
    for (xml_node c = n.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      bool ok = false;
      for (std::string_view a : allowed) ok |= XmlFile::local(c) == a;
      if (!ok) f_.fail(c, "unknown element in <" + std::string(XmlFile::local(n)) + ">");
    }
  }

  // -- header -------------------------------------------------------------------------------

  void read_header(const xml_node& h) {
    only(h, {"version", "name", "description", "worldBounds", "passingCriteria"});
    if (const xml_node v = f_.only_child(h, "version")) {
      const std::string t = f_.text(v);
      if (t != "1.0" && t != "1.1" && t != "1.2")
        b_.warn("version", f_.where(v) + ": version '" + t +
                               "' is none SteerSuite knows (1.0, 1.1, 1.2): read as 1.2");
    }
    if (const xml_node n = f_.only_child(h, "name")) name_ = f_.text(n);
    if (const xml_node d = f_.only_child(h, "description")) description_ = f_.text(d);
    const xml_node wb = f_.only_child(h, "worldBounds");
    if (!wb) f_.fail(h, "missing <worldBounds>");
    world_ = bounding_box(wb, true, "worldBounds");
    world_node_ = wb;
  }

  // -- obstacles ----------------------------------------------------------------------------

  void box_obstacle(const xml_node& n) {
    const Bounds2 b = bounding_box(n, false, "obstacle");
    if (b.x0 == b.x1 || b.z0 == b.z1) {
      b_.warn("flat-box", f_.where(n) + ": a box of zero width is dropped (it has no area)");
      return;
    }
    b_.polygon({{b.x0, b.z0}, {b.x1, b.z0}, {b.x1, b.z1}, {b.x0, b.z1}}, f_.where(n));
  }

  void circle_obstacle(const xml_node& n) {
    only(n, {"radius", "height", "position"});
    const auto r = f_.child_number(n, "radius");
    if (!r) f_.fail(n, "missing <radius>");
    if (!(*r > 0)) f_.fail(n, "<radius> must be > 0");
    const xml_node p = f_.only_child(n, "position");
    if (!p) f_.fail(n, "missing <position>");
    const Xyz c = xyz(p, true);
    if (c.random) {
      b_.warn("circle-random", f_.where(n) +
                                   ": a circle at a random position is dropped (SteerSuite drops "
                                   "it too)");
      return;
    }
    b_.circle({c.x, c.z}, *r, f_.where(n));
  }

  // Corners (+-lx/2, +-lz/2) rotated by SteerSuite's rotateInXZPlane: x' = x cos t + z sin t,
  // z' = z cos t - x sin t, t = thetaY in degrees; position is the centre (its y the base).
  void oriented_box(const xml_node& n) {
    only(n, {"thetaY", "size", "position"});
    const auto theta = f_.child_number(n, "thetaY");
    if (!theta) f_.fail(n, "missing <thetaY>");
    const xml_node sz = f_.only_child(n, "size"), ps = f_.only_child(n, "position");
    if (!sz) f_.fail(n, "missing <size>");
    if (!ps) f_.fail(n, "missing <position>");
    const Xyz s = xyz(sz, false), c = xyz(ps, false);
    if (!(s.x > 0 && s.z > 0)) f_.fail(sz, "the box needs x > 0 and z > 0");
    const double t = *theta * std::numbers::pi / 180, ct = std::cos(t), st = std::sin(t);
    std::vector<Vec2> v;
    for (auto [ux, uz] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
      const double x = ux * s.x / 2, z = uz * s.z / 2;
      v.push_back({c.x + x * ct + z * st, c.z + z * ct - x * st});
    }
    b_.polygon(v, f_.where(n));
  }

  // A stub in SteerSuite (no geometry); here the polygon its vertices describe.
  void polygon_obstacle(const xml_node& n) {
    only(n, {"vertex"});
    std::vector<Vec2> v;
    for (const xml_node& c : XmlFile::children(n, "vertex")) {
      const Xyz p = xyz(c, false);
      v.push_back({p.x, p.z});
    }
    if (v.size() < 3) f_.fail(n, "needs at least 3 <vertex> elements");
    b_.warn("polygon", f_.where(n) +
                           ": SteerSuite reads polygon obstacles as a stub without geometry; "
                           "imported as the polygon its vertices describe");
    b_.polygon(v, f_.where(n));
  }

  // numObstacles square boxes of side obstacleSize, each placed like SteerSuite's
  // randomPositionInRegionWithoutCollisions with the size as the disc's radius.
  void obstacle_region(const xml_node& n) {
    only(n, {"numObstacles", "obstacleSize", "obstacleHeight", "regionBounds"});
    const auto count = f_.child_number(n, "numObstacles");
    const auto size = f_.child_number(n, "obstacleSize");
    if (!count) f_.fail(n, "missing <numObstacles>");
    if (!size) f_.fail(n, "missing <obstacleSize>");
    if (*count < 0 || *count != std::floor(*count) ||
        *count > static_cast<double>(std::min<std::size_t>(max_agents_, 100000)))
      f_.fail(n, "<numObstacles> must be a whole number, at most " +
                     std::to_string(std::min<std::size_t>(max_agents_, 100000)));
    if (!(*size > 0)) f_.fail(n, "<obstacleSize> must be > 0");
    const xml_node rb = f_.only_child(n, "regionBounds");
    if (!rb) f_.fail(n, "missing <regionBounds>");
    const Bounds2 r = bounding_box(rb, true, "regionBounds");
    for (int k = 0; k < static_cast<int>(*count); ++k) {
      const Vec2 c = random_spot(r, *size, n, "box " + std::to_string(k + 1));
      const double h = *size / 2;
      b_.polygon({{c.x - h, c.y - h}, {c.x + h, c.y - h}, {c.x + h, c.y + h}, {c.x - h, c.y + h}},
                 f_.where(n));
    }
  }

  // -- agents -------------------------------------------------------------------------------

  RawAgent read_agent(const xml_node& n, bool region) {
    if (region)
      only(n, {"numAgents", "regionBounds", "initialConditions", "goalSequence"});
    else
      only(n, {"name", "initialConditions", "goalSequence"});
    RawAgent a;
    a.node = n;
    a.region = world_;
    const xml_node ic = f_.only_child(n, "initialConditions");
    if (!ic) f_.fail(n, "missing <initialConditions>");
    // Unknown children of initialConditions are ignored by SteerSuite (colour, spawn times).
    if (const auto r = f_.child_number(ic, "radius")) {
      if (!(*r > 0)) f_.fail(f_.only_child(ic, "radius"), "must be > 0");
      a.radius = *r;
    } else {
      b_.warn("no-radius", f_.where(ic) + ": no <radius> (SteerSuite leaves it undefined): " +
                               fmt(kDefaultRadius) + " m");
    }
    if (const auto s = f_.child_number(ic, "speed")) {
      if (!(*s >= 0)) f_.fail(f_.only_child(ic, "speed"), "must be >= 0");
      a.speed = *s;
    }
    if (const xml_node p = f_.only_child(ic, "position")) {
      a.position = xyz(p, true);
      a.random_position = a.position.random;
      heights_ |= a.position.y != 0;
    } else if (region) {
      a.random_position = true;
    } else {
      f_.fail(ic, "missing <position>");
    }
    if (const xml_node d = f_.only_child(ic, "direction")) a.direction = xyz(d, true);
    const xml_node gs = f_.only_child(n, "goalSequence");
    if (!gs) f_.fail(n, "missing <goalSequence>");
    for (xml_node g = gs.first_child(); g; g = g.next_sibling())
      if (g.type() == pugi::node_element) a.goals.push_back(read_goal(g));
    if (a.goals.empty()) f_.fail(gs, "no goals");
    return a;
  }

  void read_region(const xml_node& n, std::vector<RawAgent>& out) {
    RawAgent a = read_agent(n, true);
    const auto count = f_.child_number(n, "numAgents");
    if (!count) f_.fail(n, "missing <numAgents>");
    if (*count < 0 || *count != std::floor(*count) ||
        *count > static_cast<double>(max_agents_ - std::min(max_agents_, out.size())))
      f_.fail(n, "<numAgents> must be a whole number, at most " + std::to_string(max_agents_) +
                     " agents in all");
    const xml_node rb = f_.only_child(n, "regionBounds");
    if (!rb) f_.fail(n, "missing <regionBounds>");
    a.region = bounding_box(rb, true, "regionBounds");
    if (!a.random_position)
      b_.warn("region-position",
              f_.where(n) +
                  ": a <position> in a region's initial conditions puts every agent of "
                  "the region on that point (as in SteerSuite)");
    for (std::size_t k = 0; k < static_cast<std::size_t>(*count); ++k) out.push_back(a);
  }

  TargetSpec read_goal(const xml_node& g) {
    const std::string_view type = XmlFile::local(g);
    TargetSpec out;
    out.node = g;
    if (type == "seekAxisAlignedBoxRegion") {
      out.box = true;
      const xml_node rb = f_.only_child(g, "goalRegionBounds");
      if (!rb) f_.fail(g, "missing <goalRegionBounds>");
      out.region = bounding_box(rb, false, "goalRegionBounds");
      if (out.region.x0 == out.region.x1 || out.region.z0 == out.region.z1)
        f_.fail(rb, "the goal region has no area");
    } else if (type == "seekStaticTarget") {
      const xml_node t = f_.only_child(g, "targetLocation");
      if (!t) f_.fail(g, "missing <targetLocation>");
      out.target = xyz(t, true);
      heights_ |= out.target.y != 0;
    } else if (type == "fleeStaticTarget" || type == "seekDynamicTarget" ||
               type == "fleeDynamicTarget" || type == "flowStaticDirection" ||
               type == "flowDynamicDirection" || type == "idle" || type == "groupTarget") {
      f_.fail(g,
              "goal type not supported (SteerSuite's own steering modules reject it too; "
              "seekStaticTarget and seekAxisAlignedBoxRegion are)");
    } else {
      f_.fail(g, "unknown goal type");
    }
    // SteerSuite ignores unknown children of a goal; <random>true</random> at goal level makes a
    // static target random as well.
    if (const xml_node r = f_.only_child(g, "random"); r && f_.text(r) == "true" && !out.box)
      out.target.random = true;
    if (const auto s = f_.child_number(g, "desiredSpeed")) {
      if (!(*s > 0)) f_.fail(f_.only_child(g, "desiredSpeed"), "must be > 0");
      out.speed = *s;
    }
    if (f_.only_child(g, "Behaviour"))
      b_.warn("behaviour", f_.where(f_.only_child(g, "Behaviour")) +
                               ": ignored (no SteerSuite steering module reads it)");
    return out;
  }

  // A random spot for a disc of radius r in the x-z box, by SteerSuite's rejection sampling.
  Vec2 random_spot(const Bounds2& region, double r, const xml_node& n, const std::string& what) {
    const double xspan = region.x1 - region.x0 - 2 * r, zspan = region.z1 - region.z0 - 2 * r;
    if (xspan < 0 || zspan < 0)
      f_.fail(n, "the region is narrower than the " + what + " (radius " + fmt(r) + " m)");
    for (int k = 0; k < kAttempts; ++k) {
      const double x = region.x0 + r + rng_.rand(xspan);
      const double z = region.z0 + r + rng_.rand(zspan);
      if (b_.free(x, z, r)) return {x, z};
    }
    f_.fail(n, "could not place " + what + " without overlaps in " + std::to_string(kAttempts) +
                   " tries (SteerSuite gives up there too): the region is too crowded");
  }

  void place(RawAgent& a) {
    const Vec2 p =
        random_spot(a.region, a.radius, a.node, "agent " + std::to_string(b_.agent_count() + 1));
    a.position = {p.x, 0, p.y, false};
  }

  // Adds the agent row; draws its random direction (after its position, as SteerSuite does).
  void emit(RawAgent& a) {
    Vec2 dir{0, 0};
    if (a.direction && a.direction->random) {
      const double t = rng_.rand(2 * std::numbers::pi);
      dir = {std::cos(t), std::sin(t)};
    } else if (a.direction) {
      dir = {a.direction->x, a.direction->z};
    }
    nlohmann::json goals = nlohmann::json::array();
    std::optional<double> speed;
    Vec2 first_target{};
    for (std::size_t k = 0; k < a.goals.size(); ++k) {
      const TargetSpec& g = a.goals[k];
      std::string name;
      if (g.box) {
        name = b_.area_goal({{g.region.x0, g.region.z0},
                             {g.region.x1, g.region.z0},
                             {g.region.x1, g.region.z1},
                             {g.region.x0, g.region.z1}},
                            f_.where(g.node));
        if (k == 0)
          first_target = {(g.region.x0 + g.region.x1) / 2, (g.region.z0 + g.region.z1) / 2};
      } else {
        Vec2 t{g.target.x, g.target.z};
        if (g.target.random) t = random_target(g.node);
        name = b_.disc_goal(t, kArrivalRadius, f_.where(g.node));
        if (k == 0) first_target = t;
      }
      goals.push_back(name);
      if (g.speed) {
        if (speed && *speed != *g.speed)
          b_.warn("speeds", f_.where(g.node) +
                                ": one walking speed per agent: the first goal's desiredSpeed " +
                                fmt(*speed) + " m/s is kept, not " + fmt(*g.speed));
        if (!speed) speed = g.speed;
      }
    }
    if (!speed) {
      b_.warn("no-speed", f_.where(a.goals.front().node) +
                              ": no <desiredSpeed> (SteerSuite leaves it undefined): " +
                              fmt(kDefaultSpeed) + " m/s");
      speed = kDefaultSpeed;
    }
    if (!a.direction) {
      b_.warn("no-direction", f_.where(a.node) + ": no initial <direction>: facing the first goal");
      dir = {first_target.x - a.position.x, first_target.y - a.position.z};
    }
    const double len = std::hypot(dir.x, dir.y);
    const double vx = len > 0 ? a.speed * dir.x / len : 0;
    const double vy = len > 0 ? a.speed * dir.y / len : 0;
    nlohmann::json row = {{"x", a.position.x}, {"y", a.position.z},  {"vx", vx},
                          {"vy", vy},          {"radius", a.radius}, {"pref_speed", *speed}};
    row["goal"] = goals.size() == 1 ? goals[0] : goals;
    b_.agent(std::move(row), f_.where(a.node));
    b_.occupy(a.position.x, a.position.z, a.radius);
  }

  // SteerSuite's modules draw a random target when the goal becomes active: a uniform point of
  // the world 1 m clear of obstacles. Drawn here once, from a generator of their own (MT19937
  // seeded with 2, like the engine's), in the order agents are listed.
  Vec2 random_target(const xml_node& n) {
    const Bounds2& w = world_;
    for (int k = 0; k < kAttempts; ++k) {
      const double x = w.x0 + goal_rng_.rand(w.x1 - w.x0), z = w.z0 + goal_rng_.rand(w.z1 - w.z0);
      if (b_.free(x, z, 1.0, /*agents=*/false)) return {x, z};  // agents do not block it
    }
    f_.fail(n, "could not draw a random target 1 m clear of the obstacles");
  }

  void finish_world() {
    const Box& e = b_.extent();
    double x0 = world_.x0, y0 = world_.z0, x1 = world_.x1, y1 = world_.z1;
    const bool degenerate = !(x1 > x0 && y1 > y0);
    if (!e.empty() && (degenerate || e.x0 < x0 || e.y0 < y0 || e.x1 > x1 || e.y1 > y1)) {
      constexpr double kBoundsMargin = 1;
      if (!degenerate) {
        b_.warn("world", f_.where(world_node_) +
                             ": the scene extends beyond worldBounds (SteerSuite does not clip "
                             "to them): the world is grown to hold it, with a 1 m margin");
        x0 = std::min(x0, e.x0 - kBoundsMargin);
        y0 = std::min(y0, e.y0 - kBoundsMargin);
        x1 = std::max(x1, e.x1 + kBoundsMargin);
        y1 = std::max(y1, e.y1 + kBoundsMargin);
      } else {
        x0 = e.x0 - kBoundsMargin;
        y0 = e.y0 - kBoundsMargin;
        x1 = e.x1 + kBoundsMargin;
        y1 = e.y1 + kBoundsMargin;
      }
    }
    if (heights_)
      b_.warn("heights", f_.source() +
                             ": heights (y) are ignored: the ground plane x-z is the "
                             "world's x-y");
    nlohmann::json& d = b_.doc();
    d["name"] = name_.empty() ? std::filesystem::path(f_.source()).stem().string() : name_;
    d["description"] = "SteerSuite test case " + f_.source() +
                       (description_.empty() ? std::string() : ": " + description_);
    d["bounds"] = {x0, y0, x1, y1};
    d["dt"] = kDt;
    d["duration"] = kDuration;
    d["stop_when_all_arrived"] = true;
    d["arrival"] = "remove";
    // SteerSuite's reference agents plan paths around obstacles (PPR's A* on its grid): the
    // path service does that here.
    if (!d["obstacles"].empty()) d["navigation"] = nlohmann::json::object();
  }

  XmlFile f_;
  DocBuilder b_;
  SteerRng rng_, goal_rng_;
  Bounds2 world_;
  xml_node world_node_;
  std::string name_, description_;
  bool heights_ = false;
  std::size_t max_agents_;
};

}  // namespace

Imported import_steersuite(const std::filesystem::path& path, std::string_view text,
                           const LoadOptions& options) {
  if (!options.behavior.empty())
    throw Error(Error::Kind::usage,
                path.string() +
                    ": a behaviour file goes with a Menge scene, not a SteerSuite "
                    "test case");
  return SteerSuiteReader(path, text, kMaxAgents).run();
}

Imported import_steersuite(const std::filesystem::path& path, std::string_view text,
                           const LoadOptions& options, std::size_t max_agents) {
  if (!options.behavior.empty()) return import_steersuite(path, text, options);
  return SteerSuiteReader(path, text, std::min(max_agents, kMaxAgents)).run();
}

}  // namespace crowddb::io
