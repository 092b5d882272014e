// Menge (MengeCrowdSim/Menge) projects, scenes and behaviours, read the way Menge's own loaders
// read them (SimXMLLoader, FSMDescrip, buildFSM): agents from the scene's generators, with the
// profile values sampled per agent; obstacles from explicit obstacle sets; and the behaviour's
// state machine compiled, per agent, into a crowddb goal sequence.
//
// Compiling the state machine (docs/importers/menge.md, "Behaviour"): an agent starts in its
// group's state; the state's goal selector picks a goal from where the agent is at that point
// (its initial position, later the point of the goal it has just reached). A transition whose
// condition already holds there fires at once (`auto`, or `goal_reached` when the agent is within
// the distance); otherwise the agent walks to the goal, and the first `goal_reached` transition
// of the state (in declaration order) moves it on: the goal's area is Menge's reach region for
// that distance. Where the agent stands, the state's first timer moves it on: the timer becomes
// the wait of the goal it stands on. Prob targets are drawn per agent and visit. A final state
// ends the sequence (the agent stands, arrival policy "idle"); so does a state nothing moves the
// agent out of. A loop back to a state the agent has been in is followed round until the
// project's duration has surely passed. Everything else in a state machine (spatial conditions,
// and/or/not, return targets, timers where the agent walks, actions, velocity modifiers, tasks,
// events) cannot be evaluated before the run: each kind is one warning line, and the chain
// follows the goal_reached path.
//
// Random draws (profile selectors, property distributions, generator noise, random goals) come
// from crowddb's Rng, one stream per agent (the project's `random` seed, the agent's index), in
// that order; they do not reproduce Menge's numbers. The work is bounded by the input: at most
// `max_agents` agents, each sequence at most kMaxVisits goals (kMaxVisitsInAll in all), each
// goal found in O(transitions + goals of a set).
#include "io/import/menge.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>

#include "crowddb/error.hpp"
#include "io/import/builder.hpp"
#include "io/import/xml.hpp"
#include "util/rng.hpp"
#include "world/geometry.hpp"

namespace crowddb::io {
namespace {

using pugi::xml_node;

constexpr double kMinReach = 0.05;  // [m] smallest arrival disc of a point goal
constexpr double kWall = 0.1;       // [m] thickness of walls made from segments
constexpr double kMargin = 2;       // [m] around everything, for the bounds
constexpr double kTimeStep = 0.1;   // Menge's default <Common time_step>
constexpr double kBigWhole = 9e15;  // whole numbers above this are not read exactly
constexpr uint64_t kAllGoals = std::numeric_limits<uint64_t>::max();
// The streams of the timers drawn once at load (per_agent="0"), counted down from here, clear of
// the agents' streams (one per agent index).
constexpr uint64_t kTimerStream = std::numeric_limits<uint64_t>::max();
// A state machine that loops is followed round until the project's duration has surely passed,
// with at most this many goals in an agent's sequence, and this many in all the sequences.
// Each pick from a goal set costs the set's size: the rounds stop after this many in all, so that
// a project of many agents and goals cannot make the import hang.
constexpr std::size_t kMaxVisits = 1000;
constexpr std::size_t kMaxVisitsInAll = 1 << 20;
constexpr std::size_t kMaxPickWork = std::size_t{1} << 27;

const char* const kModels[] = {"orca",       "pedvo",    "helbing", "johannson",
                               "karamouzas", "zanlungo", "gcf",     "dummy"};
// Each model's per-agent and global parameter tag.
const char* model_tag(const std::string& model) {
  if (model == "orca") return "ORCA";
  if (model == "pedvo") return "PedVO";
  if (model == "helbing") return "Helbing";
  if (model == "johannson") return "Johansson";
  if (model == "karamouzas") return "Karamouzas";
  if (model == "zanlungo") return "Zanlungo";
  if (model == "gcf") return "GCF";
  return "Dummy";
}
bool model_tag_name(std::string_view n) {
  for (const char* t : {"ORCA", "PedVO", "Helbing", "Johansson", "Karamouzas", "Zanlungo", "GCF",
                        "Dummy", "OpenSteer"})
    if (n == t) return true;
  return false;
}

std::string clip(std::string_view s) {
  return std::string(s.substr(0, 40)) + (s.size() > 40 ? "..." : "");
}

// -- attributes ------------------------------------------------------------------------------
// Menge reads numbers with atof/atoi (a malformed value is 0, silently). Here numbers are strict
// (an error names the attribute); booleans follow atoi, with a warning when the text is not an
// integer, since Menge's files rely on it ("true" reads as false).

uint64_t whole(const XmlFile& f, const xml_node& n, const char* name,
               std::optional<uint64_t> fallback = std::nullopt) {
  std::optional<double> v = f.attr_number_opt(n, name);
  if (!v) {
    if (!fallback) f.fail(n, std::string("missing attribute '") + name + "' (a whole number)");
    return *fallback;
  }
  if (!(*v >= 0) || *v != std::floor(*v) || *v > kBigWhole)
    f.fail(n, std::string("attribute '") + name + "': expected a whole number >= 0, got '" +
                  clip(n.attribute(name).value()) + "'");
  return static_cast<uint64_t>(*v);
}

bool flag(const XmlFile& f, DocBuilder& b, const xml_node& n, const char* name, bool fallback) {
  const pugi::xml_attribute a = n.attribute(name);
  if (!a) return fallback;
  const std::string_view s = a.value();
  auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  std::size_t i = 0;
  while (i < s.size() && space(s[i])) ++i;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
  const std::size_t digits = i;
  bool nonzero = false;
  while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) nonzero |= s[i++] != '0';
  const bool integer = i > digits;
  while (i < s.size() && space(s[i])) ++i;
  std::string lower(s);
  for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  // "false" reads as 0, which is what it says: only texts whose reading differs are reported.
  if ((!integer || i != s.size()) && lower != "false")
    b.warn(std::string("bool:") + name,
           f.where(n) + ": " + name + "=\"" + clip(s) + "\" is not an integer: read as " +
               (nonzero ? "1 (true)" : "0 (false)") +
               ", as Menge does (it reads booleans with atoi: only a non-zero integer is true)");
  return nonzero;
}

std::string type_of(const XmlFile& f, const xml_node& n) {
  return f.attr_string(n, "type");
}

// -- distributions ---------------------------------------------------------------------------

struct Dist {
  enum class Kind { c, u, n };
  Kind kind = Kind::c;
  double a = 0, b = 0;  // c: the value; u: min, max; n: mean, stddev
  xml_node node;        // where it was given (empty: Menge's default)

  static Dist constant(double v, xml_node n = {}) { return {Kind::c, v, 0, n}; }

  double sample(Rng& rng, bool integer) const {
    switch (kind) {
      case Kind::c:
        return a;
      case Kind::u:
        if (integer) {
          const double lo = std::min(a, b), hi = std::max(a, b);
          return lo + static_cast<double>(rng.below(static_cast<uint64_t>(hi - lo) + 1));
        }
        return rng.uniform(a, b);
      case Kind::n: {
        // Box-Muller, clamped to mean +- 3 sigma as Menge's normal generator is.
        const double u1 = 1.0 - rng.uniform(), u2 = rng.uniform();
        const double z = std::sqrt(-2 * std::log(u1)) * std::cos(2 * std::numbers::pi * u2);
        return std::clamp(a + b * z, a - 3 * b, a + 3 * b);
      }
    }
    return a;
  }
};

// -- goals -----------------------------------------------------------------------------------

struct Shape {
  enum class Kind { point, circle, aabb, obb };
  Kind kind = Kind::point;
  Vec2 p;               // the point, the circle's centre, the AABB's min corner, the OBB's pivot
  double r = 0;         // circle radius
  double w = 0, h = 0;  // box size (OBB: along its rotated axes)
  double c = 1, s = 0;  // OBB rotation

  Vec2 world(double lx, double ly) const {  // a point of the box's local frame
    return {p.x + c * lx - s * ly, p.y + s * lx + c * ly};
  }
  Vec2 centroid() const {
    switch (kind) {
      case Kind::point:
      case Kind::circle:
        return p;
      case Kind::aabb:
        return {p.x + w / 2, p.y + h / 2};
      case Kind::obb:
        return world(w / 2, h / 2);
    }
    return p;
  }
  // Menge's Geometry2D::squaredDistance: a circle measures to its perimeter.
  double sqdist(Vec2 q) const {
    double lx = q.x - p.x, ly = q.y - p.y;
    switch (kind) {
      case Kind::point:
        return lx * lx + ly * ly;
      case Kind::circle: {
        const double d = std::hypot(lx, ly) - r;
        return d * d;
      }
      case Kind::obb: {
        const double x = c * lx + s * ly, y = c * ly - s * lx;
        lx = x;
        ly = y;
        break;
      }
      case Kind::aabb:
        break;
    }
    const double dx = lx < 0 ? -lx : (lx > w ? lx - w : 0);
    const double dy = ly < 0 ? -ly : (ly > h ? ly - h : 0);
    return dx * dx + dy * dy;
  }
  // The box grown by d on every side (corners square), counter-clockwise.
  std::vector<Vec2> box(double d) const {
    return {world(-d, -d), world(w + d, -d), world(w + d, h + d), world(-d, h + d)};
  }
};

struct GoalDef {
  Shape shape;
  uint64_t id = 0;
  uint64_t capacity = kAllGoals;
  double weight = 1;
  xml_node node;
  uint64_t assigned = 0;  // agents given this goal so far (the static view: nobody leaves)
};

struct GoalSetDef {
  uint64_t id = 0;
  xml_node node;
  std::vector<GoalDef> goals;             // in the file's order (Menge's order for every selector)
  std::map<uint64_t, std::size_t> index;  // goal id -> position in `goals`
};

// -- states ----------------------------------------------------------------------------------

struct SelectorDef {
  enum class Type {
    identity,
    explicit_,
    mirror,
    offset,
    nearest,
    farthest,
    random,
    weighted,
    shared
  };
  Type type = Type::identity;
  xml_node node;  // empty: the default identity selector (the state names it)
  uint64_t set_id = 0, goal_id = 0;
  std::size_t set = 0, goal = 0;  // resolved
  bool mirror_x = false, mirror_y = false;
  Dist off_x, off_y;  // offset: a 2-D distribution, x then y
  std::string shared_name;
  std::size_t shared_state = 0;
  // The agent keeps the goal it got on its first entry (persistent="1", or a state whose
  // selector another state shares).
  bool persistent = false;
};

enum class Motion { walk, navigate, stand };

struct TransitionDef {
  xml_node node;
  enum class Cond { goal_reached, always, timer, other };
  Cond cond = Cond::other;
  xml_node cond_node;
  double distance = 0;
  // timer: the wait, as a crowddb goal's `wait` (null: none), and its least value [s]
  nlohmann::json wait;
  double least_wait = 0;
  // A state; kProb: a prob target (`prob`, states and weights, drawn per agent and visit); -1:
  // a target a static sequence cannot follow (return).
  static constexpr std::ptrdiff_t kProb = -2;
  std::ptrdiff_t target = -1;
  std::vector<std::pair<std::size_t, double>> prob;
  bool followable() const { return target >= 0 || target == kProb; }
};

struct StateDef {
  std::string name;
  xml_node node;
  bool final = false;
  SelectorDef sel;
  Motion motion = Motion::stand;  // Menge's default: the zero velocity component
  std::vector<TransitionDef> out;
};

// -- scene -----------------------------------------------------------------------------------

struct Profile {
  std::string name;
  xml_node node;
  Dist max_speed = Dist::constant(2.5), pref_speed = Dist::constant(1.34),
       neighbor_dist = Dist::constant(5), max_neighbors = Dist::constant(10),
       radius = Dist::constant(0.2), tau = Dist::constant(2.5), tau_obst = Dist::constant(0.15);
  uint64_t obstacle_set = 0xFFFFFFFF;
  bool used = false;
};

struct Generator {
  enum class Type { explicit_, rect, hex };
  Type type = Type::explicit_;
  xml_node node;
  std::vector<std::pair<Vec2, xml_node>> points;  // explicit
  Vec2 anchor;
  double c = 1, s = 0;  // rotation
  Vec2 offset;          // rect_grid
  uint64_t nx = 0;      // rect_grid: count_x
  bool row_x = true;    // hex_lattice
  uint64_t row_pop = 1;
  double row_dist = 0, nbr = 0;
  uint64_t count = 0;
  std::optional<Dist> noise;

  Vec2 local(uint64_t i) const {
    if (type == Type::rect)
      return {static_cast<double>(i % nx) * offset.x, static_cast<double>(i / nx) * offset.y};
    const double half = nbr / 2;
    if (row_x) {
      const uint64_t band_pop = 2 * row_pop - 1, band = i / band_pop, j = i - band * band_pop;
      const double y = static_cast<double>(band) * 2 * row_dist;
      if (j >= row_pop) return {half + static_cast<double>(j - row_pop) * nbr, y + row_dist};
      return {static_cast<double>(j) * nbr, y};
    }
    const uint64_t column = i / row_pop, j = i - column * row_pop;
    return {static_cast<double>(column) * row_dist,
            static_cast<double>(j) * nbr + (column % 2 ? half : 0)};
  }
};

struct ProfileChoice {
  std::size_t profile;
  double weight;
};

struct Group {
  xml_node node;
  xml_node profile_sel, state_sel;
  bool weighted = false;
  std::vector<ProfileChoice> profiles;
  std::size_t state = 0;
  std::vector<Generator> generators;
};

struct Obstacle {
  std::vector<Vec2> ring;
  xml_node node;
};

struct ObstacleSetDef {
  uint64_t cls = 0;
  xml_node node;
  std::vector<Obstacle> obstacles;
};

// A goal picked for an agent in a state.
struct Picked {
  Shape shape;
  std::string origin;  // the <Goal>, or the selector that made the goal for the agent
};

class MengeReader {
 public:
  MengeReader(std::string_view scene, const std::string& scene_name, std::string_view behavior,
              const std::string& behavior_name, const ProjectSettings& settings)
      : scene_(scene, scene_name), bfsm_(behavior, behavior_name), set_(settings) {}

  Imported run() {
    check_model();
    read_scene();
    read_behavior();
    make_agents();
    finish_world();
    return b_.finish();
  }

 private:
  // -- project -----------------------------------------------------------------------------

  void check_model() {
    const std::string& m = set_.model;
    if (std::find_if(std::begin(kModels), std::end(kModels),
                     [&](const char* k) { return m == k; }) == std::end(kModels))
      throw Error(Error::Kind::input,
                  (set_.origin.empty() ? scene_.source() : set_.origin) + ": unknown model '" +
                      clip(m) +
                      "' (Menge's are orca, pedvo, helbing, johannson, karamouzas, zanlungo, "
                      "gcf, dummy)");
    orca_ = m == "orca" || m == "pedvo";
    tag_ = model_tag(m);
    if (!set_.model_given)
      b_.warn("no-model", (set_.origin.empty() ? scene_.source() : set_.origin) +
                              ": no model named (Menge takes it from the project or its "
                              "command line): read as orca");
    if (!orca_)
      b_.warn("model", (set_.origin.empty() ? scene_.source() : set_.origin) + ": model '" + m +
                           "' is not in crowddb: its agents steer with crowddb's default model "
                           "(orca, default parameters); the <" +
                           tag_ + "> parameters are dropped");
  }

  // -- scene -------------------------------------------------------------------------------

  void read_scene() {
    const xml_node root = scene_.root();
    if (XmlFile::local(root) != "Experiment")
      scene_.fail(root, "expected a Menge scene (<Experiment>)");
    if (const pugi::xml_attribute v = root.attribute("version");
        v && std::string(v.value()) != "2.0")
      b_.warn("version", scene_.where(root) + ": version \"" + clip(v.value()) +
                             "\" (Menge writes 2.0 and never reads it): read as 2.0");
    bool common = false, spatial = false, elevation = false;
    for (xml_node c = root.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      const std::string_view n = XmlFile::local(c);
      if (n == "Common") {
        common = true;
        for (pugi::xml_attribute a = c.first_attribute(); a; a = a.next_attribute()) {
          if (std::string_view(a.name()) == "time_step") {
            time_step_ = scene_.attr_number(c, "time_step");
            if (!(time_step_ > 0)) scene_.fail(c, "attribute 'time_step': must be > 0");
          } else {
            b_.warn("common-attr", scene_.where(c) + ": unknown attribute '" + clip(a.name()) +
                                       "': ignored (as Menge does)");
          }
        }
      } else if (n == "SpatialQuery") {
        if (spatial) scene_.fail(c, "a second <SpatialQuery> (Menge allows one)");
        spatial = true;
        spatial_query(c);
      } else if (n == "Elevation") {
        if (elevation) scene_.fail(c, "a second <Elevation> (Menge allows one)");
        elevation = true;
        const std::string t = type_of(scene_, c);
        if (t == "nav_mesh" || t == "height_field")
          b_.warn("elevation", scene_.where(c) + ": elevation '" + t +
                                   "' dropped: heights are ignored (Menge's 2-D dynamics do not "
                                   "use them either; only its terrain velocity modifier does)");
        else if (t != "flat")
          scene_.fail(c, "unknown elevation type '" + clip(t) + "' (flat, nav_mesh, height_field)");
      } else if (n == "AgentProfile") {
        profile(c);
      } else if (n == "AgentGroup") {
        group_nodes_.push_back(c);
      } else if (n == "ObstacleSet") {
        obstacle_set(c);
      } else if (!model_tag_name(n)) {
        b_.warn("scene-element:" + std::string(n),
                scene_.where(c) + ": unknown element: ignored (as Menge does)");
      }
    }
    if (!common) scene_.fail(root, "missing <Common time_step=...> (Menge requires it)");
    if (!spatial) scene_.fail(root, "missing <SpatialQuery> (Menge requires it)");
    if (group_nodes_.empty()) scene_.fail(root, "no <AgentGroup>: Menge needs at least one agent");
  }

  void spatial_query(const xml_node& c) {
    const std::string t = type_of(scene_, c);
    if (t != "kd-tree" && t != "nav_mesh")
      scene_.fail(c, "unknown spatial query type '" + clip(t) + "' (kd-tree, nav_mesh)");
    if (flag(scene_, b_, c, "test_visibility", false))
      b_.warn("visibility", scene_.where(c) +
                                ": test_visibility=1 (neighbours behind obstacles are not seen) "
                                "is not supported: every agent sees its neighbours");
    if (t == "nav_mesh")
      b_.warn("sq-navmesh", scene_.where(c) + ": a nav-mesh spatial query is not read (file " +
                                clip(c.attribute("file_name").value()) +
                                "): neighbours are found by distance, obstacles come from the "
                                "obstacle sets only");
  }

  // -- profiles ----------------------------------------------------------------------------

  void profile(const xml_node& n) {
    Profile p;
    p.name = scene_.attr_string(n, "name");
    p.node = n;
    if (profile_index_.count(p.name))
      scene_.fail(n, "a second profile named '" + clip(p.name) + "' (names are unique)");
    if (const pugi::xml_attribute inh = n.attribute("inherits")) {
      const auto it = profile_index_.find(inh.value());
      if (it == profile_index_.end())
        scene_.fail(n, "inherits from the undefined profile '" + clip(inh.value()) +
                           "' (define it before this one, as Menge requires)");
      const std::string name = p.name;
      p = profiles_[it->second];
      p.name = name;
      p.node = n;
      p.used = false;
    }
    for (xml_node c = n.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      const std::string_view cn = XmlFile::local(c);
      if (cn == "Common" || cn == tag_) {
        for (pugi::xml_attribute a = c.first_attribute(); a; a = a.next_attribute())
          profile_attr(p, c, a.name());
        for (xml_node q = c.first_child(); q; q = q.next_sibling()) {
          if (q.type() != pugi::node_element) continue;
          if (XmlFile::local(q) != "Property") {
            b_.warn("profile-child", scene_.where(q) +
                                         ": unexpected element: ignored (as "
                                         "Menge does)");
            continue;
          }
          property(p, q);
        }
      } else if (cn == "VelModifier") {
        b_.warn("velmod-profile", scene_.where(c) + ": velocity modifier '" +
                                      clip(c.attribute("type").value()) +
                                      "' not supported: dropped");
      } else if (!model_tag_name(cn)) {
        b_.warn("profile-element:" + std::string(cn),
                scene_.where(c) + ": unknown element in a profile: ignored (as Menge does)");
      }
    }
    profile_index_[p.name] = profiles_.size();
    profiles_.push_back(std::move(p));
  }

  // One attribute of <Common> or of the model's tag: a constant.
  void profile_attr(Profile& p, const xml_node& c, const char* name) {
    const std::string_view a = name;
    auto number = [&] { return Dist::constant(scene_.attr_number(c, name), c); };
    if (a == "r") {
      p.radius = number();
    } else if (a == "pref_speed") {
      p.pref_speed = number();
    } else if (a == "max_speed") {
      p.max_speed = number();
    } else if (a == "neighbor_dist") {
      p.neighbor_dist = number();
    } else if (a == "max_neighbors") {
      p.max_neighbors = Dist::constant(static_cast<double>(whole(scene_, c, name)), c);
    } else if (a == "max_accel" || a == "max_angle_vel" || a == "priority") {
      scene_.attr_number(c, name);  // checked; crowddb has no use for it (docs)
    } else if (a == "class") {
      whole(scene_, c, name);
    } else if (a == "obstacleSet") {
      p.obstacle_set = whole(scene_, c, name);
    } else if (orca_ && a == "tau") {
      p.tau = number();
    } else if (orca_ && a == "tauObst") {
      p.tau_obst = number();
    } else if (set_.model == "pedvo" &&
               (a == "turningBias" || a == "factor" || a == "buffer" || a == "density_aware")) {
      scene_.attr_number(c, name);
      b_.warn("pedvo", scene_.where(c) + ": PedVO's " + std::string(a) +
                           " (and its other pedestrian terms) dropped: crowddb's orca");
    } else if (XmlFile::local(c) == "Common") {
      b_.warn("profile-attr", scene_.where(c) + ": unexpected attribute '" + clip(a) +
                                  "': ignored (Menge warns and ignores it too)");
    }
    // Other attributes of a non-orca model's tag: dropped with the model (one warning above).
  }

  void property(Profile& p, const xml_node& q) {
    const std::string name = scene_.attr_string(q, "name");
    auto dist = [&](bool integer) {
      if (q.attribute("seed"))
        b_.warn("seed", scene_.where(q) +
                            ": seed attributes are ignored: every draw comes from the "
                            "project's random seed");
      const std::string t = scene_.attr_string(q, "dist");
      Dist d;
      d.node = q;
      auto num = [&](const char* key) {
        const double v = scene_.attr_number(q, key);
        if (integer && (v != std::floor(v) || std::abs(v) > kBigWhole))
          scene_.fail(q, std::string("attribute '") + key + "': expected a whole number");
        return v;
      };
      if (t == "c") {
        d.a = num("value");
      } else if (t == "u") {
        d.kind = Dist::Kind::u;
        d.a = num("min");
        d.b = num("max");
      } else if (t == "n" && !integer) {
        d.kind = Dist::Kind::n;
        d.a = num("mean");
        d.b = num("stddev");
        if (d.b < 0) scene_.fail(q, "attribute 'stddev': must be >= 0");
      } else {
        scene_.fail(q, "attribute 'dist': unknown distribution '" + clip(t) + "' (" +
                           (integer ? "c or u for an integer" : "c, u or n") + ")");
      }
      return d;
    };
    if (name == "r") {
      p.radius = dist(false);
    } else if (name == "pref_speed") {
      p.pref_speed = dist(false);
    } else if (name == "max_speed") {
      p.max_speed = dist(false);
    } else if (name == "neighbor_dist") {
      p.neighbor_dist = dist(false);
    } else if (name == "max_neighbors") {
      p.max_neighbors = dist(true);
    } else if (name == "max_accel" || name == "max_angle_vel") {
      dist(false);  // checked, dropped (docs)
    } else if (orca_ && name == "tau") {
      p.tau = dist(false);
    } else if (orca_ && name == "tauObst") {
      p.tau_obst = dist(false);
    } else {
      b_.warn("property", scene_.where(q) + ": property '" + clip(name) +
                              "' is none Menge samples: ignored (as Menge does)");
    }
  }

  // -- obstacles ---------------------------------------------------------------------------

  void obstacle_set(const xml_node& n) {
    const std::string t = type_of(scene_, n);
    const uint64_t cls = whole(scene_, n, "class");
    if (t == "nav_mesh") {
      b_.warn("obst-navmesh", scene_.where(n) + ": a nav-mesh obstacle set is not read (file " +
                                  clip(n.attribute("file_name").value()) +
                                  "): the walls of its mesh are missing from the scene");
      return;
    }
    if (t != "explicit")
      scene_.fail(n, "unknown obstacle set type '" + clip(t) + "' (explicit, nav_mesh)");
    ObstacleSetDef set{cls, n, {}};
    for (xml_node o = n.first_child(); o; o = o.next_sibling()) {
      if (o.type() != pugi::node_element) continue;
      if (XmlFile::local(o) != "Obstacle") {
        b_.warn("obst-child", scene_.where(o) +
                                  ": unexpected element in an obstacle set: "
                                  "ignored (as Menge does)");
        continue;
      }
      set.obstacles.push_back({obstacle(o), o});
    }
    obstacle_sets_.push_back(std::move(set));
  }

  // An obstacle's vertices, checked; spikes (an edge doubling back along the one before, which
  // Menge's segments allow and a polygon does not) are removed.
  std::vector<Vec2> obstacle(const xml_node& o) {
    if (!flag(scene_, b_, o, "closed", false))
      scene_.fail(o,
                  "an open obstacle (closed=\"0\" or missing): Menge does not support them "
                  "either");
    std::vector<Vec2> v;
    for (xml_node c = o.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      if (XmlFile::local(c) != "Vertex") {
        b_.warn("obst-child", scene_.where(c) +
                                  ": unexpected element in an obstacle: ignored "
                                  "(as Menge does)");
        continue;
      }
      v.push_back({scene_.attr_number(c, "p_x"), scene_.attr_number(c, "p_y")});
    }
    if (v.size() < 2) scene_.fail(o, "an obstacle needs at least 2 <Vertex> elements");
    // A ring without area is all spikes: it stays as it is and becomes walls.
    if (v.size() < 3 || signed_area(v) == 0) return v;
    return without_spikes(v, o);
  }

  // Repeated vertices and spike tips removed in one pass (a stack over the ring, then its seam).
  std::vector<Vec2> without_spikes(const std::vector<Vec2>& v, const xml_node& o) {
    auto same = [](Vec2 a, Vec2 b) { return a.x == b.x && a.y == b.y; };
    bool spikes = false;
    auto spike = [&](Vec2 a, Vec2 m, Vec2 c) {
      const double ux = m.x - a.x, uy = m.y - a.y, wx = c.x - m.x, wy = c.y - m.y;
      const bool yes = cross(ux, uy, wx, wy) == 0 && ux * wx + uy * wy < 0;
      spikes |= yes;
      return yes;
    };
    std::vector<Vec2> out;
    for (const Vec2& m : v) {
      if (!out.empty() && same(out.back(), m)) continue;
      out.push_back(m);
      while (out.size() >= 3 && spike(out[out.size() - 3], out[out.size() - 2], out.back())) {
        out.erase(out.end() - 2);
        if (same(out[out.size() - 2], out.back())) out.pop_back();
      }
    }
    std::size_t f = 0;  // the ring is out[f..]
    while (out.size() - f > 2) {
      const std::size_t n = out.size();
      if (same(out[n - 1], out[f]) || spike(out[n - 2], out[n - 1], out[f])) {
        out.pop_back();
      } else if (spike(out[n - 1], out[f], out[f + 1])) {
        ++f;
      } else {
        break;
      }
    }
    if (spikes)
      b_.warn("spike", scene_.where(o) +
                           ": a spike (an edge doubling back along the one before it) is "
                           "removed from the polygon");
    if (out.size() - f < 3) return v;  // cannot happen for a ring with area
    return {out.begin() + static_cast<std::ptrdiff_t>(f), out.end()};
  }

  // One obstacle into the document: counter-clockwise, a solid block; clockwise, a container
  // (finish_world); without area, walls.
  void add_obstacle(const Obstacle& ob) {
    const std::vector<Vec2>& v = ob.ring;
    const xml_node& o = ob.node;
    const double area = v.size() >= 3 ? signed_area(v) : 0;
    if (area > 0) {
      b_.polygon(v, scene_.where(o));
      solids_.push_back(ob);
    } else if (area < 0) {
      containers_.push_back(ob);
    } else {
      b_.warn("flat-obstacle", scene_.where(o) +
                                   ": an obstacle without area (a segment, or points on a line) "
                                   "becomes walls " +
                                   fmt(kWall) + " m thick along its edges, solid from both sides");
      if (std::all_of(v.begin(), v.end(),
                      [&](const Vec2& p) { return p.x == v[0].x && p.y == v[0].y; }))
        scene_.fail(o, "an obstacle whose vertices all coincide");
      for (std::size_t k = 0; k + 1 < (v.size() == 2 ? 2 : v.size() + 1); ++k)
        wall(v[k], v[(k + 1) % v.size()], o, true);
    }
  }

  // A wall along a -> b, kWall thick: centred on it, or on its left (Menge's solid side).
  void wall(Vec2 a, Vec2 b, const xml_node& o, bool centred) {
    const double dx = b.x - a.x, dy = b.y - a.y, len = std::hypot(dx, dy);
    if (!(len > 0)) return;  // a repeated vertex: no edge
    const double nx = -dy / len * kWall, ny = dx / len * kWall;
    const double s0 = centred ? -0.5 : 0, s1 = centred ? 0.5 : 1;
    b_.polygon({{a.x + s0 * nx, a.y + s0 * ny},
                {b.x + s0 * nx, b.y + s0 * ny},
                {b.x + s1 * nx, b.y + s1 * ny},
                {a.x + s1 * nx, a.y + s1 * ny}},
               scene_.where(o));
  }

  // -- behaviour ---------------------------------------------------------------------------

  void read_behavior() {
    const xml_node root = bfsm_.root();
    if (XmlFile::local(root) != "BFSM") bfsm_.fail(root, "expected a Menge behaviour (<BFSM>)");
    std::vector<xml_node> transitions;
    for (xml_node c = root.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      const std::string_view n = XmlFile::local(c);
      if (n == "GoalSet") {
        goal_set(c);
      } else if (n == "State") {
        state(c);
      } else if (n == "Transition") {
        transitions.push_back(c);
      } else if (n == "VelModifier") {
        b_.warn("velmod", bfsm_.where(c) + ": velocity modifier '" +
                              clip(c.attribute("type").value()) + "' not supported: dropped");
      } else if (n == "Task") {
        b_.warn("task", bfsm_.where(c) + ": task '" + clip(c.attribute("type").value()) +
                            "' not supported: dropped");
      } else if (n == "EventSystem") {
        b_.warn("events",
                bfsm_.where(c) + ": the event system is not supported: its events are dropped");
      } else {
        bfsm_.fail(c,
                   "unknown element in <BFSM> (Menge rejects it: GoalSet, State, Transition, "
                   "VelModifier, Task, EventSystem)");
      }
    }
    if (states_.empty()) bfsm_.fail(root, "no <State>");
    for (StateDef& s : states_) resolve(s);
    for (const xml_node& t : transitions) transition(t);
  }

  void goal_set(const xml_node& n) {
    const uint64_t id = whole(bfsm_, n, "id");
    auto it = set_index_.find(id);
    if (it != set_index_.end()) {
      b_.warn("goalset-merge", bfsm_.where(n) + ": a second goal set with id " +
                                   std::to_string(id) + ": merged into the first (as Menge does)");
    } else {
      it = set_index_.emplace(id, sets_.size()).first;
      sets_.push_back({id, n, {}, {}});
    }
    for (xml_node g = n.first_child(); g; g = g.next_sibling()) {
      if (g.type() != pugi::node_element) continue;
      if (XmlFile::local(g) != "Goal") {
        b_.warn("goalset-child", bfsm_.where(g) + ": not a <Goal>: ignored (as Menge does)");
        continue;
      }
      GoalDef d = goal(g);
      GoalSetDef& set = sets_[it->second];
      if (!set.index.emplace(d.id, set.goals.size()).second)
        bfsm_.fail(g, "goal set " + std::to_string(id) + " already has a goal with id " +
                          std::to_string(d.id));
      set.goals.push_back(d);
    }
  }

  Shape shape(const xml_node& g, std::string kind) {
    Shape s;
    auto num = [&](const char* k) { return bfsm_.attr_number(g, k); };
    std::transform(kind.begin(), kind.end(), kind.begin(),
                   [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
    if (kind == "point") {
      s.p = {num("x"), num("y")};
    } else if (kind == "circle") {
      s.kind = Shape::Kind::circle;
      s.p = {num("x"), num("y")};
      s.r = num("radius");
      if (!(s.r > 0)) bfsm_.fail(g, "attribute 'radius': must be > 0");
    } else if (kind == "aabb") {
      s.kind = Shape::Kind::aabb;
      const double x0 = num("min_x"), y0 = num("min_y"), x1 = num("max_x"), y1 = num("max_y");
      if (x0 > x1 || y0 > y1)
        bfsm_.fail(g, std::string("min > max in ") + (x0 > x1 ? "x" : "y") +
                          " (Menge asserts min <= max)");
      if (x0 == x1 || y0 == y1) bfsm_.fail(g, "the box has no area (min = max)");
      s.p = {x0, y0};
      s.w = x1 - x0;
      s.h = y1 - y0;
    } else if (kind == "obb") {
      s.kind = Shape::Kind::obb;
      s.p = {num("x"), num("y")};
      s.w = num("width");
      s.h = num("height");
      if (!(s.w > 0 && s.h > 0)) bfsm_.fail(g, "width and height must be > 0");
      const double t = num("angle") * std::numbers::pi / 180;
      s.c = std::cos(t);
      s.s = std::sin(t);
    } else {
      return s;  // the caller names the unknown type
    }
    return s;
  }

  GoalDef goal(const xml_node& g) {
    GoalDef d;
    d.node = g;
    const std::string t = type_of(bfsm_, g);
    d.id = whole(bfsm_, g, "id");
    d.capacity = whole(bfsm_, g, "capacity", kAllGoals);
    if (const auto w = bfsm_.attr_number_opt(g, "weight")) {
      if (*w < 0) bfsm_.fail(g, "attribute 'weight': must be >= 0");
      d.weight = *w;
    }
    if (t == "point" || t == "circle" || t == "AABB" || t == "OBB") {
      d.shape = shape(g, t);
    } else if (t == "path") {
      const std::string sh = bfsm_.attr_string(g, "shape");
      std::string low = sh;
      for (char& ch : low) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      if (low != "point" && low != "circle" && low != "aabb" && low != "obb")
        bfsm_.fail(
            g, "attribute 'shape': unknown shape '" + clip(sh) + "' (point, circle, aabb, obb)");
      d.shape = shape(g, low);
      std::vector<Vec2> pts;
      for (const xml_node& p : XmlFile::children(g, "Point"))
        pts.push_back({bfsm_.attr_number(p, "x"), bfsm_.attr_number(p, "y")});
      if (pts.size() < 2) bfsm_.fail(g, "a path goal needs at least 2 <Point> elements");
      d.shape.p.x += pts[0].x;
      d.shape.p.y += pts[0].y;
      b_.warn("path-goal", bfsm_.where(g) +
                               ": moving (path) goals are not supported: the goal "
                               "stays at its path's first point");
    } else {
      bfsm_.fail(g, "unknown goal type '" + clip(t) + "' (point, circle, AABB, OBB, path)");
    }
    return d;
  }

  void state(const xml_node& n) {
    StateDef s;
    s.node = n;
    s.name = bfsm_.attr_string(n, "name");
    if (s.name.empty()) bfsm_.fail(n, "attribute 'name' is empty");
    if (state_index_.count(s.name))
      bfsm_.fail(n, "a second state named '" + clip(s.name) + "' (names are unique)");
    if (!n.attribute("final"))
      bfsm_.fail(n, "missing attribute 'final' (0 or 1: Menge requires it)");
    s.final = flag(bfsm_, b_, n, "final", false);
    bool vel = false;
    for (xml_node c = n.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      const std::string_view cn = XmlFile::local(c);
      if (cn == "GoalSelector") {
        if (s.sel.node)
          b_.warn("selector-repeat", bfsm_.where(c) +
                                         ": a second goal selector in the state: it replaces "
                                         "the first (as in Menge)");
        s.sel = selector(c);
      } else if (cn == "VelComponent") {
        if (vel) bfsm_.fail(c, "a second velocity component in the state (Menge allows one)");
        vel = true;
        s.motion = velocity(c);
      } else if (cn == "Action") {
        const std::string t = type_of(bfsm_, c);
        b_.warn("action:" + t, bfsm_.where(c) + ": action '" + clip(t) +
                                   "' not supported: dropped (its effect on the agent is lost)");
      } else if (cn == "VelModifier") {
        b_.warn("velmod", bfsm_.where(c) + ": velocity modifier '" +
                              clip(c.attribute("type").value()) + "' not supported: dropped");
      } else {
        bfsm_.fail(c,
                   "unknown element in a <State> (Menge rejects it: GoalSelector, "
                   "VelComponent, Action, VelModifier)");
      }
    }
    state_index_[s.name] = states_.size();
    states_.push_back(std::move(s));
  }

  SelectorDef selector(const xml_node& c) {
    using T = SelectorDef::Type;
    SelectorDef d;
    d.node = c;
    const std::string t = type_of(bfsm_, c);
    d.persistent = flag(bfsm_, b_, c, "persistent", false);
    auto set_id = [&] { d.set_id = whole(bfsm_, c, "goal_set"); };
    if (t == "identity") {
      d.type = T::identity;
    } else if (t == "explicit") {
      d.type = T::explicit_;
      set_id();
      d.goal_id = whole(bfsm_, c, "goal");
    } else if (t == "mirror") {
      d.type = T::mirror;
      d.mirror_x = flag(bfsm_, b_, c, "mirror_x", false);
      d.mirror_y = flag(bfsm_, b_, c, "mirror_y", false);
    } else if (t == "offset") {
      d.type = T::offset;
      const std::string dist = bfsm_.attr_string(c, "dist");
      if (dist == "u") {
        d.off_x = {Dist::Kind::u, bfsm_.attr_number(c, "min_x"), bfsm_.attr_number(c, "max_x"), c};
        d.off_y = {Dist::Kind::u, bfsm_.attr_number(c, "min_y"), bfsm_.attr_number(c, "max_y"), c};
      } else if (dist == "c") {
        d.off_x = Dist::constant(bfsm_.attr_number(c, "x_value"), c);
        d.off_y = Dist::constant(bfsm_.attr_number(c, "y_value"), c);
      } else {
        bfsm_.fail(c, "attribute 'dist': unknown 2-D distribution '" + clip(dist) +
                          "' (u or c; Menge has no 2-D normal either)");
      }
    } else if (t == "nearest" || t == "farthest" || t == "random" || t == "weighted") {
      d.type = t == "nearest"    ? T::nearest
               : t == "farthest" ? T::farthest
               : t == "random"   ? T::random
                                 : T::weighted;
      set_id();
    } else if (t == "nearest_nav_mesh" || t == "farthest_nav_mesh") {
      d.type = t == "nearest_nav_mesh" ? T::nearest : T::farthest;
      set_id();
      b_.warn("gsel-navmesh", bfsm_.where(c) + ": goal selector '" + t +
                                  "' measures path lengths on a nav mesh: read as '" +
                                  (d.type == T::nearest ? "nearest" : "farthest") +
                                  "' (straight-line distance to the goal's centre)");
    } else if (t == "shared") {
      d.type = T::shared;
      d.shared_name = bfsm_.attr_string(c, "state_name");
    } else {
      bfsm_.fail(c, "unknown goal selector type '" + clip(t) +
                        "' (identity, explicit, mirror, offset, nearest, farthest, random, "
                        "weighted, shared, nearest_nav_mesh, farthest_nav_mesh)");
    }
    return d;
  }

  Motion velocity(const xml_node& c) {
    const std::string t = type_of(bfsm_, c);
    if (t == "goal") return Motion::walk;
    if (t == "zero") return Motion::stand;
    if (t == "road_map" || t == "nav_mesh" || t == "vel_field") {
      b_.warn("navigation", bfsm_.where(c) + ": velocity component '" + t + "' (file " +
                                clip(c.attribute("file_name").value()) +
                                ") is not read: crowddb's navigation plans its own paths to the "
                                "goal");
      return Motion::navigate;
    }
    if (t == "const" || t == "const_dir") {
      b_.warn("const-vel", bfsm_.where(c) + ": velocity component '" + t +
                               "' (a fixed velocity, no goal) is not supported: the agent walks "
                               "to the state's goal instead");
      return Motion::walk;
    }
    bfsm_.fail(c, "unknown velocity component type '" + clip(t) +
                      "' (goal, zero, const, const_dir, road_map, nav_mesh, vel_field)");
  }

  void resolve(StateDef& s) {
    SelectorDef& d = s.sel;
    using T = SelectorDef::Type;
    if (d.type == T::identity || d.type == T::mirror || d.type == T::offset) return;
    if (d.type == T::shared) {
      const auto it = state_index_.find(d.shared_name);
      if (it == state_index_.end())
        bfsm_.fail(d.node, "attribute 'state_name': unknown state '" + clip(d.shared_name) + "'");
      if (states_[it->second].sel.type == T::shared)
        bfsm_.fail(d.node, "shares the goal of state '" + clip(d.shared_name) +
                               "', which shares another's (Menge requires a full selector there)");
      d.shared_state = it->second;
      states_[it->second].sel.persistent = true;  // Menge makes a shared selector persistent
      return;
    }
    const auto it = set_index_.find(d.set_id);
    if (it == set_index_.end())
      bfsm_.fail(d.node, "attribute 'goal_set': no goal set with id " + std::to_string(d.set_id));
    d.set = it->second;
    if (d.type != T::explicit_) return;
    const auto& index = sets_[d.set].index;
    const auto g = index.find(d.goal_id);
    if (g == index.end())
      bfsm_.fail(d.node, "attribute 'goal': goal set " + std::to_string(d.set_id) +
                             " has no goal with id " + std::to_string(d.goal_id));
    d.goal = g->second;
  }

  std::size_t state_named(const XmlFile& f, const xml_node& n, const std::string& name,
                          const char* what) {
    const auto it = state_index_.find(name);
    if (it == state_index_.end())
      f.fail(n, std::string(what) + ": unknown state '" + clip(name) + "'" +
                    (!name.empty() && (std::isspace(static_cast<unsigned char>(name.front())) ||
                                       std::isspace(static_cast<unsigned char>(name.back())))
                         ? " (names are not trimmed: no spaces after the commas)"
                         : ""));
    return it->second;
  }

  // A float distribution given by attributes with `prefix`: dist="c" value, "u" min max, "n"
  // mean stddev (Menge's FloatGenerator; generator noise uses "displace_", timers none).
  Dist read_dist(const XmlFile& f, const xml_node& n, const std::string& prefix) {
    const auto key = [&](const char* name) { return prefix + name; };
    if (n.attribute(key("seed").c_str()))
      b_.warn("seed", f.where(n) +
                          ": seed attributes are ignored: every draw comes from the "
                          "project's random seed");
    const std::string t = f.attr_string(n, key("dist").c_str());
    Dist d;
    d.node = n;
    if (t == "c") {
      d.a = f.attr_number(n, key("value").c_str());
    } else if (t == "u") {
      d.kind = Dist::Kind::u;
      d.a = f.attr_number(n, key("min").c_str());
      d.b = f.attr_number(n, key("max").c_str());
    } else if (t == "n") {
      d.kind = Dist::Kind::n;
      d.a = f.attr_number(n, key("mean").c_str());
      d.b = f.attr_number(n, key("stddev").c_str());
      if (d.b < 0) f.fail(n, "attribute '" + key("stddev") + "': must be >= 0");
    } else {
      f.fail(n,
             "attribute '" + key("dist") + "': unknown distribution '" + clip(t) + "' (c, u or n)");
    }
    return d;
  }

  // Menge's TimerCondition: the agent leaves its state once a duration drawn on entry has
  // passed (per_agent="1": drawn per agent and entry; "0": one value drawn at load for all). It
  // becomes the wait of a goal where the agent stands (docs/importers/menge.md, "Behaviour").
  void timer(TransitionDef& t, const xml_node& cond) {
    const pugi::xml_attribute per = cond.attribute("per_agent");
    if (!per) bfsm_.fail(cond, "missing attribute 'per_agent' (Menge requires it on a timer)");
    const bool per_agent = flag(bfsm_, b_, cond, "per_agent", true);
    Dist d = read_dist(bfsm_, cond, "");
    if (d.kind == Dist::Kind::u && d.a > d.b) std::swap(d.a, d.b);
    if (!per_agent) {  // one value for everyone, as Menge's loader draws it
      Rng once = Rng::stream(seed(), kTimerStream - timers_++);
      d = Dist::constant(d.sample(once, false), cond);
    }
    double lo = d.a, hi = d.a;
    if (d.kind == Dist::Kind::u) {
      hi = d.b;
    } else if (d.kind == Dist::Kind::n) {
      // crowddb's waits are uniform or exponential: the uniform of the same mean and spread.
      lo = d.a - std::sqrt(3.0) * d.b;
      hi = d.a + std::sqrt(3.0) * d.b;
      b_.warn("timer-normal",
              bfsm_.where(cond) + ": a normal timer (mean " + fmt(d.a) + " s, stddev " + fmt(d.b) +
                  " s) becomes a wait drawn uniformly in [" + fmt(std::max(lo, 0.0)) + ", " +
                  fmt(std::max(hi, 0.0)) + "] s (the same mean and spread)");
    }
    if (hi > Goal::kMaxWait)
      b_.warn("timer-cap", bfsm_.where(cond) + ": a timer longer than " + fmt(Goal::kMaxWait) +
                               " s is cut to that");
    lo = std::clamp(lo, 0.0, Goal::kMaxWait);  // a negative duration fires at once
    hi = std::clamp(hi, 0.0, Goal::kMaxWait);
    t.least_wait = lo;
    if (hi > 0) t.wait = lo == hi ? nlohmann::json(lo) : nlohmann::json::array({lo, hi});
  }

  void transition(const xml_node& n) {
    TransitionDef t;
    t.node = n;
    const std::string from = bfsm_.attr_string(n, "from");
    bool target = false;
    if (const pugi::xml_attribute to = n.attribute("to")) {
      t.target = static_cast<std::ptrdiff_t>(state_named(bfsm_, n, to.value(), "attribute 'to'"));
      target = true;
    }
    xml_node cond;
    for (xml_node c = n.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      const std::string_view cn = XmlFile::local(c);
      if (cn == "Condition") {
        if (cond)
          b_.warn("cond-repeat", bfsm_.where(c) +
                                     ": a second condition in the transition: it "
                                     "replaces the first (as in Menge)");
        cond = c;
      } else if (cn == "Target") {
        const std::string tt = type_of(bfsm_, c);
        if (tt != "prob" && tt != "return")
          bfsm_.fail(c, "unknown target type '" + clip(tt) + "' (prob, return)");
        target = true;
        t.target = -1;
        t.prob.clear();
        if (tt == "return") {
          b_.warn("target:return",
                  bfsm_.where(c) +
                      ": a 'return' target cannot be compiled into a goal sequence: the "
                      "transition is not followed");
          continue;
        }
        // Menge's ProbTarget: each <State name weight> (weight default 1), drawn in proportion.
        double total = 0;
        for (xml_node e = c.first_child(); e; e = e.next_sibling()) {
          if (e.type() != pugi::node_element) continue;
          if (XmlFile::local(e) != "State")
            bfsm_.fail(e, "unknown element in a prob <Target> (Menge reads <State>)");
          const std::size_t st =
              state_named(bfsm_, e, bfsm_.attr_string(e, "name"), "attribute 'name'");
          const double w = bfsm_.attr_number_opt(e, "weight").value_or(1);
          if (!(w >= 0) || !std::isfinite(w)) bfsm_.fail(e, "attribute 'weight': must be >= 0");
          total += w;
          t.prob.emplace_back(st, w);
        }
        if (!(total > 0))
          bfsm_.fail(c,
                     "a prob target needs a <State> with a weight > 0 (Menge's would have "
                     "nowhere to go)");
        t.target = TransitionDef::kProb;
      } else {
        bfsm_.fail(c, "unknown element in a <Transition> (Menge rejects it: Condition, Target)");
      }
    }
    if (!target) bfsm_.fail(n, "no target: give to=\"State\" or a <Target>");
    if (!cond) bfsm_.fail(n, "missing <Condition> (Menge requires one)");
    t.cond_node = cond;
    const std::string ct = type_of(bfsm_, cond);
    if (ct == "goal_reached") {
      t.cond = TransitionDef::Cond::goal_reached;
      t.distance = bfsm_.attr_number_opt(cond, "distance").value_or(0);
      if (t.distance < 0) bfsm_.fail(cond, "attribute 'distance': must be >= 0");
    } else if (ct == "auto") {
      t.cond = TransitionDef::Cond::always;
    } else if (ct == "timer") {
      t.cond = TransitionDef::Cond::timer;
      timer(t, cond);
    } else if (ct == "AABB" || ct == "circle" || ct == "OBB" || ct == "and" || ct == "or" ||
               ct == "not" || ct == "clear_AABB") {
      b_.warn("cond:" + ct, bfsm_.where(cond) + ": condition '" + ct +
                                "' cannot be evaluated before the run: the transition is not "
                                "followed (the chain takes the goal_reached path, if any)");
    } else {
      bfsm_.fail(cond, "unknown condition type '" + clip(ct) +
                           "' (goal_reached, auto, timer, AABB, circle, OBB, and, or, not)");
    }
    // `from` is a comma-separated list, not trimmed (Menge splits it the same way).
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = from.find(',', start);
      const std::string name =
          from.substr(start, comma == std::string::npos ? comma : comma - start);
      states_[state_named(bfsm_, n, name, "attribute 'from'")].out.push_back(t);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }

  // -- agents ------------------------------------------------------------------------------

  void make_agents() {
    for (const xml_node& n : group_nodes_) {
      Group g = group(n);
      for (const Generator& gen : g.generators) {
        emit(g, gen);
        pending_ -= gen.count;
      }
    }
    if (b_.agent_count() == 0) scene_.fail(scene_.root(), "no agents (Menge needs at least one)");
  }

  Group group(const xml_node& n) {
    Group g;
    g.node = n;
    for (xml_node c = n.first_child(); c; c = c.next_sibling()) {
      if (c.type() != pugi::node_element) continue;
      const std::string_view cn = XmlFile::local(c);
      if (cn == "ProfileSelector" || cn == "StateSelector") {
        xml_node& slot = cn == "ProfileSelector" ? g.profile_sel : g.state_sel;
        if (slot) {
          b_.warn("selector-dup", scene_.where(c) + ": a second <" + std::string(cn) +
                                      "> in the group: ignored (Menge uses the first)");
          continue;
        }
        slot = c;
      } else if (cn != "Generator") {
        b_.warn("group-child", scene_.where(c) +
                                   ": unexpected element in a group: ignored "
                                   "(as Menge does)");
      }
    }
    if (!g.profile_sel) scene_.fail(n, "missing <ProfileSelector>");
    if (!g.state_sel) scene_.fail(n, "missing <StateSelector>");
    profile_selector(g);
    const std::string st = type_of(scene_, g.state_sel);
    if (st != "const")
      scene_.fail(g.state_sel, "unknown state selector type '" + clip(st) + "' (const)");
    const std::string name = scene_.attr_string(g.state_sel, "name");
    const auto it = state_index_.find(name);
    if (it == state_index_.end())
      scene_.fail(g.state_sel, "unknown state '" + clip(name) + "' (the behaviour " +
                                   bfsm_.source() + " has no such <State>)");
    g.state = it->second;
    for (const xml_node& c : XmlFile::children(n, "Generator"))
      g.generators.push_back(generator(c));
    return g;
  }

  void profile_selector(Group& g) {
    const xml_node& n = g.profile_sel;
    const std::string t = type_of(scene_, n);
    auto find = [&](const xml_node& at, const std::string& name) {
      const auto it = profile_index_.find(name);
      if (it == profile_index_.end()) scene_.fail(at, "unknown profile '" + clip(name) + "'");
      return it->second;
    };
    if (t == "const") {
      g.profiles.push_back({find(n, scene_.attr_string(n, "name")), 1});
    } else if (t == "random" || t == "weighted") {
      g.weighted = t == "weighted";
      double total = 0;
      for (const xml_node& p : XmlFile::children(n, "Profile")) {
        const std::size_t i = find(p, scene_.attr_string(p, "name"));
        double w = 1;
        if (g.weighted) {
          w = scene_.attr_number(p, "weight");
          if (w < 0) scene_.fail(p, "attribute 'weight': must be >= 0");
        }
        total += w;
        g.profiles.push_back({i, w});
      }
      if (g.profiles.empty()) scene_.fail(n, "no <Profile name=...> to choose from");
      if (g.weighted && !(total > 0)) scene_.fail(n, "the weights add up to 0");
    } else {
      scene_.fail(n, "unknown profile selector type '" + clip(t) + "' (const, random, weighted)");
    }
  }

  Generator generator(const xml_node& n) {
    Generator g;
    g.node = n;
    const std::string t = type_of(scene_, n);
    auto num = [&](const char* k) { return scene_.attr_number(n, k); };
    auto rotation = [&] {
      const double r = scene_.attr_number_opt(n, "rotation").value_or(0) * std::numbers::pi / 180;
      g.c = std::cos(r);
      g.s = std::sin(r);
    };
    const std::size_t room =
        set_.max_agents - std::min(set_.max_agents, b_.agent_count() + pending_);
    auto too_many = [&](const std::string& count) {
      scene_.fail(n, "would create " + count + " agents: more than " +
                         std::to_string(set_.max_agents) + " in all");
    };
    if (t == "explicit" || t == "nav_mesh_explicit") {
      if (t == "nav_mesh_explicit")
        b_.warn("gen-navmesh", scene_.where(n) +
                                   ": nav_mesh_explicit positions are not projected onto the nav "
                                   "mesh: the given points are used");
      for (xml_node c = n.first_child(); c; c = c.next_sibling()) {
        if (c.type() != pugi::node_element) continue;
        if (XmlFile::local(c) != "Agent") {
          b_.warn("gen-child", scene_.where(c) +
                                   ": unexpected element in a generator: ignored "
                                   "(as Menge does)");
          continue;
        }
        if (g.points.size() >= room) too_many("more than " + std::to_string(room));
        g.points.push_back({{scene_.attr_number(c, "p_x"), scene_.attr_number(c, "p_y")}, c});
      }
      g.count = g.points.size();
    } else if (t == "rect_grid") {
      g.type = Generator::Type::rect;
      g.anchor = {num("anchor_x"), num("anchor_y")};
      g.offset = {num("offset_x"), num("offset_y")};
      const uint64_t nx = whole(scene_, n, "count_x"), ny = whole(scene_, n, "count_y");
      rotation();
      if (nx != 0 && ny > room / nx)
        too_many(fmt(static_cast<double>(nx) * static_cast<double>(ny)));
      g.nx = nx;
      g.count = nx * ny;
    } else if (t == "hex_lattice") {
      g.type = Generator::Type::hex;
      hex(g, n, room);
    } else {
      scene_.fail(n, "unknown generator type '" + clip(t) +
                         "' (explicit, rect_grid, hex_lattice, nav_mesh_explicit)");
    }
    if (n.attribute("displace_dist")) g.noise = noise(n);
    pending_ += g.count;
    return g;
  }

  // HexLatticeGenerator::set, in double precision (Menge: float).
  void hex(Generator& g, const xml_node& n, std::size_t room) {
    const Vec2 anchor{scene_.attr_number(n, "anchor_x"), scene_.attr_number(n, "anchor_y")};
    const std::string align = scene_.attr_string(n, "alignment");
    const std::string dir = scene_.attr_string(n, "row_direction");
    const double density = scene_.attr_number(n, "density");
    const double width = scene_.attr_number(n, "width");
    const uint64_t pop = whole(scene_, n, "population");
    const double rot = scene_.attr_number_opt(n, "rotation").value_or(0) * std::numbers::pi / 180;
    if (align != "center" && align != "left" && align != "right")
      scene_.fail(n, "attribute 'alignment': '" + clip(align) + "' (center, left or right)");
    if (dir != "x" && dir != "y")
      scene_.fail(n, "attribute 'row_direction': '" + clip(dir) + "' (x or y)");
    if (!(density > 0)) scene_.fail(n, "attribute 'density': must be > 0");
    if (!(width >= 0)) scene_.fail(n, "attribute 'width': must be >= 0");
    const double r = 1 / std::sqrt(2 * density * std::sqrt(3.0));
    g.row_dist = r * std::sqrt(3.0);
    g.nbr = 2 * r;
    if (!(g.nbr > 0) || !std::isfinite(g.nbr))
      scene_.fail(n, "attribute 'density': too large (the lattice spacing is 0)");
    auto too_many = [&](double count) {
      scene_.fail(n, "would create " + fmt(count) + " agents: more than " +
                         std::to_string(set_.max_agents) + " in all");
    };
    if (pop > room) too_many(static_cast<double>(pop));
    g.row_x = dir == "x";
    double actual_width;
    if (g.row_x) {
      const double per_row = std::floor(width / g.nbr);
      if (per_row > static_cast<double>(room)) too_many(per_row);
      g.row_pop = std::max<uint64_t>(1, static_cast<uint64_t>(per_row));
      const uint64_t band = 2 * g.row_pop - 1, rows = (pop / band + 1) * 2;
      g.count = band * (rows / 2);
      if (g.count - (g.row_pop - 1) > pop) g.count -= g.row_pop - 1;
      actual_width = static_cast<double>(g.row_pop - 1) * g.nbr;
    } else {
      const double rows_d = std::floor(width / g.row_dist);
      if (rows_d > static_cast<double>(room)) too_many(rows_d);
      const uint64_t rows = std::max<uint64_t>(1, static_cast<uint64_t>(rows_d));
      g.row_pop = pop / rows + 1;
      g.count = rows * g.row_pop;
      actual_width = static_cast<double>(rows - 1) * g.row_dist;
    }
    if (g.count > room) too_many(static_cast<double>(g.count));
    g.c = std::cos(rot);
    g.s = std::sin(rot);
    const double k = align == "center" ? 0.5 : (align == "right" ? 1 : 0);
    g.anchor = {anchor.x - g.c * actual_width * k, anchor.y - g.s * actual_width * k};
  }

  Dist noise(const xml_node& n) { return read_dist(scene_, n, "displace_"); }

  // A sampled value that crowddb requires > 0, named by where it was given.
  double positive(const Dist& d, Rng& rng, const Profile& p, const char* what) {
    const double v = d.sample(rng, false);
    if (!(v > 0))
      scene_.fail(d.node ? d.node : p.node,
                  std::string(what) + " " + fmt(v) + (d.kind == Dist::Kind::c ? "" : " (drawn)") +
                      " for agent " + std::to_string(b_.agent_count()) + ": must be > 0");
    return v;
  }

  void emit(const Group& g, const Generator& gen) {
    for (uint64_t i = 0; i < gen.count; ++i) {
      const std::size_t index = b_.agent_count();
      Rng rng = Rng::stream(seed(), index);
      // Profile (Menge's order: profile, then position, then state).
      std::size_t pi = g.profiles[0].profile;
      if (g.profiles.size() > 1 || g.weighted) {
        if (!g.weighted) {
          pi = g.profiles[rng.below(g.profiles.size())].profile;
        } else {
          double total = 0;
          for (const ProfileChoice& c : g.profiles) total += c.weight;
          const double target = total * rng.uniform();
          double acc = 0;
          for (const ProfileChoice& c : g.profiles) {
            pi = c.profile;
            acc += c.weight;
            if (acc > target) break;
          }
        }
      }
      Profile& p = profiles_[pi];
      p.used = true;
      const double tau = orca_ ? positive(p.tau, rng, p, "tau") : 0;
      const double tau_obst = orca_ ? positive(p.tau_obst, rng, p, "tauObst") : 0;
      double max_speed = positive(p.max_speed, rng, p, "max_speed");
      // pref_speed 0 is legal in Menge (an agent waiting for an event to set it going): such an
      // agent stands in every state; crowddb's agents need a speed > 0, it gets max_speed.
      double pref = p.pref_speed.sample(rng, false);
      const bool frozen = pref == 0;
      if (frozen) {
        b_.warn("pref-zero", scene_.where(p.pref_speed.node ? p.pref_speed.node : p.node) +
                                 ": pref_speed 0: these agents stand where they are (transitions "
                                 "that hold there still fire); crowddb gives them pref_speed = "
                                 "max_speed, with nowhere to walk");
        pref = max_speed;
      } else if (!(pref > 0)) {
        scene_.fail(p.pref_speed.node ? p.pref_speed.node : p.node,
                    "pref_speed " + fmt(pref) + " for agent " + std::to_string(b_.agent_count()) +
                        ": must be >= 0");
      }
      double neighbors = p.max_neighbors.sample(rng, true);
      const double ndist = positive(p.neighbor_dist, rng, p, "neighbor_dist");
      const double radius = positive(p.radius, rng, p, "r");
      if (pref > max_speed) {
        b_.warn("speeds", scene_.where(p.node) + ": pref_speed " + fmt(pref) + " > max_speed " +
                              fmt(max_speed) +
                              " (Menge's agents never exceed max_speed): pref_speed lowered to "
                              "max_speed");
        pref = max_speed;
      }
      if (neighbors < 1 || neighbors > 1000) {
        b_.warn("neighbors", scene_.where(p.node) + ": max_neighbors " + fmt(neighbors) +
                                 " is outside crowddb's 1..1000: clamped");
        neighbors = std::clamp(neighbors, 1.0, 1000.0);
      }
      orca_params({tau, tau_obst, ndist, neighbors}, p);
      // Position.
      Vec2 local = gen.type == Generator::Type::explicit_ ? gen.points[i].first : gen.local(i);
      if (gen.noise) {
        const double disp = gen.noise->sample(rng, false);
        const double dir = rng.uniform(0, 2 * std::numbers::pi);
        local.x += std::cos(dir) * disp;
        local.y += std::sin(dir) * disp;
      }
      Vec2 pos = local;
      if (gen.type != Generator::Type::explicit_)
        pos = {gen.anchor.x + gen.c * local.x - gen.s * local.y,
               gen.anchor.y + gen.s * local.x + gen.c * local.y};
      // Behaviour.
      const xml_node& origin =
          gen.type == Generator::Type::explicit_ ? gen.points[i].second : gen.node;
      const std::string where = scene_.where(origin);
      const nlohmann::json goals = compile(g.state, pos, rng, where, !frozen, max_speed);
      nlohmann::json row = {{"x", pos.x},
                            {"y", pos.y},
                            {"radius", radius},
                            {"pref_speed", pref},
                            {"max_speed", max_speed}};
      row["goal"] = goals.size() == 1 ? goals[0] : goals;
      b_.agent(std::move(row), where);
      placed_.push_back({pos, origin});
    }
  }

  uint64_t seed() const { return set_.seed == 0 ? 1 : set_.seed; }

  struct OrcaValues {
    double tau, tau_obst, neighbor_dist, max_neighbors;
    bool operator==(const OrcaValues&) const = default;
  };

  void orca_params(const OrcaValues& v, const Profile& p) {
    if (!orca_) return;
    if (!orca_values_) {
      orca_values_ = v;
    } else if (!(*orca_values_ == v)) {
      b_.warn("orca-params", scene_.where(p.node) +
                                 ": ORCA's tau, tauObst, neighbor_dist and max_neighbors differ "
                                 "between agents (crowddb has one set): the first agent's are "
                                 "used for all");
    }
  }

  // -- the state machine, compiled -----------------------------------------------------------

  std::string origin_of(const StateDef& s) const {
    return bfsm_.where(s.sel.node ? s.sel.node : s.node);
  }

  // The goal the state's selector gives an agent at `pos`.
  // `again`: the agent has gone round a loop of the state machine. Capacities are counted at
  // start-up only (every first assignment held for the whole run); who holds a goal on a later
  // round depends on the run, so those picks ignore them.
  Picked pick(std::size_t si, Vec2 pos, Rng& rng, std::map<std::size_t, Picked>& chosen,
              bool again) {
    using T = SelectorDef::Type;
    StateDef& s = states_[si];
    SelectorDef& d = s.sel;
    if (d.type == T::shared) {
      // Menge shares the selector object and makes it persistent: the agent keeps the goal it
      // got in that state, or gets one from that state's selector now.
      if (const auto it = chosen.find(d.shared_state); it != chosen.end()) return it->second;
      Picked p = pick(d.shared_state, pos, rng, chosen, again);
      chosen[d.shared_state] = p;
      return p;
    }
    Picked p;
    p.origin = origin_of(s);
    switch (d.type) {
      case T::identity:
        p.shape.p = pos;
        return p;
      case T::mirror:
        p.shape.p = {d.mirror_x ? -pos.x : pos.x, d.mirror_y ? -pos.y : pos.y};
        return p;
      case T::offset:
        p.shape.p.x = pos.x + d.off_x.sample(rng, false);
        p.shape.p.y = pos.y + d.off_y.sample(rng, false);
        return p;
      default:
        break;
    }
    GoalSetDef& set = sets_[d.set];
    pick_work_ += set.goals.size();
    GoalDef* chosen_goal = nullptr;
    if (d.type == T::explicit_) {
      chosen_goal = &set.goals[d.goal];
      if (!again && chosen_goal->assigned >= chosen_goal->capacity)
        b_.warn("capacity", bfsm_.where(chosen_goal->node) +
                                ": more agents are sent to this goal than its capacity " +
                                std::to_string(chosen_goal->capacity) +
                                " (counting every assignment as held for the whole run): the "
                                "capacity is not enforced");
    } else {
      std::vector<GoalDef*> avail;
      for (GoalDef& g : set.goals)
        if (again || g.assigned < g.capacity) avail.push_back(&g);
      if (avail.empty()) {
        if (set.goals.empty())
          bfsm_.fail(d.node, "goal set " + std::to_string(set.id) + " has no goals");
        b_.warn("capacity-full", bfsm_.where(d.node) + ": every goal of set " +
                                     std::to_string(set.id) +
                                     " is at capacity (counting every assignment as held for "
                                     "the whole run): capacities are ignored from here on");
        for (GoalDef& g : set.goals) avail.push_back(&g);
      }
      if (d.type == T::nearest || d.type == T::farthest) {
        chosen_goal = avail[0];
        double best = sq(chosen_goal->shape.centroid(), pos);
        for (std::size_t k = 1; k < avail.size(); ++k) {
          const double dd = sq(avail[k]->shape.centroid(), pos);
          if (d.type == T::nearest ? dd < best : dd > best) {
            best = dd;
            chosen_goal = avail[k];
          }
        }
      } else if (d.type == T::random) {
        chosen_goal = avail[rng.below(avail.size())];
      } else {  // weighted: GoalSet::getRandomWeightedGoal
        double total = 0;
        for (const GoalDef* g : avail) total += g->weight;
        const double target = total * rng.uniform();
        chosen_goal = avail[0];
        double acc = chosen_goal->weight;
        for (std::size_t k = 1; k < avail.size() && !(acc > target); ++k) {
          chosen_goal = avail[k];
          acc += chosen_goal->weight;
        }
      }
    }
    if (!again) ++chosen_goal->assigned;
    p.shape = chosen_goal->shape;
    p.origin = bfsm_.where(chosen_goal->node);
    return p;
  }

  static double sq(Vec2 a, Vec2 b) { return (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y); }

  // Menge's goal_reached region for distance d, as a crowddb goal.
  // `wait`: the goal's wait (a timer of the state the agent stands in once there).
  std::string reach_goal(const Picked& g, double d, const xml_node& cond,
                         const nlohmann::json& wait = nullptr) {
    const Shape& s = g.shape;
    switch (s.kind) {
      case Shape::Kind::point:
        if (d < kMinReach) {
          b_.warn("reach-min",
                  bfsm_.where(cond) + ": goal_reached distance " + fmt(d) + " m to a point goal " +
                      (d == 0 ? "never fires in Menge (its agents stop about 0.01 m short)"
                              : "is tighter than crowddb's arrival") +
                      ": the goal is a disc of " + fmt(kMinReach) + " m");
          d = kMinReach;
        }
        return b_.disc_goal(s.p, d, g.origin, wait);
      case Shape::Kind::circle:
        return b_.disc_goal(s.p, s.r + d, g.origin, wait);  // Menge measures to the perimeter
      case Shape::Kind::aabb:
      case Shape::Kind::obb:
        return b_.area_goal(s.box(d), g.origin, wait);
    }
    return {};
  }

  // The goal an agent walks to and stays at (no transition moves it on).
  std::string end_goal(const Picked& g) {
    const Shape& s = g.shape;
    if (s.kind == Shape::Kind::point) return b_.disc_goal(s.p, kMinReach, g.origin);
    if (s.kind == Shape::Kind::circle) return b_.disc_goal(s.p, s.r, g.origin);
    return b_.area_goal(s.box(0), g.origin);
  }

  // The agent's goal sequence; `agent` names it (a goal where it stands is named by it).
  // `walks`: false for an agent with pref_speed 0 (it stands in every state). `max_speed` bounds
  // how soon it can get anywhere: a machine that loops is followed round until the project's
  // duration has passed even at that speed, with every timer at its shortest.
  nlohmann::json compile(std::size_t start, Vec2 pos, Rng& rng, const std::string& agent,
                         bool walks, double max_speed) {
    nlohmann::json seq = nlohmann::json::array();
    std::vector<char> visited(states_.size(), 0);
    std::map<std::size_t, Picked> chosen;
    bool final = false;
    std::size_t si = start;
    double least_time = 0;  // [s] the least time the sequence so far can take
    std::size_t idle = 0;   // transitions since the sequence last grew
    bool again = false;     // gone round a loop
    // The goal reached last and its reach distance (a timer's wait is spent there); `pending`:
    // reached, but not yet in `seq`, so that the wait of a timer right after joins it.
    struct Reach {
      Picked g;
      double d;
      xml_node cond;
    };
    std::optional<Reach> here, pending;
    auto put = [&](nlohmann::json goal) {
      seq.push_back(std::move(goal));
      ++visits_;
      idle = 0;
    };
    auto flush = [&] {
      if (pending) put(reach_goal(pending->g, pending->d, pending->cond));
      pending.reset();
    };
    // Room for another goal? The first round is bounded by the states; the rounds of a loop
    // by the caps.
    auto room = [&] {
      if (!again ||
          (seq.size() < kMaxVisits && visits_ < kMaxVisitsInAll && pick_work_ < kMaxPickWork))
        return true;
      b_.warn("visits", bfsm_.where(states_[si].node) + ": a loop's goal sequence is cut at " +
                            std::to_string(kMaxVisits) + " goals (in all the sequences at " +
                            std::to_string(kMaxVisitsInAll) + " goals, or " +
                            std::to_string(kMaxPickWork) +
                            " goals looked at by the selectors): the agent stands after its "
                            "last one");
      return false;
    };
    auto stand = [&] {
      flush();
      if (seq.empty()) seq.push_back(b_.disc_goal(pos, kMinReach, agent));
    };
    // Moves the agent on along `t` (its target drawn if it is a prob target); false: the
    // sequence ends here.
    auto follow = [&](const TransitionDef& t) {
      std::size_t to = 0;
      if (t.target >= 0) {
        to = static_cast<std::size_t>(t.target);
      } else {  // Menge's ProbTarget: the first state whose running weight exceeds the draw
        double total = 0;
        for (const auto& [st, w] : t.prob) total += w;
        const double draw = total * rng.uniform();
        double acc = 0;
        for (const auto& [st, w] : t.prob) {
          to = st;
          acc += w;
          if (acc > draw) break;
        }
      }
      if (visited[to]) {
        if (!(set_.duration > 0)) {
          b_.warn("cycle", bfsm_.where(t.node) +
                               ": the state machine loops back to a state the agent has been "
                               "in, and the project has no duration: the goal sequence ends "
                               "before the loop");
          return false;
        }
        if (!unrolled_said_) {
          unrolled_said_ = true;
          b_.warn("cycle-unrolled",
                  bfsm_.where(t.node) +
                      ": the state machine loops back to a state the agent has been in: each "
                      "agent's goal sequence follows it round (random goals and prob targets "
                      "drawn again on every round) until the project's duration (" +
                      fmt(set_.duration) + " s) has passed at the least");
        }
        if (least_time > set_.duration) return false;
        again = true;
      }
      if (++idle > 2 * states_.size() + 2) {  // round and round without walking or waiting
        b_.warn("cycle", bfsm_.where(t.node) +
                             ": the state machine loops without a walk or a wait: the goal "
                             "sequence ends there");
        return false;
      }
      si = to;
      return true;
    };
    while (true) {
      visited[si] = 1;
      const StateDef& s = states_[si];
      const Motion motion = walks ? s.motion : Motion::stand;
      const auto kept = chosen.find(si);
      const Picked g = s.sel.persistent && kept != chosen.end() ? kept->second
                                                                : pick(si, pos, rng, chosen, again);
      chosen[si] = g;
      if (s.final) {
        if (motion != Motion::stand && g.shape.sqdist(pos) > 0)
          b_.warn("final-walk", bfsm_.where(s.node) +
                                    ": a final state's agents stand where they enter it (crowddb's "
                                    "arrival); Menge's walk to its goal until every agent is final "
                                    "is dropped");
        stand();
        final = true;
        break;
      }
      // A transition that holds on entry fires at once (Menge tests them before moving).
      const TransitionDef* now = nullptr;
      for (const TransitionDef& t : s.out) {
        if (!t.followable()) continue;
        if (t.cond == TransitionDef::Cond::always ||
            (t.cond == TransitionDef::Cond::goal_reached &&
             g.shape.sqdist(pos) <= t.distance * t.distance)) {
          now = &t;
          break;
        }
      }
      if (now) {
        if (!follow(*now)) {
          stand();
          break;
        }
        continue;
      }
      const TransitionDef* timer = nullptr;
      for (const TransitionDef& t : s.out)
        if (t.followable() && t.cond == TransitionDef::Cond::timer) {
          timer = &t;
          break;
        }
      if (motion == Motion::stand || !(g.shape.sqdist(pos) > 0)) {
        // Nothing moves the agent: it stands in this state until a timer takes it on.
        if (!timer) {
          stand();
          break;
        }
        if (!timer->wait.is_null()) {
          // The wait is spent where the agent stands: the goal it has just reached (the wait
          // joins it), the one it reached before, or its spot.
          if (pending) {
            put(reach_goal(pending->g, pending->d, pending->cond, timer->wait));
            pending.reset();
          } else if (!room()) {
            break;
          } else {
            put(here ? reach_goal(here->g, here->d, here->cond, timer->wait)
                     : b_.disc_goal(pos, kMinReach, agent, timer->wait));
          }
          least_time += timer->least_wait;
        }
        if (!follow(*timer)) {
          stand();
          break;
        }
        continue;
      }
      if (motion == Motion::navigate) navigate_ = true;
      if (timer)
        b_.warn("timer-walk", bfsm_.where(timer->cond_node) +
                                  ": a timer in a state whose agents walk cannot be compiled (it "
                                  "may fire before the goal is reached): the chain takes the "
                                  "goal_reached path, if any");
      const TransitionDef* next = nullptr;
      for (const TransitionDef& t : s.out)
        if (t.followable() && t.cond == TransitionDef::Cond::goal_reached) {
          next = &t;
          break;
        }
      flush();
      if (!room()) break;
      if (!next) {
        put(end_goal(g));
        break;
      }
      pending = here = Reach{g, next->distance, next->cond_node};
      idle = 0;
      least_time += std::max(0.0, std::sqrt(g.shape.sqdist(pos)) - next->distance) / max_speed;
      pos = g.shape.centroid();
      if (!follow(*next)) break;
    }
    stand();
    all_final_ &= final;
    return seq;
  }

  // -- the world ---------------------------------------------------------------------------

  void finish_world() {
    // Obstacle sets, now that it is known which profiles' agents exist: a set whose class no
    // agent's obstacleSet mask has is invisible to all of them in Menge (until an action changes
    // a mask), so it is dropped; one that only some agents see is kept for all.
    for (const ObstacleSetDef& set : obstacle_sets_) {
      std::size_t seen = 0, used = 0;
      std::string hidden;
      for (const Profile& p : profiles_) {
        if (!p.used) continue;
        ++used;
        if (p.obstacle_set & set.cls)
          ++seen;
        else if (hidden.empty())
          hidden = "'" + clip(p.name) + "' (obstacleSet " + std::to_string(p.obstacle_set) + ")";
      }
      if (seen == 0) {
        b_.warn("obstacle-hidden", scene_.where(set.node) + ": obstacle class " +
                                       std::to_string(set.cls) +
                                       " is invisible to every agent (their obstacleSet masks "
                                       "exclude it): dropped, as Menge's agents start without it");
        continue;
      }
      if (seen < used)
        b_.warn("obstacle-class", scene_.where(set.node) + ": obstacle class " +
                                      std::to_string(set.cls) +
                                      " is invisible to the agents of "
                                      "profile " +
                                      hidden +
                                      " in Menge: crowddb's agents see "
                                      "every obstacle");
      for (const Obstacle& o : set.obstacles) add_obstacle(o);
    }
    // Menge's agents ignore the edges of a solid block they start in (its edges face outwards);
    // crowddb's reader rejects them. Said here, naming the agent and the block.
    for (const Obstacle& o : solids_) {
      Box box;
      for (const Vec2& v : o.ring) box.add(v.x, v.y);
      for (const auto& [p, node] : placed_)
        if (p.x > box.x0 && p.x < box.x1 && p.y > box.y0 && p.y < box.y1 &&
            point_in_polygon(o.ring, p.x, p.y) && dist2_to_boundary(o.ring, p.x, p.y) > 0)
          scene_.fail(node, "agent at (" + fmt(p.x) + ", " + fmt(p.y) +
                                ") lies inside the obstacle at " + scene_.where(o.node) +
                                " (Menge's agents ignore a block they start in; crowddb's "
                                "agents must start outside)");
    }
    // Clockwise obstacles are containers: solid for the agents inside. The first axis-aligned
    // rectangle that holds everything becomes the world's walled bounds; the others are walls.
    std::optional<Box> bounds;
    for (const Obstacle& c : containers_) {
      if (bounds || !axis_rectangle(c.ring)) continue;
      Box r;
      for (const Vec2& v : c.ring) r.add(v.x, v.y);
      const Box& e = b_.extent();
      if (e.x0 >= r.x0 && e.y0 >= r.y0 && e.x1 <= r.x1 && e.y1 <= r.y1) bounds = r;
    }
    for (const Obstacle& c : containers_) {
      Box r;
      for (const Vec2& v : c.ring) r.add(v.x, v.y);
      if (bounds && r.x0 == bounds->x0 && r.y0 == bounds->y0 && r.x1 == bounds->x1 &&
          r.y1 == bounds->y1 && axis_rectangle(c.ring))
        continue;
      b_.warn("container", scene_.where(c.node) +
                               ": a clockwise obstacle (in Menge a container: solid only for the "
                               "agents inside it) becomes walls " +
                               fmt(kWall) + " m thick outside its edges, solid from both sides");
      for (std::size_t k = 0; k < c.ring.size(); ++k)
        wall(c.ring[k], c.ring[(k + 1) % c.ring.size()], c.node, false);
    }
    nlohmann::json& d = b_.doc();
    const Box& e = b_.extent();
    Box w = bounds ? *bounds : Box{e.x0 - kMargin, e.y0 - kMargin, e.x1 + kMargin, e.y1 + kMargin};
    d["name"] = set_.name;
    d["description"] = "Menge scene " + scene_.source() + " with behaviour " + bfsm_.source() +
                       (set_.origin.empty() ? std::string() : " (project " + set_.origin + ")");
    d["bounds"] = {w.x0, w.y0, w.x1, w.y1};
    d["walls"] = true;
    const double step = set_.time_step > 0 ? set_.time_step : time_step_;
    d["dt"] = step / static_cast<double>(1 + set_.sub_steps);
    d["duration"] = set_.duration;
    d["seed"] = seed();
    // Menge keeps final agents in the world, standing, and stops when every agent is final.
    d["arrival"] = "idle";
    d["stop_when_all_arrived"] = all_final_;
    if (orca_ && orca_values_) {
      d["steering"] = {{"model", "orca"},
                       {"orca",
                        {{"time_horizon", orca_values_->tau},
                         {"time_horizon_obst", orca_values_->tau_obst},
                         {"neighbor_dist", orca_values_->neighbor_dist},
                         {"max_neighbors", static_cast<uint64_t>(orca_values_->max_neighbors)}}}};
    }
    if (navigate_) d["navigation"] = nlohmann::json::object();
  }

  static bool axis_rectangle(const std::vector<Vec2>& r) {
    if (r.size() != 4) return false;
    for (std::size_t k = 0; k < 4; ++k) {
      const Vec2& a = r[k];
      const Vec2& b = r[(k + 1) % 4];
      if ((a.x == b.x) == (a.y == b.y)) return false;  // not exactly one coordinate shared
    }
    return true;
  }

  XmlFile scene_, bfsm_;
  const ProjectSettings& set_;
  DocBuilder b_;
  bool orca_ = true;
  std::string tag_ = "ORCA";
  double time_step_ = kTimeStep;
  std::vector<Profile> profiles_;
  std::map<std::string, std::size_t> profile_index_;
  std::vector<xml_node> group_nodes_;
  std::vector<ObstacleSetDef> obstacle_sets_;
  std::vector<Obstacle> containers_;
  std::vector<Obstacle> solids_;                   // counter-clockwise obstacles added
  std::vector<std::pair<Vec2, xml_node>> placed_;  // every agent's position and element
  std::vector<GoalSetDef> sets_;
  std::map<uint64_t, std::size_t> set_index_;
  std::vector<StateDef> states_;
  std::map<std::string, std::size_t> state_index_;
  std::size_t pending_ = 0;  // agents of the generators read so far, not yet emitted
  std::optional<OrcaValues> orca_values_;
  bool navigate_ = false;
  bool all_final_ = true;
  uint64_t timers_ = 0;         // timers drawn once at load so far
  std::size_t visits_ = 0;      // goals in the sequences compiled so far
  std::size_t pick_work_ = 0;   // goals looked at by the picks so far
  bool unrolled_said_ = false;  // the warning that a loop is followed round was given
};

}  // namespace

Imported import_menge_pair(std::string_view scene_text, const std::string& scene_name,
                           std::string_view behavior_text, const std::string& behavior_name,
                           const ProjectSettings& settings) {
  return MengeReader(scene_text, scene_name, behavior_text, behavior_name, settings).run();
}

namespace {

// A file named by a project or paired with a scene: Error(io) naming who asked for it.
std::string read_named(const std::filesystem::path& file, const std::string& asked_by) {
  try {
    return read_file(file);
  } catch (const Error& e) {
    throw Error(e.kind(), asked_by + ": " + e.what());
  }
}

}  // namespace

Imported import_menge(const std::filesystem::path& path, std::string_view text,
                      const LoadOptions& options) {
  const std::string root = xml_root_name(text);
  if (root == "BFSM")
    throw Error(Error::Kind::usage,
                path.string() +
                    ": a Menge behaviour file (<BFSM>) on its own: load the project "
                    "file, or the scene with this file as its behaviour "
                    "(--behavior " +
                    path.string() + ")");
  ProjectSettings set;
  std::filesystem::path scene = path, behavior = options.behavior;
  std::string scene_text;
  if (root == "Project") {
    const XmlFile f(text, path.string());
    const pugi::xml_node n = f.root();
    set.origin = f.where(n);
    set.name = path.stem().string();
    const std::filesystem::path dir = path.parent_path();
    scene = (dir / f.attr_string(n, "scene")).lexically_normal();
    if (behavior.empty()) behavior = (dir / f.attr_string(n, "behavior")).lexically_normal();
    if (const pugi::xml_attribute m = n.attribute("model")) {
      set.model = m.value();
      set.model_given = true;
    }
    if (const auto d = f.attr_number_opt(n, "duration")) {
      if (*d < 0) f.fail(n, "attribute 'duration': must be >= 0");
      set.duration = *d;
    }
    set.time_step = f.attr_number_opt(n, "timeStep").value_or(-1);
    if (const auto r = f.attr_number_opt(n, "random")) {
      if (!(*r >= 0) || *r != std::floor(*r) || *r > kBigWhole)
        f.fail(n, "attribute 'random': expected a whole number >= 0");
      set.seed = static_cast<uint64_t>(*r);
    }
    set.sub_steps = whole(f, n, "subSteps", 0);
    if (set.sub_steps > 1000000) f.fail(n, "attribute 'subSteps': at most 10^6");
    scene_text = read_named(scene, f.where(n) + ": attribute 'scene'");
    // view, output, scbVersion, dumpPath, outSamples: the viewer's and the trajectory writer's.
  } else if (root == "Experiment") {
    set.name = path.stem().string();
    scene_text = std::string(text);
    if (behavior.empty()) {
      const std::string stem = path.stem().string();
      if (stem.size() < 2 || stem.back() != 'S')
        throw Error(Error::Kind::usage,
                    path.string() +
                        ": a Menge scene needs its behaviour: pass it with "
                        "--behavior, or load the project file (a scene NameS.xml "
                        "pairs with NameB.xml beside it)");
      behavior =
          path.parent_path() / (stem.substr(0, stem.size() - 1) + "B" + path.extension().string());
      std::error_code ec;
      if (!std::filesystem::is_regular_file(behavior, ec))
        throw Error(Error::Kind::io,
                    path.string() + ": no behaviour file beside the scene: " + behavior.string() +
                        " does not exist (pass one with --behavior, or load "
                        "the project file)");
    }
  } else {
    throw Error(Error::Kind::input,
                path.string() + ": not a Menge file (expected <Project>, <Experiment> or <BFSM>)");
  }
  const std::string behavior_text =
      read_named(behavior, root == "Project" && options.behavior.empty()
                               ? set.origin + ": attribute 'behavior'"
                               : scene.string() + ": its behaviour");
  return import_menge_pair(scene_text, scene.string(), behavior_text, behavior.string(), set);
}

}  // namespace crowddb::io
