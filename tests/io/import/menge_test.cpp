// The Menge importer (src/io/import/menge.cpp): placements against numbers worked out by hand from
// Menge's generator algorithms, the state machine compiled into goal sequences, the project and
// pairing rules, the round trip through convert_scenario, and one-line errors naming the file and
// line for every kind of bad input.
#include "io/import/menge.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "crowddb/error.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "io/scenario_doc.hpp"

namespace crowddb {
namespace {

using nlohmann::json;

// A fresh folder per test.
class Dir {
 public:
  Dir() {
    char tmpl[] = "/tmp/crowddb-menge-XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~Dir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const std::filesystem::path p = path_ / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

const std::string kProfile = R"(  <AgentProfile name="p">
    <Common r="0.2" pref_speed="1.3" max_speed="2" max_accel="5" neighbor_dist="5"
            max_neighbors="10" obstacleSet="1" />
    <ORCA tau="3" tauObst="0.15" />
    <Helbing mass="80" />
  </AgentProfile>
)";

// A scene: the common header, one profile, then `body`.
std::string scene(const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<Experiment version=\"2.0\">\n"
         "  <SpatialQuery type=\"kd-tree\" test_visibility=\"0\" />\n"
         "  <Common time_step=\"0.1\" />\n" +
         kProfile + body + "</Experiment>\n";
}

// A group of the profile "p" starting in `state`.
std::string group(const std::string& generators, const std::string& state = "Walk") {
  return "  <AgentGroup>\n    <ProfileSelector type=\"const\" name=\"p\" />\n"
         "    <StateSelector type=\"const\" name=\"" +
         state + "\" />\n" + generators + "  </AgentGroup>\n";
}

std::string agents(std::initializer_list<std::pair<double, double>> ps) {
  std::string s = "    <Generator type=\"explicit\">\n";
  for (auto [x, y] : ps) {
    std::ostringstream os;
    os.precision(17);
    os << "      <Agent p_x=\"" << x << "\" p_y=\"" << y << "\" />\n";
    s += os.str();
  }
  return s + "    </Generator>\n";
}

// A behaviour where every agent stands still in a final state.
const std::string kStand = R"(<BFSM>
  <State name="Walk" final="1" />
</BFSM>
)";

io::Imported pair(const std::string& s, const std::string& b, io::ProjectSettings set = {}) {
  set.model_given = true;
  return io::import_menge_pair(s, "s.xml", b, "b.xml", set);
}

// The error a pair gives (import and the crowddb reader), checked to be one line.
std::string error_of(const std::string& s, const std::string& b, io::ProjectSettings set = {}) {
  try {
    set.model_given = true;
    const io::Imported im = io::import_menge_pair(s, "s.xml", b, "b.xml", set);
    io::parse_document(im.doc.dump(), "s.xml", &im.origins);
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << "not one line: " << what;
    return what;
  }
  return "";
}

// 1-based line of the first line of `text` that contains `needle`.
int line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

// "file:LINE: <element>: " of the line holding `needle`.
std::string at(const std::string& file, const std::string& text, const std::string& needle,
               const std::string& element) {
  return file + ":" + std::to_string(line_of(text, needle)) + ": <" + element + ">";
}

// The goal named `name` of a converted document.
const json& goal(const json& doc, const std::string& name) {
  for (const json& g : doc["goals"])
    if (g["name"] == name) return g;
  ADD_FAILURE() << "no goal " << name;
  static const json none;
  return none;
}

// An agent's goal sequence, as goal objects.
std::vector<json> sequence(const json& doc, std::size_t agent) {
  const json& g = doc["agents"][agent]["goal"];
  std::vector<json> out;
  if (g.is_string()) {
    out.push_back(goal(doc, g));
  } else {
    for (const json& n : g) out.push_back(goal(doc, n));
  }
  return out;
}

void expect_disc(const json& g, double x, double y, double r) {
  EXPECT_NEAR(g.value("x", std::nan("")), x, 1e-12) << g;
  EXPECT_NEAR(g.value("y", std::nan("")), y, 1e-12) << g;
  EXPECT_NEAR(g.value("arrival_radius", std::nan("")), r, 1e-12) << g;
}

void expect_area(const json& g, std::vector<std::pair<double, double>> corners) {
  ASSERT_TRUE(g.contains("area")) << g;
  ASSERT_EQ(g["area"].size(), corners.size()) << g;
  for (std::size_t k = 0; k < corners.size(); ++k) {
    EXPECT_NEAR(g["area"][k][0].get<double>(), corners[k].first, 1e-12) << g << " corner " << k;
    EXPECT_NEAR(g["area"][k][1].get<double>(), corners[k].second, 1e-12) << g << " corner " << k;
  }
}

void expect_at(const json& doc, std::size_t i, double x, double y) {
  EXPECT_NEAR(doc["agents"][i]["x"].get<double>(), x, 1e-9) << "agent " << i;
  EXPECT_NEAR(doc["agents"][i]["y"].get<double>(), y, 1e-9) << "agent " << i;
}

bool has_warning(const std::vector<std::string>& ws, const std::string& prefix,
                 const std::string& part) {
  for (const std::string& w : ws)
    if (w.rfind(prefix, 0) == 0 && w.find(part) != std::string::npos) return true;
  return false;
}

// -- placement -----------------------------------------------------------------------------

TEST(MengePlacement, ExplicitAgentsAtTheirPoints) {
  const io::Imported im = pair(scene(group(agents({{1, 2}, {-3.5, 4}}))), kStand);
  ASSERT_EQ(im.doc["agents"].size(), 2u);
  expect_at(im.doc, 0, 1, 2);
  expect_at(im.doc, 1, -3.5, 4);
  EXPECT_EQ(im.doc["agents"][0]["radius"], 0.2);
  EXPECT_EQ(im.doc["agents"][0]["pref_speed"], 1.3);
  EXPECT_EQ(im.doc["agents"][0]["max_speed"], 2.0);
  EXPECT_FALSE(im.doc["agents"][0].contains("max_accel"));  // orca has no acceleration limit
}

// RectGridGenerator: agent i at anchor + Rot(rotation) (u offset_x, v offset_y), u = i mod
// count_x, v = i div count_x. With rotation 90: (x, y) -> (-y, x), so world = (10 - 2v, 5 + u).
TEST(MengePlacement, RectGridRotated) {
  const std::string gen = R"(    <Generator type="rect_grid" anchor_x="10" anchor_y="5"
        offset_x="1" offset_y="2" count_x="3" count_y="2" rotation="90" />
)";
  const io::Imported im = pair(scene(group(gen)), kStand);
  ASSERT_EQ(im.doc["agents"].size(), 6u);
  expect_at(im.doc, 0, 10, 5);
  expect_at(im.doc, 1, 10, 6);
  expect_at(im.doc, 2, 10, 7);
  expect_at(im.doc, 3, 8, 5);
  expect_at(im.doc, 4, 8, 6);
  expect_at(im.doc, 5, 8, 7);
}

// HexLatticeGenerator with density 2/sqrt(3): r = 1 / sqrt(2 density sqrt(3)) = 0.5, so
// neighbours are 1 m apart and rows sqrt(3)/2 = 0.8660254 m apart.
// Rows along x, width 2.5, population 4: rowPop = floor(2.5 / 1) = 2, a band holds 2 + 1 agents,
// rowCount = (4 div 3 + 1) 2 = 4, total = 3 (4 div 2) = 6, and 6 - (2 - 1) = 5 > 4 so total = 5.
// Left alignment keeps the anchor. Major rows at y = 0 and 2 rowDist, the minor row shifted by R.
TEST(MengePlacement, HexLatticeRowsAlongXLeftAligned) {
  const std::string gen = R"(    <Generator type="hex_lattice" anchor_x="0" anchor_y="0"
        alignment="left" row_direction="x" density="1.1547005383792517" width="2.5"
        population="4" />
)";
  const io::Imported im = pair(scene(group(gen)), kStand);
  const double h = std::sqrt(3.0) / 2;
  ASSERT_EQ(im.doc["agents"].size(), 5u);
  expect_at(im.doc, 0, 0, 0);
  expect_at(im.doc, 1, 1, 0);
  expect_at(im.doc, 2, 0.5, h);
  expect_at(im.doc, 3, 0, 2 * h);
  expect_at(im.doc, 4, 1, 2 * h);
}

// Rows along y (columns along x), width 2, population 3: rowCount = floor(2 / 0.8660254) = 2,
// rowPop = 3 div 2 + 1 = 2, total = 4; actualWidth = (2 - 1) 0.8660254. Right alignment moves
// the anchor (10, 0) back by the whole width: the first column at x = 10 - 0.8660254, the second
// at x = 10, shifted up by R = 0.5.
TEST(MengePlacement, HexLatticeRowsAlongYRightAligned) {
  const std::string gen = R"(    <Generator type="hex_lattice" anchor_x="10" anchor_y="0"
        alignment="right" row_direction="y" density="1.1547005383792517" width="2"
        population="3" />
)";
  const io::Imported im = pair(scene(group(gen)), kStand);
  const double h = std::sqrt(3.0) / 2;
  ASSERT_EQ(im.doc["agents"].size(), 4u);
  expect_at(im.doc, 0, 10 - h, 0);
  expect_at(im.doc, 1, 10 - h, 1);
  expect_at(im.doc, 2, 10, 0.5);
  expect_at(im.doc, 3, 10, 1.5);
}

TEST(MengePlacement, NoiseMovesAgentsWithinItsRange) {
  const std::string gen = R"(    <Generator type="rect_grid" anchor_x="0" anchor_y="0"
        offset_x="2" offset_y="2" count_x="5" count_y="5"
        displace_dist="u" displace_min="0.1" displace_max="0.25" />
)";
  const io::Imported a = pair(scene(group(gen)), kStand);
  const io::Imported b = pair(scene(group(gen)), kStand);
  EXPECT_EQ(a.doc["agents"], b.doc["agents"]);  // seeded: the same every time
  ASSERT_EQ(a.doc["agents"].size(), 25u);
  for (std::size_t i = 0; i < 25; ++i) {
    const double gx = static_cast<double>(i % 5) * 2, gy = static_cast<double>(i / 5) * 2;
    const double d = std::hypot(a.doc["agents"][i]["x"].get<double>() - gx,
                                a.doc["agents"][i]["y"].get<double>() - gy);
    EXPECT_GE(d, 0.1 - 1e-12);
    EXPECT_LE(d, 0.25 + 1e-12);
  }
  io::ProjectSettings other;
  other.seed = 99;
  EXPECT_NE(pair(scene(group(gen)), kStand, other).doc["agents"], a.doc["agents"]);
}

TEST(MengePlacement, ProfilePropertiesAndInheritance) {
  const std::string s = R"(<Experiment version="2.0">
  <SpatialQuery type="kd-tree" />
  <Common time_step="0.05" />
  <AgentProfile name="base">
    <Common r="0.25" pref_speed="1.2" max_speed="1.5" />
  </AgentProfile>
  <AgentProfile name="child" inherits="base">
    <Common r="0.3">
      <Property name="pref_speed" dist="u" min="1.0" max="1.4" />
    </Common>
  </AgentProfile>
  <AgentGroup>
    <ProfileSelector type="const" name="child" />
    <StateSelector type="const" name="Walk" />
    <Generator type="rect_grid" anchor_x="0" anchor_y="0" offset_x="1" offset_y="1"
               count_x="10" count_y="1" />
  </AgentGroup>
</Experiment>
)";
  const io::Imported im = pair(s, kStand);
  EXPECT_EQ(im.doc["dt"], 0.05);
  bool differ = false;
  for (const json& a : im.doc["agents"]) {
    EXPECT_EQ(a["radius"], 0.3);
    EXPECT_EQ(a["max_speed"], 1.5);
    EXPECT_GE(a["pref_speed"].get<double>(), 1.0);
    EXPECT_LT(a["pref_speed"].get<double>(), 1.4);
    differ |= a["pref_speed"] != im.doc["agents"][0]["pref_speed"];
  }
  EXPECT_TRUE(differ);  // sampled per agent
  // Menge's defaults for tau (2.5) and tauObst (0.15) go to steering.orca.
  EXPECT_EQ(im.doc["steering"]["orca"]["time_horizon"], 2.5);
  EXPECT_EQ(im.doc["steering"]["orca"]["time_horizon_obst"], 0.15);
}

TEST(MengePlacement, OrcaParametersGoToSteering) {
  const io::Imported im = pair(scene(group(agents({{0, 0}}))), kStand);
  const json& o = im.doc["steering"]["orca"];
  EXPECT_EQ(im.doc["steering"]["model"], "orca");
  EXPECT_EQ(o["time_horizon"], 3.0);
  EXPECT_EQ(o["time_horizon_obst"], 0.15);
  EXPECT_EQ(o["neighbor_dist"], 5.0);
  EXPECT_EQ(o["max_neighbors"], 10);
}

TEST(MengePlacement, PrefSpeedAboveMaxSpeedIsLowered) {
  const std::string s = R"(<Experiment>
  <SpatialQuery type="kd-tree" />
  <Common time_step="0.1" />
  <AgentProfile name="p"><Common pref_speed="3" max_speed="2" /></AgentProfile>
)" + group(agents({{0, 0}})) +
                        "</Experiment>\n";
  const io::Imported im = pair(s, kStand);
  EXPECT_EQ(im.doc["agents"][0]["pref_speed"], 2.0);
  EXPECT_TRUE(has_warning(im.warnings, "s.xml:4: <AgentProfile>", "pref_speed lowered"));
}

// -- goals and the state machine -----------------------------------------------------------

TEST(MengeGoals, ExplicitChainOfTwoGoals) {
  const std::string b = R"(<BFSM>
  <GoalSet id="0">
    <Goal type="point" id="0" x="5" y="0" />
    <Goal type="point" id="1" x="5" y="5" />
  </GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="0" />
    <VelComponent type="goal" />
  </State>
  <State name="Walk2" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="1" />
    <VelComponent type="goal" />
  </State>
  <State name="Stop" final="1" />
  <Transition from="Walk" to="Walk2"><Condition type="goal_reached" distance="0.5" /></Transition>
  <Transition from="Walk2" to="Stop"><Condition type="goal_reached" distance="0.25" /></Transition>
</BFSM>
)";
  const io::Imported im = pair(scene(group(agents({{0, 0}}))), b);
  const auto seq = sequence(im.doc, 0);
  ASSERT_EQ(seq.size(), 2u);
  expect_disc(seq[0], 5, 0, 0.5);
  expect_disc(seq[1], 5, 5, 0.25);
  EXPECT_EQ(im.doc["arrival"], "idle");
  EXPECT_EQ(im.doc["stop_when_all_arrived"], true);  // every chain ends in a final state
  EXPECT_TRUE(im.warnings.empty()) << im.warnings[0];
}

// Mirror: (x, y) -> (-x, y) with mirror_x only. Identity in the final state: the agent stands.
TEST(MengeGoals, MirrorThenIdentityFinalState) {
  const std::string b = R"(<BFSM>
  <State name="Walk" final="0">
    <GoalSelector type="mirror" mirror_x="1" mirror_y="0" />
    <VelComponent type="goal" />
  </State>
  <State name="Stop" final="1">
    <GoalSelector type="identity" />
    <VelComponent type="goal" />
  </State>
  <Transition from="Walk" to="Stop"><Condition type="goal_reached" distance="0.1" /></Transition>
</BFSM>
)";
  const io::Imported im = pair(scene(group(agents({{3, 2}, {-1, -4}}))), b);
  auto seq = sequence(im.doc, 0);
  ASSERT_EQ(seq.size(), 1u);
  expect_disc(seq[0], -3, 2, 0.1);
  seq = sequence(im.doc, 1);
  ASSERT_EQ(seq.size(), 1u);
  expect_disc(seq[0], 1, -4, 0.1);
  EXPECT_TRUE(im.warnings.empty()) << im.warnings[0];
}

// An agent that starts in a final state stands where it is: a small disc at its position.
TEST(MengeGoals, StartInAnIdentityFinalState) {
  const io::Imported im = pair(scene(group(agents({{2, 3}}))), kStand);
  const auto seq = sequence(im.doc, 0);
  ASSERT_EQ(seq.size(), 1u);
  expect_disc(seq[0], 2, 3, 0.05);
  EXPECT_EQ(im.doc["stop_when_all_arrived"], true);
}

TEST(MengeGoals, NearestAndFarthestByCentroid) {
  const std::string b = R"(<BFSM>
  <GoalSet id="3">
    <Goal type="point" id="0" x="1" y="0" />
    <Goal type="point" id="1" x="10" y="0" />
    <Goal type="AABB" id="2" min_x="-5" min_y="-1" max_x="-3" max_y="1" />
  </GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="nearest" goal_set="3" />
    <VelComponent type="goal" />
  </State>
  <State name="Far" final="0">
    <GoalSelector type="farthest" goal_set="3" />
    <VelComponent type="goal" />
  </State>
  <State name="Stop" final="1" />
  <Transition from="Walk" to="Far"><Condition type="goal_reached" distance="0.2" /></Transition>
  <Transition from="Far" to="Stop"><Condition type="goal_reached" distance="0.2" /></Transition>
</BFSM>
)";
  // Agent 0 at (0, 0): nearest is (1, 0); from there the farthest centroid is (10, 0).
  // Agent 1 at (-3.5, 5): nearest is the box (centroid (-4, 0)); from (-4, 0), (10, 0).
  const io::Imported im = pair(scene(group(agents({{0, 0}, {-3.5, 5}}))), b);
  auto seq = sequence(im.doc, 0);
  ASSERT_EQ(seq.size(), 2u);
  expect_disc(seq[0], 1, 0, 0.2);
  expect_disc(seq[1], 10, 0, 0.2);
  seq = sequence(im.doc, 1);
  ASSERT_EQ(seq.size(), 2u);
  expect_area(seq[0], {{-5.2, -1.2}, {-2.8, -1.2}, {-2.8, 1.2}, {-5.2, 1.2}});
  expect_disc(seq[1], 10, 0, 0.2);
}

// OBB: pivot (1, 1) is the local min corner, width 2 along the rotated x, height 1 along the
// rotated y, angle 90 degrees counter-clockwise: local (x, y) -> (1 - y, 1 + x).
TEST(MengeGoals, OrientedBoxGeometry) {
  const std::string b = R"(<BFSM>
  <GoalSet id="0">
    <Goal type="OBB" id="0" x="1" y="1" width="2" height="1" angle="90" />
  </GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="0" />
    <VelComponent type="goal" />
  </State>
  <State name="Near" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="0" />
    <VelComponent type="goal" />
  </State>
  <State name="Stop" final="1" />
  <Transition from="Walk" to="Stop"><Condition type="goal_reached" /></Transition>
  <Transition from="Near" to="Stop"><Condition type="goal_reached" distance="0.5" /></Transition>
</BFSM>
)";
  const std::string s = scene(group(agents({{5, 5}})) + group(agents({{5, -5}}), "Near"));
  const io::Imported im = pair(s, b);
  // distance 0: the box itself.
  expect_area(sequence(im.doc, 0)[0], {{1, 1}, {1, 3}, {0, 3}, {0, 1}});
  // distance 0.5: the box grown by 0.5 (square corners): local [-0.5, 2.5] x [-0.5, 1.5].
  expect_area(sequence(im.doc, 1)[0], {{1.5, 0.5}, {1.5, 3.5}, {-0.5, 3.5}, {-0.5, 0.5}});
}

// Menge measures a circle goal's distance to its perimeter: reached within R + d of the centre.
TEST(MengeGoals, CircleGoalReachRadius) {
  const std::string b = R"(<BFSM>
  <GoalSet id="0"><Goal type="circle" id="0" x="4" y="0" radius="1" /></GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="0" />
    <VelComponent type="goal" />
  </State>
  <State name="Stop" final="1" />
  <Transition from="Walk" to="Stop"><Condition type="goal_reached" distance="0.2" /></Transition>
</BFSM>
)";
  const io::Imported im = pair(scene(group(agents({{-4, 0}}))), b);
  expect_disc(sequence(im.doc, 0)[0], 4, 0, 1.2);
}

TEST(MengeGoals, PointGoalWithDistanceZeroGetsTheMinimumDisc) {
  const std::string b = R"(<BFSM>
  <GoalSet id="0"><Goal type="point" id="0" x="4" y="0" /></GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="0" />
    <VelComponent type="goal" />
  </State>
  <State name="Stop" final="1" />
  <Transition from="Walk" to="Stop"><Condition type="goal_reached" /></Transition>
</BFSM>
)";
  const io::Imported im = pair(scene(group(agents({{-4, 0}}))), b);
  expect_disc(sequence(im.doc, 0)[0], 4, 0, 0.05);
  EXPECT_TRUE(has_warning(im.warnings, "b.xml:8: <Condition>", "never fires"));
}

// A chain that does not end in a final state runs for the whole duration, as in Menge.
TEST(MengeGoals, NoFinalStateRunsToTheDuration) {
  const std::string b = R"(<BFSM>
  <GoalSet id="0"><Goal type="AABB" id="0" min_x="8" min_y="-1" max_x="10" max_y="1" /></GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="0" />
    <VelComponent type="road_map" file_name="graph.txt" />
  </State>
</BFSM>
)";
  const io::Imported im = pair(scene(group(agents({{0, 0}}))), b);
  expect_area(sequence(im.doc, 0)[0], {{8, -1}, {10, -1}, {10, 1}, {8, 1}});
  EXPECT_EQ(im.doc["stop_when_all_arrived"], false);
  EXPECT_EQ(im.doc["duration"], 400.0);        // Menge's default
  EXPECT_TRUE(im.doc.contains("navigation"));  // road_map: crowddb plans the path
  EXPECT_TRUE(has_warning(im.warnings, "b.xml:5: <VelComponent>", "road_map"));
}

TEST(MengeGoals, CapacityIsHonouredAtStartUp) {
  const std::string b = R"(<BFSM>
  <GoalSet id="0">
    <Goal type="point" id="0" x="1" y="0" capacity="1" />
    <Goal type="point" id="1" x="2" y="0" capacity="1" />
  </GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="nearest" goal_set="0" />
    <VelComponent type="goal" />
  </State>
</BFSM>
)";
  const io::Imported im = pair(scene(group(agents({{0, 0}, {0, 1}, {0, 2}}))), b);
  expect_disc(sequence(im.doc, 0)[0], 1, 0, 0.05);
  expect_disc(sequence(im.doc, 1)[0], 2, 0, 0.05);  // the nearest is full
  EXPECT_TRUE(has_warning(im.warnings, "b.xml:7: <GoalSelector>", "at capacity"));
}

TEST(MengeGoals, RandomAndWeightedDrawFromTheSeed) {
  const std::string b = R"(<BFSM>
  <GoalSet id="0">
    <Goal type="point" id="0" x="1" y="0" weight="1" />
    <Goal type="point" id="1" x="2" y="0" weight="0" />
    <Goal type="point" id="2" x="3" y="0" weight="3" />
  </GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="weighted" goal_set="0" />
    <VelComponent type="goal" />
  </State>
  <State name="Rand" final="0">
    <GoalSelector type="random" goal_set="0" />
    <VelComponent type="goal" />
  </State>
</BFSM>
)";
  std::string gens;
  for (int i = 0; i < 40; ++i) gens += agents({{0, static_cast<double>(i)}});
  const std::string s = scene(group(gens) + group(gens, "Rand"));
  const io::Imported im = pair(s, b);
  int counts[2][3] = {};
  for (std::size_t i = 0; i < 80; ++i) {
    const double x = sequence(im.doc, i)[0]["x"].get<double>();
    ++counts[i / 40][static_cast<int>(x) - 1];
  }
  EXPECT_EQ(counts[0][1], 0);  // weight 0 is never drawn
  EXPECT_GT(counts[0][2], counts[0][0]);
  EXPECT_GT(counts[1][0] * counts[1][1] * counts[1][2], 0);
  EXPECT_EQ(pair(s, b).doc, im.doc);
}

// -- files ---------------------------------------------------------------------------------

const std::string kTwoGoals = R"(<BFSM>
  <GoalSet id="0"><Goal type="point" id="0" x="6" y="0" /></GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="0" />
    <VelComponent type="goal" />
  </State>
  <State name="Stop" final="1" />
  <Transition from="Walk" to="Stop"><Condition type="goal_reached" distance="0.3" /></Transition>
</BFSM>
)";

// pref_speed 0 (Menge: an agent waiting for an event): it stands in every state.
TEST(MengeGoals, ZeroPrefSpeedStands) {
  const std::string s = R"(<Experiment>
  <SpatialQuery type="kd-tree" />
  <Common time_step="0.1" />
  <AgentProfile name="p"><Common pref_speed="0" max_speed="2" /></AgentProfile>
)" + group(agents({{1, 1}})) +
                        "</Experiment>\n";
  const io::Imported im = pair(s, kTwoGoals);
  const auto seq = sequence(im.doc, 0);
  ASSERT_EQ(seq.size(), 1u);
  expect_disc(seq[0], 1, 1, 0.05);
  EXPECT_EQ(im.doc["agents"][0]["pref_speed"], 2.0);
  EXPECT_EQ(im.doc["stop_when_all_arrived"], false);  // it never reaches the final state
  EXPECT_TRUE(has_warning(im.warnings, "s.xml:4: <Common>", "pref_speed 0"));
}

TEST(MengeFiles, ProjectNamesSceneBehaviourAndSettings) {
  Dir d;
  d.write("sub/aS.xml", scene(group(agents({{0, 0}, {0, 2}}))));
  d.write("sub/aB.xml", kTwoGoals);
  const auto proj = d.write("proj.xml", R"(<?xml version="1.0"?>
<Project scene="sub/aS.xml" behavior="sub/aB.xml" view="sub/aV.xml" model="orca"
         duration="20" timeStep="0.05" random="7" />
)");
  const Scenario sc = load_scenario(proj);
  EXPECT_EQ(sc.format, "menge");
  EXPECT_EQ(sc.name, "proj");
  EXPECT_EQ(sc.config.dt, 0.05);  // the project's timeStep overrides the scene's
  EXPECT_EQ(sc.ticks, 400u);      // 20 s
  EXPECT_EQ(sc.config.seed, 7u);
  EXPECT_EQ(sc.world.agents().size(), 2u);
  EXPECT_TRUE(sc.stop_when_all_arrived);
  EXPECT_TRUE(sc.config.walls);
}

TEST(MengeFiles, SceneNameSPairsWithNameB) {
  Dir d;
  const auto s = d.write("twoS.xml", scene(group(agents({{0, 0}}))));
  d.write("twoB.xml", kTwoGoals);
  const Scenario sc = load_scenario(s);
  EXPECT_EQ(sc.name, "twoS");
  EXPECT_EQ(sc.world.agents().size(), 1u);
  EXPECT_TRUE(has_warning(sc.warnings, s.string(), "no model named"));
  // Without its behaviour: an error naming both files.
  std::filesystem::remove(d / "twoB.xml");
  try {
    load_scenario(s);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(s.string()), std::string::npos) << what;
    EXPECT_NE(what.find((d / "twoB.xml").string()), std::string::npos) << what;
  }
}

TEST(MengeFiles, BehaviorOption) {
  Dir d;
  const auto s = d.write("scene.xml", scene(group(agents({{0, 0}}))));
  const auto b = d.write("elsewhere/walk.xml", kTwoGoals);
  LoadOptions o;
  o.behavior = b;
  const Scenario sc = load_scenario(s, o);
  EXPECT_EQ(sc.world.goals().size(), 1u);
  // A scene not named NameS.xml needs the option.
  EXPECT_THROW(load_scenario(s), Error);
}

TEST(MengeFiles, BehaviourAloneSaysWhatToPass) {
  Dir d;
  const auto b = d.write("aB.xml", kTwoGoals);
  try {
    load_scenario(b);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("load the project file, or the scene"), std::string::npos)
        << e.what();
  }
}

TEST(MengeFiles, MissingSceneOfAProjectNamesTheProject) {
  Dir d;
  const auto proj =
      d.write("p.xml", "<Project scene=\"none.xml\" behavior=\"b.xml\" model=\"orca\"/>");
  try {
    load_scenario(proj);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(proj.string() + ":1: <Project>: attribute 'scene'", 0),
              0u)
        << e.what();
  }
}

// load_scenario(file) and parse_scenario(convert_scenario(file).json) build the same world.
TEST(MengeFiles, RoundTripThroughConvert) {
  Dir d;
  const std::string s =
      scene(group(R"(    <Generator type="rect_grid" anchor_x="-6" anchor_y="-2" offset_x="0.8"
        offset_y="0.8" count_x="4" count_y="6" displace_dist="u" displace_min="0"
        displace_max="0.1" />
)") +
            R"(  <ObstacleSet type="explicit" class="1">
    <Obstacle closed="1">
      <Vertex p_x="-1" p_y="-1" /><Vertex p_x="1" p_y="-1" />
      <Vertex p_x="1" p_y="1" /><Vertex p_x="-1" p_y="1" />
    </Obstacle>
  </ObstacleSet>
)");
  d.write("rt/rtS.xml", s);
  d.write("rt/rtB.xml", R"(<BFSM>
  <State name="Walk" final="0">
    <GoalSelector type="mirror" mirror_x="1" mirror_y="1" />
    <VelComponent type="goal" />
  </State>
  <State name="Stop" final="1" />
  <Transition from="Walk" to="Stop"><Condition type="goal_reached" distance="0.2" /></Transition>
</BFSM>
)");
  const auto proj = d.write("rt.xml", R"(<Project scene="rt/rtS.xml" behavior="rt/rtB.xml"
    model="orca" random="3"/>)");
  Scenario a = load_scenario(proj);
  const Converted c = convert_scenario(proj);
  EXPECT_EQ(c.format, "menge");
  Scenario b = parse_scenario(c.json, "rt.json");
  ASSERT_EQ(a.world.agents().size(), 24u);
  Simulation sa(std::move(a.world), a.config), sb(std::move(b.world), b.config);
  EXPECT_EQ(sa.state_hash(), sb.state_hash());
  for (int k = 0; k < 50; ++k) {
    sa.step();
    sb.step();
  }
  EXPECT_EQ(sa.state_hash(), sb.state_hash());
}

// -- warnings ------------------------------------------------------------------------------

TEST(MengeWarnings, UnsupportedElementsOneLineEach) {
  const std::string b = R"(<BFSM>
  <GoalSet id="0"><Goal type="point" id="0" x="6" y="0" /></GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="0" />
    <VelComponent type="goal" />
    <Action type="set_property" property="pref_speed" dist="c" value="2" />
    <VelModifier type="scale" scale="0.5" />
  </State>
  <State name="Wait" final="0" />
  <State name="Stop" final="1" />
  <Transition from="Walk" to="Wait"><Condition type="timer" per_agent="0" dist="c" value="3" /></Transition>
  <Transition from="Wait" to="Walk"><Condition type="timer" per_agent="0" dist="c" value="1" /></Transition>
  <Transition from="Walk"><Condition type="goal_reached" distance="0.3" />
    <Target type="prob"><State name="Stop" weight="1" /></Target></Transition>
  <Transition from="Walk" to="Stop"><Condition type="goal_reached" distance="0.4" /></Transition>
  <Task type="whatever" />
  <EventSystem />
</BFSM>
)";
  const io::Imported im = pair(scene(group(agents({{0, 0}}))), b);
  const auto& w = im.warnings;
  EXPECT_TRUE(has_warning(w, "b.xml:6: <Action>", "set_property"));
  EXPECT_TRUE(has_warning(w, "b.xml:7: <VelModifier>", "scale"));
  // A timer where the agent walks may fire on the way: not compiled.
  EXPECT_TRUE(has_warning(w, "b.xml:11: <Condition>", "a timer in a state whose agents walk"));
  EXPECT_TRUE(has_warning(w, "b.xml:16: <Task>", "whatever"));
  EXPECT_TRUE(has_warning(w, "b.xml:17: <EventSystem>", "not supported"));
  for (const std::string& line : w) EXPECT_EQ(line.find('\n'), std::string::npos);
  // The first goal_reached transition is followed, its prob target drawn (one state).
  const auto seq = sequence(im.doc, 0);
  ASSERT_EQ(seq.size(), 1u);
  expect_disc(seq[0], 6, 0, 0.3);
  EXPECT_EQ(im.doc["stop_when_all_arrived"], true);
}

// -- timers, prob targets and loops (Menge's tradeshow) -------------------------------------

// Walk to a random booth; stand there 2-4 s (Arrive); then, drawn 1:1, 4-6 s (Happy) or 1-2 s
// (Angry); then walk to another booth, round and round.
const std::string kBooths = R"(<BFSM>
  <GoalSet id="0">
    <Goal type="AABB" id="0" min_x="10" min_y="0" max_x="11" max_y="1" />
    <Goal type="AABB" id="1" min_x="-11" min_y="0" max_x="-10" max_y="1" />
  </GoalSet>
  <State name="Walk" final="0">
    <GoalSelector type="random" goal_set="0" per_agent="1" />
    <VelComponent type="goal" />
  </State>
  <State name="Arrive" final="0"><VelComponent type="zero" /></State>
  <State name="Decide" final="0"><VelComponent type="zero" /></State>
  <State name="Happy" final="0"><VelComponent type="zero" /></State>
  <State name="Angry" final="0"><VelComponent type="zero" /></State>
  <Transition from="Walk" to="Arrive"><Condition type="goal_reached" distance="0.4" /></Transition>
  <Transition from="Arrive" to="Decide">
    <Condition type="timer" dist="u" min="4" max="2" seed="5" per_agent="1" /></Transition>
  <Transition from="Decide"><Condition type="auto" />
    <Target type="prob"><State name="Happy" weight="1.0" /><State name="Angry" weight="1.0" /></Target>
  </Transition>
  <Transition from="Happy" to="Walk"><Condition type="timer" dist="u" min="4" max="6" per_agent="1" /></Transition>
  <Transition from="Angry" to="Walk"><Condition type="timer" dist="c" value="1.5" per_agent="1" /></Transition>
</BFSM>
)";

TEST(MengeBehaviour, TimersBecomeWaitsAndLoopsAreFollowedRound) {
  io::ProjectSettings set;
  set.duration = 120;
  const io::Imported im = pair(scene(group(agents({{0, 0}, {0, 3}}))), kBooths, set);
  EXPECT_EQ(im.doc["stop_when_all_arrived"], false);
  EXPECT_TRUE(has_warning(im.warnings, "b.xml:", "follows it round"));
  EXPECT_TRUE(has_warning(im.warnings, "b.xml:16: <Condition>", "seed attributes"));
  for (std::size_t a = 0; a < 2; ++a) {
    const auto seq = sequence(im.doc, a);
    // Each visit: the booth reached, with Arrive's wait (min and max in either order), then
    // the booth again with Happy's or Angry's; the sequence may end anywhere in a visit, and
    // the last booth reached without its wait.
    int happy = 0, angry = 0;
    for (std::size_t k = 0; k < seq.size(); ++k) {
      if (!seq[k].contains("wait")) {
        EXPECT_EQ(k + 1, seq.size()) << "only the last goal has no wait";
        continue;
      }
      if (seq[k]["wait"] == json({2.0, 4.0})) {
        if (k + 1 < seq.size() && seq[k + 1].contains("wait")) {
          EXPECT_EQ(seq[k]["area"], seq[k + 1]["area"]) << k;
        }
      } else if (seq[k]["wait"] == json({4.0, 6.0})) {
        ++happy;
      } else {
        EXPECT_EQ(seq[k]["wait"], json(1.5)) << k;
        ++angry;
      }
      if (seq[k]["wait"] != json({2.0, 4.0})) {
        ASSERT_GT(k, 0u);
        EXPECT_EQ(seq[k - 1]["wait"], json({2.0, 4.0})) << k;
      }
    }
    EXPECT_GT(happy, 0);
    EXPECT_GT(angry, 0);
    // Booths 21 m apart at most (max_speed 2 m/s), or the same booth again; every round waits
    // 3.5 s at the least: the sequence lasts past the duration, and not many rounds more.
    EXPECT_GT(seq.size(), 2 * 120 / 16.5);
    EXPECT_LT(seq.size(), 2 * (120 / 3.5 + 2));
  }
  // Drawn from the project's seed: the same again, and not the same agent twice.
  EXPECT_EQ(pair(scene(group(agents({{0, 0}, {0, 3}}))), kBooths, set).doc, im.doc);
  EXPECT_NE(im.doc["agents"][0]["goal"], im.doc["agents"][1]["goal"]);
}

TEST(MengeBehaviour, WithoutADurationTheSequenceEndsBeforeTheLoop) {
  io::ProjectSettings set;
  set.duration = 0;
  const io::Imported im = pair(scene(group(agents({{0, 0}}))), kBooths, set);
  const auto seq = sequence(im.doc, 0);
  ASSERT_EQ(seq.size(), 2u);  // the first booth and its two waits
  EXPECT_EQ(seq[0]["wait"], json({2.0, 4.0}));
  EXPECT_TRUE(has_warning(im.warnings, "b.xml:", "no duration"));
}

TEST(MengeBehaviour, SharedTimerDrawnOnceAndZeroTimeLoopsEnd) {
  // per_agent="0": one duration for everyone. Stand 0-10 s at the start (no goal reached: the
  // agent's spot), then Ping and Pong hand over at once for ever.
  const std::string b = R"(<BFSM>
  <State name="Start" final="0"><VelComponent type="zero" /></State>
  <State name="Ping" final="0"><VelComponent type="zero" /></State>
  <State name="Pong" final="0"><VelComponent type="zero" /></State>
  <Transition from="Start" to="Ping"><Condition type="timer" dist="u" min="0" max="10" per_agent="0" /></Transition>
  <Transition from="Ping" to="Pong"><Condition type="auto" /></Transition>
  <Transition from="Pong" to="Ping"><Condition type="auto" /></Transition>
</BFSM>
)";
  const io::Imported im = pair(scene(group(agents({{0, 0}, {3, 0}, {6, 0}}), "Start")), b);
  double wait = -1;
  for (std::size_t a = 0; a < 3; ++a) {
    const auto seq = sequence(im.doc, a);
    ASSERT_EQ(seq.size(), 1u);
    expect_disc(seq[0], 3.0 * static_cast<double>(a), 0, 0.05);
    ASSERT_TRUE(seq[0]["wait"].is_number()) << seq[0];
    if (a == 0) wait = seq[0]["wait"].get<double>();
    EXPECT_EQ(seq[0]["wait"].get<double>(), wait);
  }
  EXPECT_GT(wait, 0);
  EXPECT_LT(wait, 10);
  EXPECT_TRUE(has_warning(im.warnings, "b.xml:", "loops without a walk or a wait"));
}

TEST(MengeBehaviour, NormalTimersAndBadTimers) {
  const std::string b = R"(<BFSM>
  <State name="Start" final="0"><VelComponent type="zero" /></State>
  <State name="Stop" final="1" />
  <Transition from="Start" to="Stop"><Condition type="timer" dist="n" mean="5" stddev="1" per_agent="1" /></Transition>
</BFSM>
)";
  const io::Imported im = pair(scene(group(agents({{0, 0}}), "Start")), b);
  const auto seq = sequence(im.doc, 0);
  ASSERT_EQ(seq.size(), 1u);
  EXPECT_NEAR(seq[0]["wait"][0].get<double>(), 5 - std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(seq[0]["wait"][1].get<double>(), 5 + std::sqrt(3.0), 1e-12);
  EXPECT_TRUE(has_warning(im.warnings, "b.xml:4: <Condition>", "same mean and spread"));
  EXPECT_EQ(im.doc["stop_when_all_arrived"], true);
  std::string bad = b;
  bad.replace(bad.find(" per_agent=\"1\""), 14, "");
  EXPECT_NE(error_of(scene(group(agents({{0, 0}}), "Start")), bad).find("'per_agent'"),
            std::string::npos);
  bad = b;
  bad.replace(bad.find("dist=\"n\""), 8, "dist=\"w\"");
  EXPECT_NE(error_of(scene(group(agents({{0, 0}}), "Start")), bad).find("unknown distribution"),
            std::string::npos);
  const std::string prob = R"(<BFSM>
  <State name="Start" final="0"><VelComponent type="zero" /></State>
  <State name="Stop" final="1" />
  <Transition from="Start"><Condition type="auto" />
    <Target type="prob"><State name="Stop" weight="0" /></Target></Transition>
</BFSM>
)";
  EXPECT_NE(error_of(scene(group(agents({{0, 0}}), "Start")), prob).find("weight > 0"),
            std::string::npos);
}

// A loop whose walks take hardly any time (0.05 m beyond the reach each) is cut at 1,000 goals.
TEST(MengeBehaviour, LoopsWithoutTimeAreCut) {
  const std::string b = R"(<BFSM>
  <GoalSet id="0">
    <Goal type="point" id="0" x="1" y="0" />
    <Goal type="point" id="1" x="1" y="0.15" />
  </GoalSet>
  <State name="A" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="0" />
    <VelComponent type="goal" />
  </State>
  <State name="B" final="0">
    <GoalSelector type="explicit" goal_set="0" goal="1" />
    <VelComponent type="goal" />
  </State>
  <Transition from="A" to="B"><Condition type="goal_reached" distance="0.1" /></Transition>
  <Transition from="B" to="A"><Condition type="goal_reached" distance="0.1" /></Transition>
</BFSM>
)";
  const io::Imported im = pair(scene(group(agents({{0, 0}}), "A")), b);
  EXPECT_EQ(im.doc["agents"][0]["goal"].size(), 1000u);
  EXPECT_TRUE(has_warning(im.warnings, "b.xml:", "cut at 1000 goals"));
  EXPECT_NO_THROW(parse_scenario(im.doc.dump(), "loop.json"));
}

// Capacities are counted at start-up; on later rounds of a loop every goal may be picked.
TEST(MengeBehaviour, CapacitiesHoldAtStartUpOnly) {
  const std::string b = R"(<BFSM>
  <GoalSet id="0">
    <Goal type="point" id="0" x="1" y="0" capacity="1" />
    <Goal type="point" id="1" x="2" y="0" capacity="1" />
  </GoalSet>
  <GoalSet id="1"><Goal type="point" id="0" x="0" y="5" /></GoalSet>
  <State name="Box" final="0">
    <GoalSelector type="nearest" goal_set="0" />
    <VelComponent type="goal" />
  </State>
  <State name="Out" final="0">
    <GoalSelector type="explicit" goal_set="1" goal="0" />
    <VelComponent type="goal" />
  </State>
  <Transition from="Box" to="Out"><Condition type="goal_reached" distance="0.1" /></Transition>
  <Transition from="Out" to="Box"><Condition type="goal_reached" distance="0.1" /></Transition>
</BFSM>
)";
  io::ProjectSettings set;
  set.duration = 30;
  const io::Imported im = pair(scene(group(agents({{0, 0}, {0, 1}}), "Box")), b, set);
  const auto first = sequence(im.doc, 0), second = sequence(im.doc, 1);
  ASSERT_GT(first.size(), 4u);
  ASSERT_GT(second.size(), 4u);
  expect_disc(first[0], 1, 0, 0.1);
  expect_disc(second[0], 2, 0, 0.1);  // the nearest is taken at start-up
  expect_disc(second[1], 0, 5, 0.1);
  expect_disc(second[2], 1, 0, 0.1);  // later, the nearest to (0, 5)
  expect_disc(first[2], 1, 0, 0.1);
  EXPECT_FALSE(has_warning(im.warnings, "b.xml:", "capacity")) << im.warnings[0];
}

// A converted tradeshow-like project runs: visitors go from booth to booth and wait there.
TEST(MengeBehaviour, VisitorsGoRoundTheBooths) {
  io::ProjectSettings set;
  set.duration = 60;
  const io::Imported im = pair(scene(group(agents({{0, 0}, {0, 3}, {0, -3}}))), kBooths, set);
  Scenario sc = parse_scenario(im.doc.dump(), "booths.json");
  Simulation sim(std::move(sc.world), sc.config);
  int waiting_ticks = 0, walking_after_a_wait = 0;
  bool waited = false;
  for (int k = 0; k < 600; ++k) {
    sim.step();
    const AgentTable& t = sim.world().agents();
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (t.state[i] == AgentState::waiting) {
        ++waiting_ticks;
        waited = true;
      } else if (waited && t.state[i] == AgentState::active) {
        ++walking_after_a_wait;
      }
    }
  }
  EXPECT_GT(waiting_ticks, 3 * 20);  // each at least one 2-4 s wait
  EXPECT_GT(walking_after_a_wait, 0);
  EXPECT_EQ(sim.world().agents().size(), 3u);
}

TEST(MengeWarnings, BooleansReadAsIntegers) {
  const std::string s = R"(<Experiment>
  <SpatialQuery type="kd-tree" test_visibility="true" />
  <Common time_step="0.1" />
  <AgentProfile name="p"><Common r="0.2" /></AgentProfile>
)" + group(agents({{0, 0}})) +
                        "</Experiment>\n";
  // final="true" is not final in Menge: the agent stays in Walk, a non-final state.
  const std::string b = "<BFSM><State name=\"Walk\" final=\"true\" /></BFSM>";
  const io::Imported im = pair(s, b);
  EXPECT_TRUE(has_warning(im.warnings, "s.xml:2: <SpatialQuery>", "read as 0 (false)"));
  EXPECT_TRUE(has_warning(im.warnings, "b.xml:1: <State>", "final=\"true\""));
  EXPECT_EQ(im.doc["stop_when_all_arrived"], false);
}

TEST(MengeWarnings, OtherModelsUseTheDefault) {
  io::ProjectSettings set;
  set.model = "helbing";
  set.origin = "p.xml:1: <Project>";
  const io::Imported im = pair(scene(group(agents({{0, 0}}))), kStand, set);
  EXPECT_FALSE(im.doc.contains("steering"));
  EXPECT_TRUE(has_warning(im.warnings, "p.xml:1: <Project>", "model 'helbing'"));
}

TEST(MengeWarnings, ClockwiseContainerBecomesBoundsOrWalls) {
  // A clockwise rectangle around everything: the world's walled bounds.
  const std::string box = R"(  <ObstacleSet type="explicit" class="1">
    <Obstacle closed="1">
      <Vertex p_x="-5" p_y="-5" /><Vertex p_x="-5" p_y="5" />
      <Vertex p_x="5" p_y="5" /><Vertex p_x="5" p_y="-5" />
    </Obstacle>
  </ObstacleSet>
)";
  io::Imported im = pair(scene(group(agents({{0, 0}})) + box), kStand);
  EXPECT_EQ(im.doc["bounds"], json({-5, -5, 5, 5}));
  EXPECT_TRUE(im.doc["obstacles"].empty());
  // A clockwise triangle: walls outside its edges, with a warning.
  const std::string tri = R"(  <ObstacleSet type="explicit" class="1">
    <Obstacle closed="1">
      <Vertex p_x="-5" p_y="-5" /><Vertex p_x="0" p_y="5" /><Vertex p_x="5" p_y="-5" />
    </Obstacle>
  </ObstacleSet>
)";
  const std::string s = scene(group(agents({{0, 0}})) + tri);
  im = pair(s, kStand);
  EXPECT_EQ(im.doc["obstacles"].size(), 3u);
  EXPECT_TRUE(
      has_warning(im.warnings, at("s.xml", s, "<Obstacle closed", "Obstacle"), "clockwise"));
}

// Menge's obstacles are segments, so a polygon may double back on itself (office.xml does);
// crowddb's polygons may not: the spike is removed, with a warning.
TEST(MengeWarnings, SpikesAreRemoved) {
  for (const std::string ring : {
           R"(<Vertex p_x="0" p_y="0" /><Vertex p_x="4" p_y="0" /><Vertex p_x="4" p_y="4" />
      <Vertex p_x="2" p_y="4" /><Vertex p_x="2" p_y="6" /><Vertex p_x="2" p_y="4" />
      <Vertex p_x="0" p_y="4" />)",
           R"(<Vertex p_x="2" p_y="6" /><Vertex p_x="2" p_y="4" /><Vertex p_x="0" p_y="4" />
      <Vertex p_x="0" p_y="0" /><Vertex p_x="4" p_y="0" /><Vertex p_x="4" p_y="4" />
      <Vertex p_x="2" p_y="4" />)"}) {
    const std::string s = scene(group(agents({{8, 8}})) +
                                "  <ObstacleSet type=\"explicit\" class=\"1\">\n"
                                "    <Obstacle closed=\"1\">\n      " +
                                ring + "\n    </Obstacle>\n  </ObstacleSet>\n");
    const io::Imported im = pair(s, kStand);
    ASSERT_EQ(im.doc["obstacles"].size(), 1u);
    EXPECT_EQ(im.doc["obstacles"][0]["vertices"].size(), 5u) << im.doc["obstacles"][0];
    EXPECT_TRUE(has_warning(im.warnings, at("s.xml", s, "<Obstacle closed", "Obstacle"), "spike"));
    EXPECT_NO_THROW(io::parse_document(im.doc.dump(), "s.xml", &im.origins));
  }
}

// -- bad input: one line naming the file and line ------------------------------------------

void expect_error(const std::string& s, const std::string& b, const std::string& where,
                  const std::string& what, io::ProjectSettings set = {}) {
  const std::string e = error_of(s, b, set);
  EXPECT_EQ(e.rfind(where, 0), 0u) << "expected " << where << "... got: " << e;
  EXPECT_NE(e.find(what), std::string::npos) << "expected '" << what << "' in: " << e;
}

TEST(MengeErrors, MalformedXml) {
  expect_error("<Experiment>\n  <Common time_step=\"0.1\">\n</Experiment>\n", kStand,
               "s.xml:3:", "malformed XML");
  expect_error(scene(group(agents({{0, 0}}))), "<BFSM>\n<State name=\"a\" final=\"1\">\n",
               "b.xml:", "malformed XML");
}

TEST(MengeErrors, UnknownElementInBfsm) {
  const std::string b = "<BFSM>\n  <State name=\"Walk\" final=\"1\" />\n  <Goal />\n</BFSM>\n";
  expect_error(scene(group(agents({{0, 0}}))), b, "b.xml:3: <Goal>", "unknown element in <BFSM>");
}

TEST(MengeErrors, UnknownTypes) {
  const std::string gen = "    <Generator type=\"hex_grid\" anchor_x=\"0\" anchor_y=\"0\" />\n";
  std::string s = scene(group(gen));
  expect_error(s, kStand, at("s.xml", s, "hex_grid", "Generator"),
               "unknown generator type 'hex_grid'");

  s = scene(group(agents({{0, 0}})));
  std::string b = R"(<BFSM>
  <GoalSet id="0"><Goal type="square" id="0" x="1" y="1" /></GoalSet>
  <State name="Walk" final="1" />
</BFSM>
)";
  expect_error(s, b, "b.xml:2: <Goal>", "unknown goal type 'square'");
  b = R"(<BFSM>
  <State name="Walk" final="1">
    <GoalSelector type="closest" goal_set="0" />
  </State>
</BFSM>
)";
  expect_error(s, b, "b.xml:3: <GoalSelector>", "unknown goal selector type 'closest'");
  b = R"(<BFSM>
  <State name="Walk" final="0" />
  <Transition from="Walk" to="Walk"><Condition type="sometimes" /></Transition>
</BFSM>
)";
  expect_error(s, b, "b.xml:3: <Condition>", "unknown condition type 'sometimes'");
  s = scene(R"(  <AgentGroup>
    <ProfileSelector type="best" />
    <StateSelector type="const" name="Walk" />
  </AgentGroup>
)");
  expect_error(s, kStand, at("s.xml", s, "best", "ProfileSelector"),
               "unknown profile selector type 'best'");
}

TEST(MengeErrors, MissingRequiredAttribute) {
  const std::string gen = R"(    <Generator type="rect_grid" anchor_x="0" anchor_y="0"
        offset_x="1" offset_y="1" count_x="3" />
)";
  const std::string s = scene(group(gen));
  expect_error(s, kStand, at("s.xml", s, "rect_grid", "Generator"), "missing attribute 'count_y'");
  const std::string b = R"(<BFSM>
  <State name="Walk" />
</BFSM>
)";
  expect_error(scene(group(agents({{0, 0}}))), b, "b.xml:2: <State>", "missing attribute 'final'");
}

TEST(MengeErrors, MalformedNumber) {
  const std::string s =
      scene(group("    <Generator type=\"explicit\">\n"
                  "      <Agent p_x=\"1.5m\" p_y=\"0\" />\n"
                  "    </Generator>\n"));
  expect_error(s, kStand, at("s.xml", s, "1.5m", "Agent"),
               "attribute 'p_x': expected a number, got '1.5m'");
}

TEST(MengeErrors, BadGoalGeometry) {
  const std::string s = scene(group(agents({{0, 0}})));
  std::string b = R"(<BFSM>
  <GoalSet id="0"><Goal type="AABB" id="0" min_x="2" min_y="0" max_x="1" max_y="1" /></GoalSet>
  <State name="Walk" final="1" />
</BFSM>
)";
  expect_error(s, b, "b.xml:2: <Goal>", "min > max in x");
  b = R"(<BFSM>
  <GoalSet id="0"><Goal type="circle" id="0" x="2" y="0" radius="0" /></GoalSet>
  <State name="Walk" final="1" />
</BFSM>
)";
  expect_error(s, b, "b.xml:2: <Goal>", "'radius': must be > 0");
  const std::string neg = R"(<Experiment>
  <SpatialQuery type="kd-tree" />
  <Common time_step="0.1" />
  <AgentProfile name="p"><Common r="-0.2" /></AgentProfile>
)" + group(agents({{0, 0}})) +
                          "</Experiment>\n";
  expect_error(neg, kStand, "s.xml:4: <Common>", "r -0.2 for agent 0: must be > 0");
}

TEST(MengeErrors, TooManyAgents) {
  std::string s = scene(group(R"(    <Generator type="rect_grid" anchor_x="0" anchor_y="0"
        offset_x="1" offset_y="1" count_x="10000" count_y="10000" />
)"));
  expect_error(s, kStand, at("s.xml", s, "rect_grid", "Generator"), "more than 2000000");
  s = scene(group(R"(    <Generator type="hex_lattice" anchor_x="0" anchor_y="0"
        alignment="center" row_direction="x" density="1" width="10" population="20000000" />
)"));
  expect_error(s, kStand, at("s.xml", s, "hex_lattice", "Generator"), "more than 2000000");
  s = scene(group(R"(    <Generator type="hex_lattice" anchor_x="0" anchor_y="0"
        alignment="center" row_direction="y" density="1" width="1e12" population="1" />
)"));
  expect_error(s, kStand, at("s.xml", s, "hex_lattice", "Generator"), "more than 2000000");
  io::ProjectSettings small;
  small.max_agents = 3;
  s = scene(group(agents({{0, 0}, {1, 0}, {2, 0}, {3, 0}})));
  expect_error(s, kStand, at("s.xml", s, "explicit", "Generator"), "more than 3", small);
}

TEST(MengeErrors, AgentInsideAnObstacle) {
  const std::string s =
      scene(group(agents({{5, 5}, {0, 0}})) + R"(  <ObstacleSet type="explicit" class="1">
    <Obstacle closed="1">
      <Vertex p_x="-1" p_y="-1" /><Vertex p_x="1" p_y="-1" />
      <Vertex p_x="1" p_y="1" /><Vertex p_x="-1" p_y="1" />
    </Obstacle>
  </ObstacleSet>
)");
  expect_error(s, kStand, at("s.xml", s, "p_x=\"0\"", "Agent"),
               "agent at (0, 0) lies inside the obstacle at " +
                   at("s.xml", s, "<Obstacle closed", "Obstacle"));
  // A walking agent: the same.
  const std::string b = R"(<BFSM>
  <State name="Walk" final="0"><GoalSelector type="mirror" mirror_x="1" />
    <VelComponent type="goal" /></State>
</BFSM>
)";
  expect_error(s, b, at("s.xml", s, "p_x=\"0\"", "Agent"), "lies inside the obstacle");
}

TEST(MengeErrors, UnknownStateNames) {
  std::string s = scene(group(agents({{0, 0}}), "Run"));
  expect_error(s, kStand, at("s.xml", s, "name=\"Run\"", "StateSelector"), "unknown state 'Run'");
  s = scene(group(agents({{0, 0}})));
  std::string b = R"(<BFSM>
  <State name="Walk" final="0" />
  <Transition from="Walk" to="Stop"><Condition type="auto" /></Transition>
</BFSM>
)";
  expect_error(s, b, "b.xml:3: <Transition>", "attribute 'to': unknown state 'Stop'");
  b = R"(<BFSM>
  <State name="Walk" final="0" />
  <State name="Run" final="0" />
  <Transition from="Walk, Run" to="Walk"><Condition type="auto" /></Transition>
</BFSM>
)";
  expect_error(s, b, "b.xml:4: <Transition>", "names are not trimmed");
}

TEST(MengeErrors, OpenObstacle) {
  const std::string s = scene(group(agents({{5, 5}})) + R"(  <ObstacleSet type="explicit" class="1">
    <Obstacle closed="0">
      <Vertex p_x="-1" p_y="-1" /><Vertex p_x="1" p_y="-1" />
    </Obstacle>
  </ObstacleSet>
)");
  expect_error(s, kStand, at("s.xml", s, "closed=", "Obstacle"), "open obstacle");
}

TEST(MengeErrors, MissingSceneParts) {
  expect_error("<Experiment>\n  <SpatialQuery type=\"kd-tree\" />\n</Experiment>\n", kStand,
               "s.xml:1: <Experiment>", "missing <Common");
  expect_error("<Project/>", kStand, "s.xml:1: <Project>", "expected a Menge scene");
}

// -- Menge's own examples (tests/data/import/menge, Apache-2.0) -----------------------------

std::filesystem::path example(const std::string& rel) {
  return std::filesystem::path(CROWDDB_SOURCE_DIR) / "tests/data/import/menge" / rel;
}

TEST(MengeExamples, FourSquare) {
  const Scenario sc = load_scenario(example("core/4square.xml"));
  EXPECT_EQ(sc.world.agents().size(), 100u);
  EXPECT_EQ(sc.world.polygons().size(), 4u);
  EXPECT_TRUE(sc.stop_when_all_arrived);
  // The first agent of the first grid sits on its anchor (-7.3, -7.3) plus noise <= 0.25.
  EXPECT_LE(std::hypot(sc.world.agents().x[0] + 7.3, sc.world.agents().y[0] + 7.3), 0.25 + 1e-9);
}

TEST(MengeExamples, CrossAndDoorway) {
  const Scenario cross = load_scenario(example("core/cross.xml"));
  EXPECT_EQ(cross.world.agents().size(), 4u);
  const Scenario door = load_scenario(example("core/steerbench/doorwayTwoway.xml"));
  EXPECT_EQ(door.world.agents().size(), 2u);
  EXPECT_EQ(door.world.polygons().size(), 4u);
  // The Stop state walks on to goal 1 in Menge; crowddb's agents stand (one warning).
  EXPECT_TRUE(has_warning(door.warnings,
                          (example("core/steerbench/doorwayTwoway/"
                                   "doorwayTwowayB.xml"))
                              .lexically_normal()
                              .string(),
                          "final state"));
  Scenario run = load_scenario(example("core/steerbench/doorwayTwoway.xml"));
  Simulation sim(std::move(run.world), run.config);
  for (int k = 0; k < 20; ++k) sim.step();
}

}  // namespace
}  // namespace crowddb
