// The Vadere importer (src/io/import/vadere.cpp): releases 0.1 to 2.4, the mapping of every
// element (docs/importers/vadere.md), spawn counts worked by hand, one-line errors naming the file
// and line, and real files from Vadere's repository (tests/data/import/vadere/README.md).
#include "io/import/vadere.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "crowddb/error.hpp"
#include "crowddb/scenario.hpp"
#include "sim/sources.hpp"
#include "support/cli.hpp"
#include "support/sanitizers.hpp"

namespace crowddb {
namespace {

using nlohmann::json;
using test::TempDir;

std::string num(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

std::string rect(double x, double y, double w, double h) {
  return R"({"x": )" + num(x) + R"(, "y": )" + num(y) + R"(, "width": )" + num(w) +
         R"(, "height": )" + num(h) + R"(, "type": "RECTANGLE"})";
}

std::string circle(double x, double y, double r) {
  return R"({"type": "CIRCLE", "center": {"x": )" + num(x) + R"(, "y": )" + num(y) +
         R"(}, "radius": )" + num(r) + "}";
}

// A 2.4 target.
std::string target(int id, const std::string& shape, bool absorbing = true, double deletion = 0.1) {
  return R"({"id": )" + std::to_string(id) + R"(, "shape": )" + shape +
         R"(, "visible": true, "absorber": {"enabled": )" + (absorbing ? "true" : "false") +
         R"(, "deletionDistance": )" + num(deletion) +
         R"(}, "waiter": {"enabled": false, "distribution": null}, "leavingSpeed": -1.0, "parallelEvents": 0})";
}

// A 2.4 source with a regular spawner and a constant distribution.
std::string source(int id, const std::string& shape, const std::string& targets, double start,
                   double end, int count, double interval, int max = -1,
                   const std::string& element = "null") {
  return R"({"id": )" + std::to_string(id) + R"(, "shape": )" + shape +
         R"(, "visible": true, "targetIds": )" + targets +
         R"(, "spawner": {"type": "org.vadere.state.attributes.spawner.AttributesRegularSpawner", )" +
         R"("constraintsElementsMax": )" + std::to_string(max) + R"(, "constraintsTimeStart": )" +
         num(start) + R"(, "constraintsTimeEnd": )" + num(end) +
         R"(, "eventPositionRandom": true, "eventPositionGridCA": false, "eventPositionFreeSpace": true, )" +
         R"("eventElementCount": )" + std::to_string(count) + R"(, "eventElement": )" + element +
         R"(, "distribution": {"type": "org.vadere.state.attributes.distributions.AttributesConstantDistribution", "updateFrequency": )" +
         num(interval) + R"(}}, "groupSizeDistribution": [1.0]})";
}

// A pedestrian of dynamicElements.
std::string pedestrian(double x, double y, const std::string& targets, double speed = 1.2,
                       double radius = 0.25, int next = 0) {
  return R"({"attributes": {"id": 1, "radius": )" + num(radius) +
         R"(, "speedDistributionMean": 1.34, "speedDistributionStandardDeviation": 0.26}, )" +
         R"("source": null, "targetIds": )" + targets + R"(, "nextTargetListIndex": )" +
         std::to_string(next) + R"(, "position": {"x": )" + num(x) + R"(, "y": )" + num(y) +
         R"(}, "velocity": {"x": 0.5, "y": 0.0}, "freeFlowSpeed": )" + num(speed) +
         R"(, "type": "PEDESTRIAN"})";
}

struct Spec {
  std::string topography;  // members after "attributes", one per line
  std::string bounds = R"({"x": 0.0, "y": 0.0, "width": 45.0, "height": 3.0})";
  std::string bounded = "true";
  std::string simulation =
      R"("finishTime": 1300.0, "simTimeStepLength": 0.4, "useFixedSeed": true, "fixedSeed": 7)";
  std::string pedestrian_attrs =
      R"({"radius": 0.195, "speedDistributionMean": 1.34, "speedDistributionStandardDeviation": 0.0, "minimumSpeed": 0.5, "maximumSpeed": 2.2})";
  std::string extra_scenario;  // more members of "scenario"
};

// A 2.4 file, one element per line (so that tests can name lines).
std::string v24(const Spec& s) {
  std::string t = "{\n";
  t += "  \"name\": \"test\",\n";
  t += "  \"description\": \"a test\",\n";
  t += "  \"release\": \"2.4\",\n";
  t += "  \"scenario\": {\n";
  t += "    \"mainModel\": \"org.vadere.simulator.models.osm.OptimalStepsModel\",\n";
  t += "    \"attributesSimulation\": {" + s.simulation + "},\n";
  if (!s.extra_scenario.empty()) t += "    " + s.extra_scenario + ",\n";
  t += "    \"topography\": {\n";
  t += "      \"attributes\": {\"bounds\": " + s.bounds +
       ", \"boundingBoxWidth\": 0.5, \"bounded\": " + s.bounded + "},\n";
  t += "      \"attributesPedestrian\": " + s.pedestrian_attrs;
  if (!s.topography.empty()) t += ",\n" + s.topography;
  t += "\n    }\n  }\n}\n";
  return t;
}

// "name": [a, b, ...] with one element per line.
std::string list(const std::string& name, const std::vector<std::string>& items) {
  std::string t = "      \"" + name + "\": [\n";
  for (std::size_t i = 0; i < items.size(); ++i)
    t += "        " + items[i] + (i + 1 < items.size() ? ",\n" : "\n");
  return t + "      ]";
}

std::string join(const std::vector<std::string>& members) {
  std::string t;
  for (std::size_t i = 0; i < members.size(); ++i) t += (i ? ",\n" : "") + members[i];
  return t;
}

// 1-based line of the first occurrence of `needle`.
int vadere_line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

io::Imported import(const std::string& text, const std::string& name = "t.scenario") {
  return io::import_vadere(name, text, {});
}

std::string vadere_error_of(const std::string& text, const std::string& name = "t.scenario") {
  try {
    TempDir dir;
    load_scenario(dir.write(name, text));
  } catch (const Error& e) {
    std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << "not one line: " << what;
    // The temporary folder's path is not part of what the test checks.
    const auto slash = what.find(name);
    return slash == std::string::npos ? what : what.substr(slash);
  }
  ADD_FAILURE() << "no error";
  return "";
}

bool has_warning(const std::vector<std::string>& ws, const std::string& part) {
  for (const std::string& w : ws)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

std::string all(const std::vector<std::string>& ws) {
  std::string t;
  for (const std::string& w : ws) t += w + "\n";
  return t;
}

const std::string kExit = target(1, rect(42, 0.7, 1.5, 1.6));

// -- releases ---------------------------------------------------------------------------------

TEST(VadereImport, Release24File) {
  Spec s;
  s.topography = join({list("targets", {kExit}),
                       list("sources", {source(10, rect(1, 1, 1, 1), "[1]", 0, 1200, 1, 30)})});
  const io::Imported im = import(v24(s));
  const json& d = im.doc;
  EXPECT_EQ(d["name"], "test");
  EXPECT_EQ(d["bounds"], json({0.0, 0.0, 45.0, 3.0}));
  EXPECT_EQ(d["dt"], 0.1);  // min(simTimeStepLength 0.4, 0.1)
  EXPECT_EQ(d["duration"], 1300.0);
  EXPECT_EQ(d["seed"], 7u);
  EXPECT_EQ(d["stop_when_all_arrived"], false);
  EXPECT_EQ(d["steering"]["model"], "orca");
  EXPECT_EQ(d["arrival"], "remove");
  EXPECT_FALSE(d.contains("navigation"));  // no obstacles but the border walls
  ASSERT_EQ(d["goals"].size(), 1u);
  EXPECT_EQ(d["goals"][0]["area"], json({{42.0, 0.7}, {43.5, 0.7}, {43.5, 2.3}, {42.0, 2.3}}));
  ASSERT_EQ(d["sources"].size(), 1u);
  const json& src = d["sources"][0];
  EXPECT_EQ(src["count"], 41u);
  EXPECT_EQ(src["start"], 0.0);
  EXPECT_DOUBLE_EQ(src["rate"].get<double>(), 1.0 / 30);
  EXPECT_EQ(src["area"], json({1.0, 1.0, 2.0, 2.0}));
  EXPECT_EQ(src["radius"], 0.195);
  EXPECT_EQ(src["pref_speed"], 1.34);
  EXPECT_EQ(src["goal"], "g0");
  // One warning names Vadere's model.
  EXPECT_TRUE(has_warning(im.warnings,
                          "t.scenario:6: /scenario/mainModel: Vadere's "
                          "OptimalStepsModel (OSM) is not available"))
      << all(im.warnings);
  EXPECT_EQ(im.origins.at("/goals/0"),
            "t.scenario:" + std::to_string(vadere_line_of(v24(s), kExit)) +
                ": /scenario/topography/targets/0");
}

// 2.0 to 2.3: the source's fields sit on the source, the distribution has a short name and its
// parameters by name; targets have "absorbing" and "deletionDistance" beside them.
TEST(VadereImport, FlatSourceOf20To23) {
  Spec s;
  const std::string flat =
      R"({"id": 10, "shape": )" + rect(1, 1, 1, 1) +
      R"(, "interSpawnTimeDistribution": "constant", "distributionParameters": {"updateFrequency": 30.0}, )"
      R"("spawnNumber": 1, "maxSpawnNumberTotal": -1, "startTime": 0.0, "endTime": 1200.0, )"
      R"("spawnAtRandomPositions": true, "spawnAtGridPositionsCA": false, "useFreeSpaceOnly": true, )"
      R"("targetIds": [1], "groupSizeDistribution": [1.0], "dynamicElementType": "PEDESTRIAN", "attributesPedestrian": null})";
  const std::string old_target =
      R"({"id": 1, "absorbing": true, "shape": )" + rect(42, 0.7, 1.5, 1.6) +
      R"(, "waitingTime": 0.0, "waitingTimeYellowPhase": 0.0, "parallelWaiters": 0, "individualWaiting": true, )"
      R"("deletionDistance": 0.1, "startingWithRedLight": false, "nextSpeed": -1.0})";
  s.topography = join({list("targets", {old_target}), list("sources", {flat})});
  const io::Imported im = import(v24(s));
  EXPECT_EQ(im.doc["sources"][0]["count"], 41u);
  EXPECT_DOUBLE_EQ(im.doc["sources"][0]["rate"].get<double>(), 1.0 / 30);
  EXPECT_EQ(im.doc["arrival"], "remove");
  EXPECT_FALSE(has_warning(im.warnings, "unknown key")) << all(im.warnings);
}

// 1.16 and older: the distribution is a Java class and its parameters a list.
TEST(VadereImport, ClassNameSourceOf116) {
  const auto flat = [](const std::string& cls, const std::string& params) {
    return R"({"id": 10, "shape": )" + rect(1, 1, 1, 1) + R"(, "interSpawnTimeDistribution": ")" +
           cls + R"(", "distributionParameters": )" + params +
           R"(, "spawnNumber": 1, "maxSpawnNumberTotal": -1, "startTime": 0.0, "endTime": 1200.0, )"
           R"("spawnAtRandomPositions": true, "useFreeSpaceOnly": true, "targetIds": [1], )"
           R"("groupSizeDistribution": [1.0], "dynamicElementType": "PEDESTRIAN", "attributesPedestrian": null})";
  };
  Spec s;
  s.topography =
      join({list("targets", {kExit}),
            list("sources", {flat("org.vadere.state.scenario.ConstantDistribution", "[30.0]")})});
  io::Imported im = import(v24(s));
  EXPECT_EQ(im.doc["sources"][0]["count"], 41u);
  EXPECT_DOUBLE_EQ(im.doc["sources"][0]["rate"].get<double>(), 1.0 / 30);

  // Exponential times between events: the mean (30 s), regularly spaced, with a warning.
  s.topography =
      join({list("targets", {kExit}), list("sources", {flat("org.vadere.state.scenario."
                                                            "NegativeExponentialDistribution",
                                                            "[30.0]")})});
  im = import(v24(s));
  EXPECT_EQ(im.doc["sources"][0]["count"], 41u);
  EXPECT_TRUE(has_warning(im.warnings, "not at random times")) << all(im.warnings);

  // Classes the 2.0 migration rejects are errors.
  s.topography = join({list("targets", {kExit}),
                       list("sources", {flat("org.vadere.state.scenario.Other", "[30.0]")})});
  EXPECT_NE(vadere_error_of(v24(s)).find("is not supported"), std::string::npos);
}

// 0.1: the root is "vadere"; seeds were useRandomSeed / randomSeed; a source's interval was
// "spawnDelay".
TEST(VadereImport, VadereRootOf01) {
  const std::string text = R"({
  "name": "old",
  "description": "",
  "release": "0.1",
  "vadere": {
    "mainModel": "org.vadere.simulator.models.osm.OptimalStepsModel",
    "attributesSimulation": {"finishTime": 100.0, "simTimeStepLength": 0.05, "useRandomSeed": true, "randomSeed": 3},
    "topography": {
      "attributes": {"bounds": {"x": 0.0, "y": 0.0, "width": 20.0, "height": 10.0}, "boundingBoxWidth": 0.5, "bounded": true},
      "obstacles": [],
      "stairs": [],
      "targets": [{"id": 1, "absorbing": true, "shape": {"x": 18.0, "y": 4.0, "width": 1.0, "height": 2.0, "type": "RECTANGLE"}, "waitingTime": 0.0, "waitingTimeYellowPhase": 0.0, "parallelWaiters": 0, "individualWaiting": true, "deletionDistance": 0.1, "startingWithRedLight": false, "nextSpeed": -1.0}],
      "sources": [{"id": -1, "shape": {"x": 1.0, "y": 1.0, "width": 3.0, "height": 8.0, "type": "RECTANGLE"}, "spawnDelay": 10.0, "interSpawnTimeDistribution": "org.vadere.state.scenario.ConstantDistribution", "distributionParameters": [1.0], "spawnNumber": 2, "startTime": 0.0, "endTime": 40.0, "spawnAtRandomPositions": true, "useFreeSpaceOnly": true, "targetIds": [1], "dynamicElementType": "PEDESTRIAN"}],
      "dynamicElements": [],
      "attributesPedestrian": {"radius": 0.2, "densityDependentSpeed": false, "speedDistributionMean": 1.3, "speedDistributionStandardDeviation": 0.0, "minimumSpeed": 0.3, "maximumSpeed": 3.0, "acceleration": 2.0}
    }
  }
})";
  const io::Imported im = import(text);
  EXPECT_EQ(im.doc["seed"], 3u);
  EXPECT_EQ(im.doc["dt"], 0.05);
  EXPECT_EQ(im.doc["duration"], 100.0);
  // spawnDelay 10 s wins over [1.0]: events at 0, 10, 20, 30, 40 of 2 agents.
  EXPECT_EQ(im.doc["sources"][0]["count"], 10u);
  EXPECT_DOUBLE_EQ(im.doc["sources"][0]["rate"].get<double>(), 0.2);
  EXPECT_EQ(im.doc["sources"][0]["pref_speed"], 1.3);
  EXPECT_TRUE(has_warning(im.warnings, "/vadere/mainModel")) << all(im.warnings);
  EXPECT_FALSE(has_warning(im.warnings, "unknown key")) << all(im.warnings);
  TempDir dir;
  const Scenario sc = load_scenario(dir.write("old.scenario", text));
  EXPECT_EQ(sc.format, "vadere");
  EXPECT_EQ(sc.world.sources().size(), 1u);
}

// -- geometry ---------------------------------------------------------------------------------

std::vector<double> box_of(const json& poly) {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (const json& v : poly["vertices"]) {
    x0 = std::min(x0, v[0].get<double>());
    y0 = std::min(y0, v[1].get<double>());
    x1 = std::max(x1, v[0].get<double>());
    y1 = std::max(y1, v[1].get<double>());
  }
  return {x0, y0, x1, y1};
}

// Vadere's border walls: four strips of boundingBoxWidth inside the bounds (reaching 0.0001
// outside and past the corners, as Topography.createObstacleBoundary makes them); crowddb's own
// walls stay on.
TEST(VadereImport, BorderWallsAreFourStripsInsideTheBounds) {
  Spec s;
  s.topography = list("targets", {kExit});
  const io::Imported im = import(v24(s));
  ASSERT_EQ(im.doc["obstacles"].size(), 4u);
  std::vector<std::vector<double>> boxes;
  for (const json& o : im.doc["obstacles"]) boxes.push_back(box_of(o));
  const double g = 0.0001;
  const std::vector<std::vector<double>> expected = {{-g, -g, 45 + g, 0.5 + g},
                                                     {44.5 - g, -g, 45 + g, 3 + g},
                                                     {-g, 2.5 - g, 45 + g, 3 + g},
                                                     {-g, -g, 0.5 + g, 3 + g}};
  for (std::size_t k = 0; k < 4; ++k)
    for (std::size_t c = 0; c < 4; ++c) EXPECT_NEAR(boxes[k][c], expected[k][c], 1e-12) << k;
  EXPECT_FALSE(im.doc.contains("walls"));  // default: on

  s.bounded = "false";
  EXPECT_TRUE(import(v24(s)).doc["obstacles"].empty());
}

// Files often carry the border walls as obstacles too, sometimes twice; an obstacle repeated
// exactly is dropped as well. A real obstacle switches navigation on.
TEST(VadereImport, DuplicateObstaclesAreDropped) {
  const std::string strip =
      R"({"id": 2, "shape": {"type": "POLYGON", "points": [{"x": -1.0E-4, "y": -1.0E-4}, {"x": 45.0001, "y": -1.0E-4}, {"x": 45.0001, "y": 0.5001}, {"x": -1.0E-4, "y": 0.5001}]}, "visible": true})";
  const std::string inner = R"({"id": 3, "shape": )" + rect(0, 0, 0.5, 3) + "}";
  const std::string pillar = R"({"id": 4, "shape": )" + rect(20, 1, 1, 1) + "}";
  const std::string same_pillar =
      R"({"id": 5, "shape": {"type": "POLYGON", "points": [{"x": 21.0, "y": 2.0}, {"x": 21.0, "y": 1.0}, {"x": 20.0, "y": 1.0}, {"x": 20.0, "y": 2.0}]}})";
  Spec s;
  s.topography = join(
      {list("obstacles", {strip, strip, inner, pillar, same_pillar}), list("targets", {kExit})});
  const io::Imported im = import(v24(s));
  ASSERT_EQ(im.doc["obstacles"].size(), 5u);  // 4 border walls + the pillar
  EXPECT_EQ(box_of(im.doc["obstacles"][4]), std::vector<double>({20, 1, 21, 2}));
  EXPECT_TRUE(has_warning(im.warnings,
                          "/scenario/topography/obstacles/0: lies within the border "
                          "walls"))
      << all(im.warnings);
  EXPECT_TRUE(has_warning(im.warnings, "(and 2 more like it)")) << all(im.warnings);
  EXPECT_TRUE(has_warning(im.warnings, "/scenario/topography/obstacles/4: repeats an earlier"))
      << all(im.warnings);
  EXPECT_TRUE(im.doc.contains("navigation"));
}

// A polygon whose edges cross (Vadere fills it by the non-zero winding rule) becomes simple
// pieces; one that encloses a hole cannot and is an error.
TEST(VadereImport, CrossingPolygonsAreSplit) {
  const std::string bowtie =
      R"({"id": 2, "shape": {"type": "POLYGON", "points": [{"x": 10.0, "y": 1.0}, {"x": 12.0, "y": 2.0}, {"x": 12.0, "y": 1.0}, {"x": 10.0, "y": 2.0}]}})";
  Spec s;
  s.topography = join({list("obstacles", {bowtie}), list("targets", {kExit})});
  const std::string text = v24(s);
  const io::Imported im = import(text);
  ASSERT_EQ(im.doc["obstacles"].size(), 6u);  // 4 border walls + 2 triangles
  EXPECT_TRUE(has_warning(im.warnings, "imported as 2 simple pieces")) << all(im.warnings);
  TempDir dir;
  EXPECT_EQ(load_scenario(dir.write("t.scenario", text)).world.polygons().size(), 6u);
}

// -- targets ----------------------------------------------------------------------------------

// A polygon target is an area goal as it is; a circle is a disc grown by deletionDistance
// (Vadere's reach test: the agent's centre within that distance of the target).
TEST(VadereImport, TargetsAreAreasAndDiscs) {
  Spec s;
  const std::string poly =
      R"({"id": 1, "shape": {"type": "POLYGON", "points": [{"x": 40.0, "y": 1.0}, {"x": 42.0, "y": 1.0}, {"x": 41.0, "y": 2.0}]}, "absorber": {"enabled": true, "deletionDistance": 0.1}})";
  s.topography =
      join({list("targets", {poly, target(2, circle(30, 1.5, 0.5), true, 0.3)}),
            list("dynamicElements", {pedestrian(5, 1.5, "[1]"), pedestrian(5, 2, "[2]")})});
  const io::Imported im = import(v24(s));
  const json& goals = im.doc["goals"];
  ASSERT_EQ(goals.size(), 2u);
  EXPECT_EQ(goals[0]["area"], json({{40.0, 1.0}, {42.0, 1.0}, {41.0, 2.0}}));
  EXPECT_FALSE(goals[0].contains("arrival_radius"));
  EXPECT_NEAR(goals[0]["x"].get<double>(), 41, 1e-12);  // the centroid
  EXPECT_NEAR(goals[0]["y"].get<double>(), 4.0 / 3, 1e-12);
  EXPECT_EQ(goals[1]["x"], 30.0);
  EXPECT_EQ(goals[1]["y"], 1.5);
  EXPECT_DOUBLE_EQ(goals[1]["arrival_radius"].get<double>(), 0.8);
  EXPECT_EQ(im.doc["agents"][0]["goal"], "g0");
  EXPECT_EQ(im.doc["agents"][1]["goal"], "g1");
}

// Targets are visited in order; an absorbing one removes the agent (arrival "remove"), the last
// non-absorbing one lets it stand ("idle"); targets after an absorbing one are never reached.
TEST(VadereImport, TargetSequencesAndAbsorption) {
  const std::string a = target(1, rect(10, 1, 1, 1), false), b = target(2, rect(20, 1, 1, 1)),
                    c = target(3, rect(30, 1, 1, 1), false);
  Spec s;
  s.topography =
      join({list("targets", {a, b, c}),
            list("dynamicElements", {pedestrian(5, 1.5, "[1, 2]"), pedestrian(5, 2, "[1, 3]"),
                                     pedestrian(6, 1.5, "[1, 3]"), pedestrian(7, 1.5, "[2, 3]"),
                                     pedestrian(8, 1.5, "[1, 2, 3]", 1.2, 0.25, 1)})});
  const io::Imported im = import(v24(s));
  const json& agents = im.doc["agents"];
  ASSERT_EQ(agents.size(), 5u);
  EXPECT_EQ(agents[0]["goal"], json({"g0", "g1"}));
  EXPECT_EQ(agents[1]["goal"], json({"g0", "g2"}));
  EXPECT_EQ(agents[3]["goal"], "g1");  // 3 comes after absorbing 2: dropped
  EXPECT_EQ(agents[4]["goal"], "g1");  // nextTargetListIndex 1: from target 2 on
  EXPECT_TRUE(has_warning(im.warnings, "/dynamicElements/3/targetIds/0: target 2 is absorbing"))
      << all(im.warnings);
  // Three end absorbed, two standing: one policy for the world, the majority's, with a warning.
  EXPECT_EQ(im.doc["arrival"], "remove");
  EXPECT_TRUE(has_warning(im.warnings, "3 agents end at an absorbing target")) << all(im.warnings);

  s.topography =
      join({list("targets", {a, c}), list("dynamicElements", {pedestrian(5, 1.5, "[1, 3]")})});
  const io::Imported idle = import(v24(s));
  EXPECT_EQ(idle.doc["arrival"], "idle");
  EXPECT_FALSE(has_warning(idle.warnings, "arrival policy")) << all(idle.warnings);
}

// A target whose waiter has a constant distribution makes each agent wait that long, one with a
// negative exponential distribution a time drawn from it: the goal's "wait". The same area
// without a waiter is another goal.
TEST(VadereImport, ConstantAndExponentialWaitsAtTargetsBecomeGoalWaits) {
  const std::string counter =
      R"({"id": 2, "shape": )" + rect(20, 1, 1, 1) +
      R"(, "absorber": {"enabled": false, "deletionDistance": 0.1}, "waiter": {"enabled": true, "distribution": {"type": "org.vadere.state.attributes.distributions.AttributesConstantDistribution", "updateFrequency": 4.5}}, "leavingSpeed": -1.0, "parallelEvents": 0})";
  const std::string queue =
      R"({"id": 4, "shape": )" + rect(30, 1, 1, 1) +
      R"(, "absorber": {"enabled": true, "deletionDistance": 0.1}, "waiter": {"enabled": true, "distribution": {"type": "org.vadere.state.attributes.distributions.AttributesNegativeExponentialDistribution", "mean": 5.0}}, "leavingSpeed": -1.0, "parallelEvents": 0})";
  Spec s;
  s.topography =
      join({list("targets", {counter, target(3, rect(20, 1, 1, 1), false),
                             target(1, rect(40, 1, 1, 1)), queue}),
            list("dynamicElements", {pedestrian(5, 1.5, "[2, 1]"), pedestrian(6, 1.5, "[3, 1]"),
                                     pedestrian(7, 1.5, "[4]")})});
  const io::Imported im = import(v24(s));
  const json& goals = im.doc["goals"];
  ASSERT_EQ(goals.size(), 4u) << goals.dump();
  EXPECT_EQ(goals[3]["wait"], json({{"exponential", 5.0}}));
  EXPECT_EQ(goals[0]["wait"], 4.5);  // made in the order of first use: counter, exit, plain
  EXPECT_FALSE(goals[1].contains("wait"));
  EXPECT_FALSE(goals[2].contains("wait"));
  EXPECT_EQ(goals[0]["area"], goals[2]["area"]);
  EXPECT_FALSE(has_warning(im.warnings, "waiting")) << all(im.warnings);
  EXPECT_EQ(im.doc["agents"][0]["goal"], json({"g0", "g1"}));
  EXPECT_EQ(im.doc["agents"][1]["goal"], json({"g2", "g1"}));
  EXPECT_EQ(im.doc["agents"][2]["goal"], "g3");
  // And it loads.
  TempDir dir;
  EXPECT_NO_THROW(load_scenario(dir.write("t.scenario", v24(s))));
}

// Ids may repeat (rimea_08 has two exits with id 1): each agent takes the nearest.
TEST(VadereImport, SharedTargetIdsTakeTheNearest) {
  Spec s;
  s.topography =
      join({list("targets", {target(1, rect(2, 1, 1, 1)), target(1, rect(40, 1, 1, 1))}),
            list("dynamicElements", {pedestrian(5, 1.5, "[1]"), pedestrian(35, 1.5, "[1]")})});
  const io::Imported im = import(v24(s));
  EXPECT_EQ(im.doc["agents"][0]["goal"], "g0");
  EXPECT_EQ(im.doc["agents"][1]["goal"], "g1");
  EXPECT_TRUE(has_warning(im.warnings,
                          "/dynamicElements/0/targetIds/0: 2 targets have id 1: the agent heads "
                          "for the one nearest to it in a straight line"))
      << all(im.warnings);
}

// -- sources ----------------------------------------------------------------------------------

json only_source(const io::Imported& im) {
  EXPECT_EQ(im.doc["sources"].size(), 1u);
  return im.doc["sources"][0];
}

io::Imported with_source(const std::string& src, const std::string& simulation = "") {
  Spec s;
  if (!simulation.empty()) s.simulation = simulation;
  s.bounds = R"({"x": 0.0, "y": 0.0, "width": 45.0, "height": 12.0})";
  s.topography = join({list("targets", {kExit}), list("sources", {src})});
  return import(v24(s));
}

// Vadere's count (docs/importers/vadere.md, Sources):
// n * (floor((min(end, finishTime) - start) / interval) + 1), capped by constraintsElementsMax;
// crowddb lets agent k in at start + k * interval / n.
TEST(VadereImport, SourceCountsAndTimes) {
  // 1 agent every 30 s from 0 to 1200 s, finishTime 1300: events at 0, 30, ..., 1200.
  {
    const json& s = only_source(with_source(source(1, rect(1, 1, 1, 1), "[1]", 0, 1200, 1, 30)));
    EXPECT_EQ(s["count"], 41u);
    EXPECT_DOUBLE_EQ(s["rate"].get<double>(), 1.0 / 30);
  }
  // finishTime 600 s comes first: events at 0 .. 600.
  {
    const auto im = with_source(source(1, rect(1, 1, 1, 1), "[1]", 0, 1200, 1, 30),
                                R"("finishTime": 600.0, "simTimeStepLength": 0.4)");
    EXPECT_EQ(only_source(im)["count"], 21u);
  }
  // 10 agents every 20 s from 0 to 100 s (rimea_07): 6 events, 60 agents, 0.5 per second.
  {
    const json& s = only_source(with_source(source(1, rect(1, 1, 5, 5), "[1]", 0, 100, 10, 20)));
    EXPECT_EQ(s["count"], 60u);
    EXPECT_DOUBLE_EQ(s["rate"].get<double>(), 0.5);
  }
  // A start of 50 s: events at 50, 80, ..., 1280 (finishTime 1300, end 2000).
  {
    const json& s = only_source(with_source(source(1, rect(1, 1, 1, 1), "[1]", 50, 2000, 1, 30)));
    EXPECT_EQ(s["count"], 42u);
    EXPECT_EQ(s["start"], 50.0);
  }
  // constraintsElementsMax caps the count.
  EXPECT_EQ(
      only_source(with_source(source(1, rect(1, 1, 1, 1), "[1]", 0, 1200, 1, 30, 10)))["count"],
      10u);
  // A start after finishTime, or an end before the start: nobody comes (a warning).
  {
    const auto im = with_source(source(1, rect(1, 1, 1, 1), "[1]", 1400, 1500, 1, 30));
    EXPECT_FALSE(im.doc.contains("sources"));
    EXPECT_TRUE(has_warning(im.warnings, "spawns nobody before finishTime")) << all(im.warnings);
  }
  // Poisson: the mean rate, regularly spaced, with a warning.
  {
    const std::string poisson =
        R"({"id": 1, "shape": )" + rect(1, 1, 1, 1) +
        R"(, "targetIds": [1], "spawner": {"type": "org.vadere.state.attributes.spawner.AttributesRegularSpawner", "constraintsTimeStart": 0.0, "constraintsTimeEnd": 500.0, "eventPositionRandom": true, "eventElementCount": 1, "distribution": {"type": "org.vadere.state.attributes.distributions.AttributesPoissonDistribution", "numberPedsPerSecond": 0.25}}})";
    const auto im = with_source(poisson);
    EXPECT_EQ(only_source(im)["count"], 126u);  // floor(500 / 4) + 1
    EXPECT_DOUBLE_EQ(only_source(im)["rate"].get<double>(), 0.25);
    EXPECT_TRUE(has_warning(im.warnings, "Poisson spawn events")) << all(im.warnings);
  }
}

// start == end: one event of eventElementCount agents, all due at once; those that do not fit
// wait for a free spot (Vadere's carry-over).
TEST(VadereImport, SingleEventSource) {
  const std::string src = source(1, rect(1, 1, 20, 10), "[1]", 0, 0, 200, 1);
  const auto im = with_source(src);
  EXPECT_EQ(only_source(im)["count"], 200u);
  EXPECT_EQ(only_source(im)["rate"], 1e9);
  EXPECT_EQ(only_source(im)["start"], 0.0);

  Spec s;
  s.bounds = R"({"x": 0.0, "y": 0.0, "width": 45.0, "height": 12.0})";
  s.topography = join({list("targets", {kExit}), list("sources", {src})});
  TempDir dir;
  Scenario sc = load_scenario(dir.write("t.scenario", v24(s)));
  EXPECT_EQ(sim::source_total(sc.world.sources()[0]), 200u);
  Simulation sim(std::move(sc.world), sc.config);
  for (int k = 0; k < 20; ++k) sim.step();
  EXPECT_EQ(sim.entered_total() + sim.waiting_to_enter(), 200u);
  EXPECT_GE(sim.entered_total(), 150u);  // 200 discs of 0.195 m in 20 x 10 m: nearly all at once
}

// updateFrequency 0 between different start and end would make Vadere loop for ever.
TEST(VadereImport, ZeroIntervalIsAnError) {
  Spec s;
  s.topography = join({list("targets", {kExit}),
                       list("sources", {source(1, rect(1, 1, 1, 1), "[1]", 0, 10, 1, 0)})});
  const std::string text = v24(s);
  EXPECT_EQ(
      vadere_error_of(text),
      "t.scenario:" + std::to_string(vadere_line_of(text, "\"id\": 1, \"shape\": {\"x\": 1,")) +
          ": /scenario/topography/sources/0/spawner/distribution: "
          "updateFrequency 0: must be > 0 when constraintsTimeEnd != "
          "constraintsTimeStart (Vadere would loop for ever)");
}

// Spawned agents: spawner.eventElement, else topography.attributesPedestrian; a speed
// distribution with sd > 0 becomes a uniform range [max(min, mean - sd), min(max, mean + sd)].
TEST(VadereImport, SpawnedAgentsAttributes) {
  const std::string element =
      R"({"radius": 0.3, "speedDistributionMean": 1.0, "speedDistributionStandardDeviation": 0.5, "minimumSpeed": 0.8, "maximumSpeed": 2.2})";
  const auto im = with_source(source(1, rect(1, 1, 5, 5), "[1]", 0, 0, 5, 1, -1, element));
  const json& s = only_source(im);
  EXPECT_EQ(s["radius"], 0.3);
  EXPECT_EQ(s["pref_speed"], json({0.8, 1.5}));
  EXPECT_TRUE(has_warning(im.warnings, "imported as uniform in [0.8, 1.5] m/s"))
      << all(im.warnings);
}

TEST(VadereImport, SourceWithoutTargetsIsAnError) {
  const std::string src = source(1, rect(1, 1, 1, 1), "[]", 0, 0, 5, 1);
  Spec s;
  s.topography = join({list("targets", {kExit}), list("sources", {src})});
  const std::string text = v24(s);
  EXPECT_EQ(vadere_error_of(text).substr(0, vadere_error_of(text).find(": a source")),
            "t.scenario:" + std::to_string(vadere_line_of(text, src)) +
                ": /scenario/topography/sources/0");
}

// -- pedestrians ------------------------------------------------------------------------------

// Initial pedestrians keep their own radius, free-flow speed (as Vadere does, not re-sampled),
// velocity and target list; one without targets stands still: a circle obstacle.
TEST(VadereImport, PedestriansWithFreeFlowSpeed) {
  Spec s;
  s.topography = join(
      {list("targets", {kExit}), list("dynamicElements", {pedestrian(5, 1.5, "[1]", 1.42, 0.22),
                                                          pedestrian(9, 1.5, "[]", 1.0, 0.2)})});
  const std::string text = v24(s);
  const io::Imported im = import(text);
  ASSERT_EQ(im.doc["agents"].size(), 1u);
  const json& a = im.doc["agents"][0];
  EXPECT_EQ(a["x"], 5.0);
  EXPECT_EQ(a["y"], 1.5);
  EXPECT_EQ(a["radius"], 0.22);
  EXPECT_EQ(a["pref_speed"], 1.42);
  EXPECT_EQ(a["vx"], 0.5);
  EXPECT_EQ(a["vy"], 0.0);
  EXPECT_EQ(a["goal"], "g0");
  const json& standing = im.doc["obstacles"].back();
  EXPECT_EQ(standing, json({{"type", "circle"}, {"x", 9.0}, {"y", 1.5}, {"radius", 0.2}}));
  EXPECT_TRUE(has_warning(im.warnings, "/dynamicElements/1: a pedestrian with no target left"))
      << all(im.warnings);
  TempDir dir;
  const Scenario sc = load_scenario(dir.write("t.scenario", text));
  ASSERT_EQ(sc.world.agents().size(), 1u);
  EXPECT_EQ(sc.world.agents().pref_speed[0], 1.42);
  EXPECT_EQ(sc.world.agents().radius[0], 0.22);
}

// -- the top level ----------------------------------------------------------------------------

TEST(VadereImport, SeedsAndTicks) {
  Spec s;
  s.topography = list("targets", {kExit});
  s.simulation =
      R"("finishTime": 20.0, "simTimeStepLength": 0.0625, "useFixedSeed": true, "fixedSeed": -5)";
  io::Imported im = import(v24(s));
  EXPECT_EQ(im.doc["seed"], 0u);  // clamped
  EXPECT_EQ(im.doc["dt"], 0.0625);
  s.simulation = R"("finishTime": 20.0, "useFixedSeed": true, "fixedSeed": 18446744073709551615)";
  EXPECT_EQ(import(v24(s)).doc["seed"], 9223372036854775807u);
  s.simulation = R"("finishTime": 20.0, "useFixedSeed": false, "fixedSeed": 99)";
  im = import(v24(s));
  EXPECT_EQ(im.doc["seed"], 1u);
  EXPECT_TRUE(has_warning(im.warnings, "crowddb uses seed 1")) << all(im.warnings);
}

// A file and its conversion build the same world, bit for bit.
void expect_round_trip(const std::filesystem::path& file) {
  SCOPED_TRACE(file.string());
  Scenario direct = load_scenario(file);
  const Converted conv = convert_scenario(file);
  EXPECT_EQ(conv.format, "vadere");
  Scenario again = parse_scenario(conv.json, file.string());
  EXPECT_EQ(direct.ticks, again.ticks);
  Simulation a(std::move(direct.world), direct.config);
  Simulation b(std::move(again.world), again.config);
  for (int k = 0; k < 50; ++k) {
    a.step();
    b.step();
  }
  EXPECT_EQ(a.state_hash(), b.state_hash());
  EXPECT_EQ(a.world().agents().size(), b.world().agents().size());
}

const char* kRealFiles[] = {"rimea_01_pathway_discrete_ca.scenario", "rimea_06_corner.scenario",
                            "bottleneck.scenario", "v0.1_to_LATEST_Test2.scenario",
                            "s001.scenario"};

std::filesystem::path data(const std::string& name) {
  return std::filesystem::path(CROWDDB_SOURCE_DIR) / "tests/data/import/vadere" / name;
}

TEST(VadereImport, RoundTripGivesTheSameWorld) {
  for (const char* f : kRealFiles) expect_round_trip(data(f));
  Spec s;
  s.topography = join({list("obstacles", {R"({"id": 9, "shape": )" + rect(20, 0.5, 1, 1) + "}"}),
                       list("targets", {kExit, target(2, circle(30, 2, 0.3), false)}),
                       list("sources", {source(1, rect(1, 1, 2, 1), "[2, 1]", 0, 10, 2, 1)}),
                       list("dynamicElements", {pedestrian(5, 1.5, "[1]")})});
  TempDir dir;
  expect_round_trip(dir.write("synthetic.scenario", v24(s)));
}

// Real files from Vadere's repository (tests/data/import/vadere/README.md), unmodified.
TEST(VadereImport, RealFilesLoadWithExpectedCounts) {
  struct Case {
    const char* file;
    std::size_t agents, circles, polygons;
    uint64_t spawned;
    const char* first_warning;
  };
  const Case cases[] = {
      // 1 agent every 30 s for 0..1200 s; the 8 border copies dropped.
      {"rimea_01_pathway_discrete_ca.scenario", 0, 0, 4, 41, "OptimalStepsModel (OSM)"},
      // 20 at t = 0, two standing pedestrians (no targets) as circles, two walls.
      {"rimea_06_corner.scenario", 0, 2, 6, 20, "OptimalStepsModel (OSM)"},
      // 100 at t = 0 behind a bottleneck.
      {"bottleneck.scenario", 0, 0, 5, 100, "CellularAutomaton (CA)"},
      // 0.1: root "vadere", 200 at t = 0.
      {"v0.1_to_LATEST_Test2.scenario", 0, 0, 6, 200, "OptimalStepsModel (OSM)"},
      // 1.1: a class-name distribution, 4 per 20 s capped at 4.
      {"s001.scenario", 0, 0, 7, 4, "OptimalStepsModel (OSM)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const Scenario sc = load_scenario(data(c.file));
    EXPECT_EQ(sc.format, "vadere");
    EXPECT_EQ(sc.world.agents().size(), c.agents);
    EXPECT_EQ(sc.world.circles().size(), c.circles);
    EXPECT_EQ(sc.world.polygons().size(), c.polygons);
    uint64_t spawned = 0;
    for (const Source& s : sc.world.sources()) spawned += sim::source_total(s);
    EXPECT_EQ(spawned, c.spawned);
    ASSERT_FALSE(sc.warnings.empty());
    EXPECT_NE(sc.warnings[0].find(c.first_warning), std::string::npos) << sc.warnings[0];
  }
}

TEST(VadereImport, RegistryRoutesVadereFiles) {
  TempDir dir;
  Spec s;
  s.topography = list("targets", {kExit});
  EXPECT_EQ(scenario_format(dir.write("a.scenario", v24(s))), "vadere");
  EXPECT_EQ(scenario_format(dir.write("a.json", v24(s))), "vadere");
  EXPECT_EQ(scenario_format(dir.write("b.json", R"({"bounds": [0, 0, 1, 1]})")), "crowddb");
  // A behaviour file belongs to Menge.
  LoadOptions opt;
  opt.behavior = "b.xml";
  try {
    load_scenario(dir / "a.scenario", opt);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::usage);
  }
}

// -- bad input --------------------------------------------------------------------------------

// Each problem is one line: the file, the line, the JSON pointer, what.
TEST(VadereImport, BadInputNamesFileAndLine) {
  struct Case {
    std::string text;
    std::string marker;   // the line to name holds this
    std::string message;  // after "t.scenario:LINE: "
  };
  const auto with = [](const std::string& topography) {
    Spec s;
    s.topography = topography;
    return v24(s);
  };
  const std::string ped_in_pillar = pedestrian(20.5, 1.5, "[1]");
  const std::vector<Case> cases = {
      {"{\n  \"name\": \"x\",\n  \"scenario\": {,\n}", "{,",
       "3:16: malformed JSON: syntax error while parsing object key - unexpected ','; expected "
       "string literal"},
      {"{\n  \"name\": \"x\",\n  \"scenario\": {\"topography\": {}},\n  \"name\": \"y\"\n}",
       "\"name\": \"y\"", "/: duplicate key \"name\" (Vadere rejects repeated keys)"},
      {"{\n  \"name\": \"x\",\n  \"scenario\": {\"topography\": {\"obstacles\": [{\"id\": 1,\n"
       "  \"i~d/\": {}, \"i~d/\": 2}]}}\n}",
       "\"i~d/\": {}",
       "/scenario/topography/obstacles/0: duplicate key \"i~d/\" (Vadere rejects repeated keys)"},
      {"{\n  \"name\": \"x\",\n  \"scenario\": {\"topography\": {}},\n  \"a~b/c\": [0, {\"k\": 1,\n"
       "  \"k\": 2}]\n}",
       "\"k\": 2", "/a~0b~1c/1: duplicate key \"k\" (Vadere rejects repeated keys)"},
      {"{\n  \"description\": \"\",\n  \"scenario\": {\"topography\": {}}\n}", "{",
       "/: missing \"name\" (a string)"},
      {"{\n  \"name\": \"x\",\n  \"scenario\": {\n    \"attributesSimulation\": {}\n  }\n}",
       "\"scenario\"", "/scenario: missing \"topography\""},
      {"{\n  \"name\": 3,\n  \"scenario\": {\"topography\": {}}\n}", "\"name\": 3",
       "/name: expected a string, got number"},
      {with(list("obstacles", {R"({"id": 1, "shape": {"type": "ELLIPSE", "x": 1.0}})"})), "ELLIPSE",
       "/scenario/topography/obstacles/0/shape/type: unknown shape type 'ELLIPSE' (Vadere's are "
       "RECTANGLE, POLYGON and CIRCLE)"},
      {with(list("obstacles", {R"({"id": 1, "shape": {"type": "RING"}})"})), "RING",
       "/scenario/topography/obstacles/0/shape/type: RING shapes are not usable in files (Vadere "
       "neither writes nor reads them)"},
      {with(list(
           "obstacles",
           {R"({"id": 1, "shape": {"type": "POLYGON", "points": [{"x": 1.0, "y": 1.0}, {"x": 2.0, "y": 1.0}]}})"})),
       "\"POLYGON\"",
       "/scenario/topography/obstacles/0/shape/points: a polygon needs at least 3 distinct "
       "points (got 2)"},
      {with(list("obstacles", {R"({"id": 1, "shape": )" + rect(1, 1, 0, 2) + "}"})), "\"id\": 1",
       "/scenario/topography/obstacles/0/shape: a rectangle needs width > 0 and height > 0 (got "
       "0 x 2)"},
      {with(list(
           "obstacles",
           {R"({"id": 1, "shape": {"type": "RECTANGLE", "x": 1.0, "y": "a", "width": 1.0, "height": 1.0}})"})),
       "\"y\": \"a\"", "/scenario/topography/obstacles/0/shape/y: expected a number, got string"},
      {with(join(
           {list("targets", {kExit}), list("dynamicElements", {pedestrian(5, 1.5, "[1, 7]")})})),
       "[1, 7]",
       "/scenario/topography/dynamicElements/0/targetIds/1: target 7 does not exist (no target "
       "has this id)"},
      {with(join({list("targets", {target(1, rect(50, 1, 1, 1))}),
                  list("dynamicElements", {pedestrian(5, 1.5, "[1]")})})),
       "\"x\": 50",
       "/scenario/topography/targets/0: a target outside the world: target 1 lies outside the "
       "bounds [0, 0, 45, 3]"},
      {with(join({list("obstacles", {R"({"id": 9, "shape": )" + rect(20, 1, 1, 1) + "}"}),
                  list("targets", {kExit}), list("dynamicElements", {ped_in_pillar})})),
       ped_in_pillar,
       "/scenario/topography/dynamicElements/0 (converted: /agents/0): agent at (20.5, 1.5) lies "
       "inside obstacle /obstacles/4, outside the walkable area"},
      {with(join({list("targets", {kExit}),
                  list("sources", {source(1, rect(1, 1, 1, 1), "[1]", 0, 0, 20000000, 1)})})),
       "\"id\": 1, \"shape\": {\"x\": 1,",
       "/scenario/topography/sources/0: would spawn 20000000 agents, more than 10^7 in all"},
      {with(join({list("targets", {kExit}),
                  list("sources", {source(1, rect(1, 1, 1, 1), "[1]", 0, 1000, 1, 1e-6)})})),
       "\"id\": 1, \"shape\": {\"x\": 1,",
       "/scenario/topography/sources/0: would spawn 1000000001 agents, more than 10^7 in all"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    const std::string expected =
        std::isdigit(static_cast<unsigned char>(c.message[0]))  // line:column of a syntax error
            ? "t.scenario:" + c.message
            : "t.scenario:" + std::to_string(vadere_line_of(c.text, c.marker)) + ": " + c.message;
    EXPECT_EQ(vadere_error_of(c.text), expected);
  }
}

// Deep nesting costs memory in proportion to the text: the line index kept a copy of the JSON
// pointer in every open container, which grew with the square of the depth (a 2 MB file of
// 10^6 nested arrays was killed at 24 GB; this one, 100,000 deep, needed about 10 GB). The
// read runs in a child limited to 2 GB of address space, so a regression fails here instead of
// exhausting the machine. (Sanitizer builds reserve terabytes of shadow memory: no limit there.)
TEST(VadereImport, DeeplyNestedValuesCostLinearMemory) {
  const std::size_t depth = 100000;
  const std::string text = "{\"name\": \"x\", \"description\": " + std::string(depth, '[') +
                           std::string(depth, ']') + "}";
  const std::string expected = "t.scenario:1: /description: expected a string, got array";
#if defined(CROWDDB_TEST_ASAN)
  EXPECT_EQ(vadere_error_of(text), expected);
#else
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const auto read_limited = [&] {
    rlimit limit;
    limit.rlim_cur = limit.rlim_max = rlim_t{2} << 30;
    setrlimit(RLIMIT_AS, &limit);
    std::exit(vadere_error_of(text) == expected ? 0 : 1);
  };
  EXPECT_EXIT(read_limited(), ::testing::ExitedWithCode(0), "");
#endif
}

// Elements Vadere has and crowddb does not: one warning each, naming file, line and element.
TEST(VadereImport, WarningsForUnsupportedElements) {
  const std::string waiting =
      R"({"id": 2, "shape": )" + rect(20, 1, 1, 1) +
      R"(, "absorber": {"enabled": false, "deletionDistance": 0.1}, "waiter": {"enabled": true, "distribution": {"type": "org.vadere.state.attributes.distributions.AttributesNormalDistribution", "mean": 5.0, "sd": 1.0}}, "leavingSpeed": 0.5, "parallelEvents": 2})";
  const std::string groups =
      R"({"id": 1, "shape": )" + rect(1, 1, 1, 1) +
      R"(, "targetIds": [2, 1], "spawner": {"constraintsTimeStart": 0.0, "constraintsTimeEnd": 0.0, "eventPositionRandom": true, "eventElementCount": 4}, "groupSizeDistribution": [0.5, 0.5]})";
  Spec s;
  s.extra_scenario =
      R"("attributesModel": {"org.vadere.state.attributes.models.AttributesOSM": {"submodels": ["org.vadere.simulator.models.groups.cgm.CentroidGroupModel"]}},
    "attributesPsychology": {"usePsychologyLayer": true, "psychologyLayer": {}},
    "stimulusInfos": [])";
  s.bounds = R"({"x": 0.0, "y": 0.0, "width": 45.0, "height": 12.0})";
  s.topography = join({
      list("measurementAreas", {R"({"id": 5, "shape": )" + rect(3, 3, 1, 1) + "}"}),
      list("stairs", {R"({"id": 4, "shape": )" + rect(10, 3, 2, 2) +
                      R"(, "treadCount": 9, "upwardDirection": {"x": 1.0, "y": 0.0}})"}),
      list("targets", {kExit, waiting}),
      list(
          "targetChangers",
          {R"({"id": 6, "shape": )" + rect(5, 5, 1, 1) +
           R"(, "reachDistance": 0.0, "changeAlgorithmType": "SELECT_LIST", "nextTarget": [1], "probabilityToChangeTarget": [1.0]})"}),
      list("absorbingAreas", {R"({"id": 7, "shape": )" + rect(5, 8, 1, 1) +
                              R"(, "absorber": {"enabled": true, "deletionDistance": 0.1}})"}),
      list("sources", {groups}),
      list("dynamicElements", {R"({"type": "CAR", "position": {"x": 5.0, "y": 5.0}})"}),
      "      \"teleporter\": {\"shift\": {\"x\": -40.0, \"y\": 0.0}, \"position\": {\"x\": 42.0, "
      "\"y\": 0.0}}",
      "      \"attributesCar\": null",
      "      \"colour\": \"red\"",
  });
  const std::string text = v24(s);
  const io::Imported im = import(text);
  const auto at = [&](const std::string& marker, const std::string& pointer) {
    return "t.scenario:" + std::to_string(vadere_line_of(text, marker)) + ": " + pointer + ": ";
  };
  const std::vector<std::string> expected = {
      at("\"mainModel\"", "/scenario/mainModel") +
          "Vadere's OptimalStepsModel (OSM) with submodels CentroidGroupModel is not available",
      at("attributesPsychology", "/scenario/attributesPsychology") + "the psychology layer",
      at("\"stairs\"", "/scenario/topography/stairs") + "1 stairs: walkable",
      at("\"targetChangers\"", "/scenario/topography/targetChangers") +
          "1 target changers are not supported",
      at("\"absorbingAreas\"", "/scenario/topography/absorbingAreas") +
          "1 absorbing areas are not supported",
      at("\"teleporter\"", "/scenario/topography/teleporter") + "the teleporter",
      at("\"id\": 2, \"shape\"", "/scenario/topography/targets/1") +
          "this kind of waiting at targets is not supported (waiter "
          "AttributesNormalDistribution)",
      at("\"id\": 2, \"shape\"", "/scenario/topography/targets/1/leavingSpeed") +
          "leavingSpeed 0.5 m/s",
      at("\"id\": 2, \"shape\"", "/scenario/topography/targets/1/parallelEvents") +
          "parallelEvents 2",
      at("groupSizeDistribution", "/scenario/topography/sources/0/groupSizeDistribution") +
          "groups of mean size 1.5 (CentroidGroupModel)",
      at("\"colour\"", "/scenario/topography/colour") + "unknown key ignored",
      at("\"CAR\"", "/scenario/topography/dynamicElements/0") +
          "a dynamic element of type CAR is dropped",
  };
  for (const std::string& e : expected)
    EXPECT_TRUE(has_warning(im.warnings, e)) << e << "\n" << all(im.warnings);
  EXPECT_FALSE(has_warning(im.warnings, "measurementAreas")) << all(im.warnings);
  EXPECT_FALSE(has_warning(im.warnings, "attributesCar")) << all(im.warnings);
  // 4 groups of mean size 1.5 per event: 6 people, walking the waiting target, then the exit.
  EXPECT_EQ(im.doc["sources"][0]["count"], 6u);
  EXPECT_EQ(im.doc["sources"][0]["goal"], json({"g0", "g1"}));
  // And it loads.
  TempDir dir;
  const Scenario sc = load_scenario(dir.write("t.scenario", text));
  EXPECT_TRUE(sc.warnings.front().ends_with(im.warnings.front())) << sc.warnings.front();
}

// Whatever the bytes, an Error or a document; never a crash or another exception.
TEST(VadereImport, TruncatedFilesGiveErrors) {
  const std::string text = test::slurp(data("rimea_06_corner.scenario"));
  for (std::size_t n = 0; n < text.size(); n += 97) {
    try {
      import(text.substr(0, n));
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace crowddb
