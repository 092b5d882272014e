#include <gtest/gtest.h>

#include <cmath>

#include "crowddb/scenario.hpp"
#include "support/cli.hpp"

namespace crowddb {
namespace {

const char* kMinimal = R"({
  "bounds": [0, 0, 100, 100],
  "goals": [{"name": "g", "x": 90, "y": 50}],
  "agents": [{"x": 10, "y": 50, "radius": 1, "max_speed": 1, "goal": "g"}]
})";

std::string error_of(const std::string& text) {
  try {
    parse_scenario(text, "s.json");
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "not one line: " << e.what();
    return e.what();
  }
  return "";
}

TEST(ScenarioJson, MinimalFileHasDefaults) {
  Scenario sc = parse_scenario(kMinimal, "s.json");
  EXPECT_EQ(sc.world.agents().size(), 1u);
  EXPECT_EQ(sc.ticks, 100u);
  EXPECT_EQ(sc.config.dt, 1.0);
  EXPECT_TRUE(sc.config.backoff);
  EXPECT_EQ(sc.config.access.ftc, "auto");
  EXPECT_TRUE(std::isinf(sc.world.agents().max_accel[0]));
  EXPECT_TRUE(sc.warnings.empty());
}

TEST(ScenarioJson, SyntaxErrorNamesLineAndColumn) {
  const std::string e = error_of("{\n  \"bounds\": [0, 0, 1, 1],\n  \"ticks\": 5,,\n}");
  EXPECT_NE(e.find("s.json:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("malformed JSON"), std::string::npos) << e;
}

TEST(ScenarioJson, InvalidFieldsNameTheirPointer) {
  struct Case {
    std::string text, expect;
  };
  const std::string head =
      R"({"bounds": [0, 0, 100, 100], "goals": [{"name": "g", "x": 1, "y": 1}], )";
  const Case cases[] = {
      {head + R"("agents": [{"x": 1, "y": 1, "radius": 0, "goal": "g"}]})", "/agents/0/radius"},
      {head + R"("agents": [{"x": 1, "y": 1, "radius": -2, "goal": "g"}]})", "/agents/0/radius"},
      {head + R"("agents": [{"x": 1, "y": 1, "goal": "nowhere"}]})", "unknown goal 'nowhere'"},
      {head + R"("agents": [{"x": "NaN", "y": 1, "goal": "g"}]})",
       "/agents/0/x: expected a number"},
      {head + R"("agents": [{"x": 1e999, "y": 1, "goal": "g"}]})", "s.json"},
      {head + R"("agents": [{"x": 1, "y": 1, "goal": "g", "colour": "red"}]})",
       "/agents/0/colour: unknown key"},
      {head + R"("agents": [{"x": 1, "y": 1, "max_speed": -1, "goal": "g"}]})",
       "/agents/0/max_speed"},
      {head + R"("ticks": -5})", "/ticks"},
      {head + R"("dt": 0})", "/dt"},
      {head + R"("steering": {"horizon": 0}})", "/steering/horizon"},
      {head + R"("steering": {"potential": {"kernel": "gauss"}}})", "/steering/potential/kernel"},
      {head + R"("arrival": "teleport"})", "/arrival"},
      {head + R"("obstacles": [{"type": "polygon", "vertices": [[0,0],[2,2],[2,0],[0,2]]}]})",
       "/obstacles/0"},
      {head + R"("obstacles": [{"type": "circle", "x": 1, "y": 1, "radius": 0}]})",
       "/obstacles/0/radius"},
      {head +
           R"("groups": [{"count": 5, "placement": {"type": "grid", "region": [0,0,1,1], "spacing": 5}, "goal": "g"}]})",
       "the grid holds 1 agents"},
      {head +
           R"("groups": [{"count": 500, "radius": 3, "placement": {"type": "uniform", "region": [0,0,10,10]}, "goal": "g"}]})",
       "too crowded"},
      {R"({"bounds": [0, 0, -1, 1]})", "/bounds"},
      {R"({"bounds": [0, 0, 1, 1], "bounds": [0, 0, 2, 2]})", "duplicate key"},
      {R"({"ticks": 3})", "/bounds: missing"},
      {R"([1, 2])", "expected an object"},
  };
  for (const Case& c : cases) {
    const std::string e = error_of(c.text);
    EXPECT_NE(e.find(c.expect), std::string::npos) << "input: " << c.text << "\nerror: " << e;
    EXPECT_EQ(e.rfind("s.json", 0), 0u) << e;
  }
}

TEST(ScenarioJson, GroupsAreReproducibleAndOverlapFree) {
  const std::string text = R"({"bounds": [0, 0, 200, 200], "seed": 9,
    "goals": [{"name": "a", "x": 0, "y": 0}, {"name": "b", "x": 200, "y": 200}, {"name": "c", "x": 0, "y": 200}],
    "groups": [{"count": 300, "radius": [1, 3], "speed": [0, 5],
                "placement": {"type": "uniform", "region": [0, 0, 200, 200]},
                "goals": {"assign": "round_robin"}}]})";
  const Scenario a = parse_scenario(text, "s.json"), b = parse_scenario(text, "s.json");
  EXPECT_EQ(a.world.agents().x, b.world.agents().x);
  EXPECT_EQ(a.world.agents().vy, b.world.agents().vy);
  EXPECT_TRUE(a.warnings.empty());
  const AgentTable& t = a.world.agents();
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_EQ(t.goal[i], i % 3);
    EXPECT_GE(t.radius[i], 1.0);
    EXPECT_LE(t.radius[i], 3.0);
    EXPECT_LE(std::hypot(t.vx[i], t.vy[i]), 5.0 + 1e-12);
    for (std::size_t j = i + 1; j < t.size(); ++j)
      ASSERT_GE(std::hypot(t.x[i] - t.x[j], t.y[i] - t.y[j]), t.radius[i] + t.radius[j]);
  }
}

TEST(ScenarioJson, CircleWithAntipodalGoalsAndOverlapWarning) {
  const std::string text = R"({"bounds": [0, 0, 100, 100],
    "groups": [{"count": 40, "radius": 1, "placement": {"type": "circle", "center": [50, 50], "radius": 5},
                "goals": {"assign": "antipodal", "arrival_radius": 0.5}}]})";
  const Scenario sc = parse_scenario(text, "s.json");
  const AgentTable& t = sc.world.agents();
  ASSERT_EQ(t.size(), 40u);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const Goal& g = sc.world.goals()[t.goal[i]];
    EXPECT_NEAR(g.x, 100 - t.x[i], 1e-9);
    EXPECT_NEAR(g.y, 100 - t.y[i], 1e-9);
  }
  // 40 agents of radius 1 on a circle of circumference 31: they overlap, which is only a warning.
  ASSERT_EQ(sc.warnings.size(), 1u);
  EXPECT_NE(sc.warnings[0].find("overlapping"), std::string::npos);
}

TEST(ScenarioJson, ShippedScenariosLoadWithoutWarnings) {
  for (const char* name : {"airport", "circle", "crossing", "bottleneck"}) {
    const Scenario sc =
        load_scenario(test::source_path(std::string("scenarios/") + name + ".json"));
    EXPECT_EQ(sc.name, name);
    EXPECT_GT(sc.world.agents().size(), 0u);
    EXPECT_TRUE(sc.warnings.empty()) << name << ": " << sc.warnings.front();
  }
  const Scenario airport = load_scenario(test::source_path("scenarios/airport.json"));
  EXPECT_EQ(airport.world.agents().size(), 1000u);
  EXPECT_EQ(airport.world.circles().size(), 24u);
  EXPECT_EQ(airport.world.goals().size(), 12u);
  EXPECT_EQ(airport.ticks, 1000u);
}

TEST(ScenarioJson, MissingFileIsAnIoError) {
  try {
    load_scenario("/nonexistent/x.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::io);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.json"), std::string::npos);
  }
}

}  // namespace
}  // namespace crowddb
