// The SteerSuite importer: small test cases written here, placements and goals worked by hand,
// the round trip through `convert`, and one-line errors naming file, line and element.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "crowddb/error.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "support/cli.hpp"  // TempDir

namespace crowddb {
namespace {

namespace fs = std::filesystem;

// A test case file in the program's temporary folder, removed with it when the program ends (a
// folder named by the process id was left behind by every run).
fs::path write_case(const std::string& name, const std::string& text) {
  static const test::TempDir dir;
  return dir.write(name, text);
}

std::string header(const std::string& bounds = "-100 100 -100 100") {
  std::istringstream is(bounds);
  double x0, x1, z0, z1;
  is >> x0 >> x1 >> z0 >> z1;
  std::ostringstream os;
  os << "<SteerBenchTestCase xmlns=\"http://www.magix.ucla.edu/steerbench\">\n"
     << "  <header><version>1.0</version><name>t</name><worldBounds><xmin>" << x0 << "</xmin><xmax>"
     << x1 << "</xmax><ymin>0</ymin><ymax>0</ymax><zmin>" << z0 << "</zmin><zmax>" << z1
     << "</zmax></worldBounds></header>\n";
  return os.str();
}

std::string agent(double x, double z, double tx, double tz, const std::string& extra = "") {
  std::ostringstream os;
  os << "  <agent><initialConditions><radius>0.5</radius><position><x>" << x << "</x><y>0</y><z>"
     << z << "</z></position><direction><x>1</x><y>0</y><z>0</z></direction><speed>0</speed>"
     << extra << "</initialConditions><goalSequence><seekStaticTarget><targetLocation><x>" << tx
     << "</x><y>0</y><z>" << tz
     << "</z></targetLocation><desiredSpeed>1.3</desiredSpeed><timeDuration>1000</timeDuration>"
        "</seekStaticTarget></goalSequence></agent>\n";
  return os.str();
}

std::string import_error_of(const fs::path& p) {
  try {
    load_scenario(p);
  } catch (const Error& e) {
    const std::string w = e.what();
    EXPECT_EQ(w.find('\n'), std::string::npos) << "not one line: " << w;
    return w;
  }
  return "";
}

TEST(SteerSuiteImport, ExplicitAgentsObstaclesAndGoalsMapToThePlaneXZ) {
  const fs::path p = write_case(
      "squeeze.xml", "<!-- c --><?xml version=\"1.0\"?>\n" + header() +
                         "  <obstacle><xmin>-20</xmin><xmax>20</xmax><ymin>0</ymin><ymax>1</ymax>"
                         "<zmin>1.25</zmin><zmax>3</zmax></obstacle>\n" +
                         agent(-10, -0.5, 10, -0.5) + agent(10, 0.5, -10, 0.5) +
                         "</SteerBenchTestCase>\n");
  Scenario sc = load_scenario(p);
  EXPECT_EQ(sc.format, "steersuite");
  EXPECT_EQ(sc.config.dt, 0.05);
  EXPECT_TRUE(sc.stop_when_all_arrived);
  EXPECT_TRUE(sc.config.navigation.enabled);  // there is an obstacle
  const AgentTable& t = sc.world.agents();
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t.x[0], -10);
  EXPECT_EQ(t.y[0], -0.5);  // z becomes y
  EXPECT_EQ(t.radius[0], 0.5);
  EXPECT_EQ(t.pref_speed[0], 1.3);
  ASSERT_EQ(sc.world.goals().size(), 2u);
  const Goal& g = sc.world.goals()[t.goal[0]];
  EXPECT_EQ(g.x, 10);
  EXPECT_EQ(g.y, -0.5);
  EXPECT_EQ(g.arrival_radius, 0.5);  // PPR's threshold
  ASSERT_EQ(sc.world.polygons().size(), 1u);
  double xmin = 1e9, xmax = -1e9, ymin = 1e9, ymax = -1e9;
  for (const Vec2& v : sc.world.polygons()[0].vertices) {
    xmin = std::min(xmin, v.x);
    xmax = std::max(xmax, v.x);
    ymin = std::min(ymin, v.y);
    ymax = std::max(ymax, v.y);
  }
  EXPECT_EQ(xmin, -20);
  EXPECT_EQ(xmax, 20);
  EXPECT_EQ(ymin, 1.25);
  EXPECT_EQ(ymax, 3);
  EXPECT_EQ(sc.world.bounds().xmin, -100);
  EXPECT_EQ(sc.world.bounds().ymax, 100);
}

TEST(SteerSuiteImport, InitialVelocityIsSpeedAlongTheNormalisedDirection) {
  const fs::path p = write_case(
      "v.xml", header() +
                   "  <agent><initialConditions><radius>0.4</radius><position><x>0</x><y>0</y>"
                   "<z>0</z></position><direction><x>3</x><y>0</y><z>4</z></direction><speed>2"
                   "</speed></initialConditions><goalSequence><seekStaticTarget><targetLocation>"
                   "<x>5</x><y>0</y><z>5</z></targetLocation><desiredSpeed>1.5</desiredSpeed>"
                   "</seekStaticTarget></goalSequence></agent></SteerBenchTestCase>");
  Scenario sc = load_scenario(p);
  const AgentTable& t = sc.world.agents();
  EXPECT_NEAR(t.vx[0], 1.2, 1e-12);
  EXPECT_NEAR(t.vy[0], 1.6, 1e-12);
  EXPECT_EQ(t.pref_speed[0], 1.5);
  EXPECT_EQ(t.radius[0], 0.4);
}

// SteerSuite's placement: MT19937 seeded with 2, rand(n) = mt() / (2^32 - 1) * n, the centre at
// region.min + r + rand(span - 2 r), x before z; a random direction drawn after the position.
TEST(SteerSuiteImport, RegionPlacementFollowsSteerSuitesGenerator) {
  const fs::path p = write_case(
      "region.xml",
      header() +
          "  <agentRegion><numAgents>3</numAgents><regionBounds><xmin>-10</xmin><xmax>10</xmax>"
          "<ymin>0</ymin><ymax>0</ymax><zmin>0</zmin><zmax>5</zmax></regionBounds>"
          "<initialConditions><radius>0.5</radius><direction><random>true</random></direction>"
          "<speed>1</speed></initialConditions><goalSequence><seekStaticTarget><targetLocation>"
          "<x>50</x><y>0</y><z>0</z></targetLocation><desiredSpeed>1.3</desiredSpeed>"
          "</seekStaticTarget></goalSequence></agentRegion></SteerBenchTestCase>");
  Scenario sc = load_scenario(p);
  const AgentTable& t = sc.world.agents();
  ASSERT_EQ(t.size(), 3u);
  std::mt19937 mt(2);
  auto rand = [&](double n) { return static_cast<double>(mt()) * (1.0 / 4294967295.0) * n; };
  for (std::size_t i = 0; i < 3; ++i) {
    const double x = -10 + 0.5 + rand(19), z = 0 + 0.5 + rand(4);  // no overlaps here: first try
    const double a = rand(2 * M_PI);
    EXPECT_DOUBLE_EQ(t.x[i], x) << i;
    EXPECT_DOUBLE_EQ(t.y[i], z) << i;
    EXPECT_NEAR(t.vx[i], std::cos(a), 1e-12) << i;
    EXPECT_NEAR(t.vy[i], std::sin(a), 1e-12) << i;
  }
}

TEST(SteerSuiteImport, RandomAgentsAvoidObstaclesAndEachOther) {
  std::string text = header("-10 10 -10 10") +
                     "  <obstacle><xmin>-2</xmin><xmax>2</xmax><ymin>0</ymin><ymax>1</ymax>"
                     "<zmin>-2</zmin><zmax>2</zmax></obstacle>\n"
                     "  <agentRegion><numAgents>60</numAgents><regionBounds><xmin>-5</xmin>"
                     "<xmax>5</xmax><ymin>0</ymin><ymax>0</ymax><zmin>-5</zmin><zmax>5</zmax>"
                     "</regionBounds><initialConditions><radius>0.3</radius><speed>0</speed>"
                     "<direction><x>1</x><y>0</y><z>0</z></direction></initialConditions>"
                     "<goalSequence><seekStaticTarget><targetLocation><x>9</x><y>0</y><z>9</z>"
                     "</targetLocation><desiredSpeed>1.3</desiredSpeed></seekStaticTarget>"
                     "</goalSequence></agentRegion></SteerBenchTestCase>";
  Scenario sc = load_scenario(write_case("crowded.xml", text));
  const AgentTable& t = sc.world.agents();
  ASSERT_EQ(t.size(), 60u);
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_TRUE(std::abs(t.x[i]) >= 2.3 || std::abs(t.y[i]) >= 2.3) << "inside the box: " << i;
    for (std::size_t j = i + 1; j < t.size(); ++j)
      EXPECT_GE(std::hypot(t.x[i] - t.x[j], t.y[i] - t.y[j]), 0.6) << i << " " << j;
  }
  EXPECT_TRUE(sc.warnings.empty());
}

TEST(SteerSuiteImport, OrientedBoxesRotateByThetaYInTheXZPlane) {
  // A 4 x 2 box rotated by 90 degrees: x' = x cos t + z sin t, z' = z cos t - x sin t, so the
  // long side (along x) lies along -z... which is 2 x 4 in x-z around the centre (10, 5).
  const fs::path p = write_case(
      "obox.xml", header() +
                      "  <orientedBoxObstacle><thetaY>90</thetaY><size><x>4</x><y>1</y><z>2</z>"
                      "</size><position><x>10</x><y>0</y><z>5</z></position>"
                      "</orientedBoxObstacle>\n" +
                      agent(0, 0, -5, 0) + "</SteerBenchTestCase>");
  Scenario sc = load_scenario(p);
  ASSERT_EQ(sc.world.polygons().size(), 1u);
  double xmin = 1e9, xmax = -1e9, ymin = 1e9, ymax = -1e9;
  for (const Vec2& v : sc.world.polygons()[0].vertices) {
    xmin = std::min(xmin, v.x);
    xmax = std::max(xmax, v.x);
    ymin = std::min(ymin, v.y);
    ymax = std::max(ymax, v.y);
  }
  EXPECT_NEAR(xmin, 9, 1e-9);
  EXPECT_NEAR(xmax, 11, 1e-9);
  EXPECT_NEAR(ymin, 3, 1e-9);
  EXPECT_NEAR(ymax, 7, 1e-9);
}

TEST(SteerSuiteImport, GoalSequencesAndBoxGoals) {
  const fs::path p = write_case(
      "seq.xml",
      header() +
          "  <agent><initialConditions><radius>0.5</radius><position><x>0</x><y>0</y><z>0</z>"
          "</position><direction><x>1</x><y>0</y><z>0</z></direction><speed>0</speed>"
          "</initialConditions><goalSequence><seekStaticTarget><targetLocation><x>10</x><y>0"
          "</y><z>0</z></targetLocation><desiredSpeed>1.2</desiredSpeed></seekStaticTarget>"
          "<seekAxisAlignedBoxRegion><targetLocation><x>0</x><y>0</y><z>0</z></targetLocation>"
          "<goalRegionBounds><xmin>20</xmin><xmax>22</xmax><ymin>0</ymin><ymax>0</ymax><zmin>-1"
          "</zmin><zmax>1</zmax></goalRegionBounds><desiredSpeed>1.2</desiredSpeed>"
          "</seekAxisAlignedBoxRegion></goalSequence></agent></SteerBenchTestCase>");
  Scenario sc = load_scenario(p);
  const AgentTable& t = sc.world.agents();
  ASSERT_EQ(sc.world.goals().size(), 2u);
  EXPECT_EQ(sc.world.goals()[t.goal[0]].x, 10);
  ASSERT_EQ(t.then[0].size(), 1u);
  const Goal& box = sc.world.goals()[t.then[0][0]];
  EXPECT_TRUE(box.is_polygon());
  EXPECT_EQ(t.pref_speed[0], 1.2);
}

TEST(SteerSuiteImport, ConvertedScenarioRunsBitIdentically) {
  std::string text = header("-20 20 -20 20") +
                     "  <obstacle><xmin>-1</xmin><xmax>1</xmax><ymin>0</ymin><ymax>1</ymax>"
                     "<zmin>-6</zmin><zmax>6</zmax></obstacle>\n"
                     "  <agentRegion><numAgents>20</numAgents><regionBounds><xmin>-15</xmin>"
                     "<xmax>-5</xmax><ymin>0</ymin><ymax>0</ymax><zmin>-5</zmin><zmax>5</zmax>"
                     "</regionBounds><initialConditions><radius>0.3</radius><speed>0</speed>"
                     "<direction><random>true</random></direction></initialConditions>"
                     "<goalSequence><seekStaticTarget><targetLocation><x>12</x><y>0</y><z>0</z>"
                     "</targetLocation><desiredSpeed>1.3</desiredSpeed></seekStaticTarget>"
                     "</goalSequence></agentRegion>" +
                     agent(10, 3, -10, 3) + "</SteerBenchTestCase>";
  const fs::path p = write_case("roundtrip.xml", text);
  const Converted c = convert_scenario(p);
  EXPECT_EQ(c.format, "steersuite");
  const fs::path j = write_case("roundtrip.json", c.json);
  Scenario a = load_scenario(p), b = load_scenario(j);
  EXPECT_EQ(b.format, "crowddb");
  Simulation sa(std::move(a.world), a.config), sb(std::move(b.world), b.config);
  for (int k = 0; k < 50; ++k) ASSERT_EQ(sa.step().state_hash, sb.step().state_hash) << k;
}

TEST(SteerSuiteImport, InvertedWorldBoundsAndASceneBeyondThemAreWarnings) {
  const fs::path p = write_case("inverted.xml", header("-100 -200 -100 -200") + agent(0, 0, 5, 5) +
                                                    agent(3, 3, -5, -5) + "</SteerBenchTestCase>");
  Scenario sc = load_scenario(p);
  ASSERT_EQ(sc.warnings.size(), 2u);
  EXPECT_NE(sc.warnings[0].find("min > max"), std::string::npos) << sc.warnings[0];
  EXPECT_NE(sc.warnings[1].find("beyond worldBounds"), std::string::npos) << sc.warnings[1];
  // The world holds the scene.
  EXPECT_LE(sc.world.bounds().xmin, -5.5);
  EXPECT_GE(sc.world.bounds().xmax, 5.5);
}

TEST(SteerSuiteImport, BadFilesGiveOneLineNamingFileLineAndElement) {
  struct Case {
    std::string name, text, expect;
  };
  const std::string end = "</SteerBenchTestCase>";
  const std::vector<Case> cases = {
      {"malformed.xml", header() + "<agent>", "malformed XML"},
      {"root.xml", "<Other/>", "not a format crowddb reads"},
      {"unknown.xml", header() + "  <teleporter/>\n" + end, ":3: <teleporter>: unknown element"},
      {"minmax.xml",
       header() +
           "  <obstacle><xmin>5</xmin><xmax>1</xmax><ymin>0</ymin><ymax>1</ymax><zmin>0</zmin>"
           "<zmax>1</zmax></obstacle>\n" +
           end,
       ":3: <obstacle>: min > max in x"},
      {"missing.xml",
       header() +
           "  <obstacle><xmin>0</xmin><xmax>1</xmax><ymin>0</ymin><ymax>1</ymax>"
           "<zmin>0</zmin></obstacle>\n" +
           end,
       "<obstacle>: missing <zmax>"},
      {"number.xml",
       header() +
           "  <agent><initialConditions><radius>wide</radius><position><x>0</x><y>0</y>"
           "<z>0</z></position></initialConditions><goalSequence/></agent>\n" +
           end,
       ":3: <radius>: expected a number, got 'wide'"},
      {"goaltype.xml",
       header() +
           "  <agent><initialConditions><position><x>0</x><y>0</y><z>0</z></position>"
           "</initialConditions><goalSequence><fleeStaticTarget/></goalSequence></agent>\n" +
           end,
       "<fleeStaticTarget>: goal type not supported"},
      {"inside.xml",
       header() +
           "  <obstacle><xmin>-5</xmin><xmax>5</xmax><ymin>0</ymin><ymax>1</ymax><zmin>-5</zmin>"
           "<zmax>5</zmax></obstacle>\n" +
           agent(0, 0, 20, 20) + end,
       ":4: <agent>"},
      {"crowded.xml",
       header() +
           "  <agentRegion><numAgents>100</numAgents><regionBounds><xmin>0</xmin><xmax>2"
           "</xmax><ymin>0</ymin><ymax>0</ymax><zmin>0</zmin><zmax>2</zmax>"
           "</regionBounds><initialConditions><radius>0.5</radius></initialConditions>"
           "<goalSequence><seekStaticTarget><targetLocation><x>9</x><y>0</y><z>9</z>"
           "</targetLocation><desiredSpeed>1</desiredSpeed></seekStaticTarget>"
           "</goalSequence></agentRegion>\n" +
           end,
       "too crowded"},
      {"huge.xml",
       header() +
           "  <agentRegion><numAgents>100000000000</numAgents><regionBounds><xmin>0"
           "</xmin><xmax>2</xmax><ymin>0</ymin><ymax>0</ymax><zmin>0</zmin><zmax>2</zmax>"
           "</regionBounds><initialConditions/><goalSequence/></agentRegion>\n" +
           end,
       ""},
  };
  for (const Case& c : cases) {
    const fs::path p = write_case(c.name, c.text);
    const std::string e = import_error_of(p);
    EXPECT_NE(e, "") << c.name;
    EXPECT_EQ(e.rfind(p.string(), 0), 0u) << "does not start with the file: " << e;
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.name << ": " << e;
  }
}

}  // namespace
}  // namespace crowddb
