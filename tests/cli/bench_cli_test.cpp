// `crowddb bench`, `crowddb convert` and `crowddb run --summary-json` end to end.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "support/cli.hpp"

namespace crowddb::test {
namespace {

const char* kWalk = R"({"name": "walk", "bounds": [0, 0, 20, 10], "duration": 30,
  "stop_when_all_arrived": true,
  "goals": [{"name": "g", "x": 15, "y": 5, "arrival_radius": 0.3}],
  "agents": [{"x": 5, "y": 5, "goal": "g", "pref_speed": 1}]})";

const char* kCase = R"(<SteerBenchTestCase xmlns="http://www.magix.ucla.edu/steerbench">
  <header><name>pair</name><worldBounds><xmin>-20</xmin><xmax>20</xmax><ymin>0</ymin><ymax>0</ymax>
    <zmin>-20</zmin><zmax>20</zmax></worldBounds></header>
  <agent><initialConditions><radius>0.5</radius><position><x>-10</x><y>0</y><z>0</z></position>
    <direction><x>1</x><y>0</y><z>0</z></direction><speed>0</speed></initialConditions>
    <goalSequence><seekStaticTarget><targetLocation><x>10</x><y>0</y><z>0</z></targetLocation>
    <desiredSpeed>1.3</desiredSpeed></seekStaticTarget></goalSequence></agent>
  <agent><initialConditions><radius>0.5</radius><position><x>10</x><y>0</y><z>0.1</z></position>
    <direction><x>-1</x><y>0</y><z>0</z></direction><speed>0</speed></initialConditions>
    <goalSequence><seekStaticTarget><targetLocation><x>-10</x><y>0</y><z>0.1</z></targetLocation>
    <desiredSpeed>1.3</desiredSpeed></seekStaticTarget></goalSequence></agent>
</SteerBenchTestCase>)";

TEST(SummaryJson, KeysAgreeWithTheRun) {
  TempDir dir;
  const auto sc = dir.write("walk.json", kWalk);
  const CliResult r = run_cli("run " + sc.string() + " --summary-json " +
                                  (dir / "s.json").string() + " --no-output --quiet",
                              dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(dir / "s.json"));
  for (const char* k : {"agents_total", "arrived", "all_arrived", "last_arrival_s", "sim_seconds",
                        "ticks", "max_overlapping_pairs", "max_obstacle_overlaps", "stalled_at_end",
                        "max_stalled_s", "frozen_agent_ticks", "wall_seconds", "ms_per_tick_median",
                        "state_hash", "steerbench", "model", "without_path"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["agents_total"], 1);
  EXPECT_EQ(j["arrived"], 1);
  EXPECT_EQ(j["all_arrived"], true);
  EXPECT_EQ(j["stopped_when_all_arrived"], true);
  // 9.7 m at 1 m/s: the run ends at the tick of the arrival.
  const double last = j["last_arrival_s"];
  EXPECT_NEAR(last, 9.7, 0.11);
  EXPECT_NEAR(j["sim_seconds"].get<double>(), last, 1e-9);
  EXPECT_EQ(j["model"], "orca");
  EXPECT_EQ(j["steerbench"]["agents"], 1);
  EXPECT_EQ(j["steerbench"]["collisions"], 0);
  // SteerBench's time stops before the arrival tick; the agent walked about 9.7 m.
  EXPECT_NEAR(j["steerbench"]["avg_time_s"].get<double>(), last - 0.1, 1e-6);
  EXPECT_NEAR(j["steerbench"]["avg_path_length_m"].get<double>(), 9.6, 0.15);
  // "-": the JSON on standard output, no text summary.
  const CliResult s = run_cli("run " + sc.string() + " --summary-json - --no-output --quiet", dir);
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_EQ(nlohmann::json::parse(s.out)["state_hash"], j["state_hash"]);
}

// A goal walled in on every side: its agent's route ends short of it, and the summary says so
// (the one whose goal is open arrives and is not counted).
TEST(SummaryJson, AgentsWithNoPathToTheirGoalAreCounted) {
  TempDir dir;
  const auto sc = dir.write("walled.json", R"({"name": "walled", "bounds": [0, 0, 20, 10],
    "duration": 20, "navigation": {},
    "goals": [{"name": "open", "x": 4, "y": 8, "arrival_radius": 0.3},
              {"name": "closed", "x": 15, "y": 5, "arrival_radius": 0.3}],
    "obstacles": [{"type": "polygon", "vertices": [[13, 3], [17, 3], [17, 3.3], [13, 3.3]]},
                  {"type": "polygon", "vertices": [[13, 6.7], [17, 6.7], [17, 7], [13, 7]]},
                  {"type": "polygon", "vertices": [[13, 3.3], [13.3, 3.3], [13.3, 6.7], [13, 6.7]]},
                  {"type": "polygon", "vertices": [[16.7, 3.3], [17, 3.3], [17, 6.7], [16.7, 6.7]]}],
    "agents": [{"x": 2, "y": 5, "goal": "closed"}, {"x": 2, "y": 2, "goal": "open"}]})");
  const CliResult r = run_cli("run " + sc.string() + " --no-output --quiet", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("1 of them with no path to their goal"), std::string::npos) << r.out;
  const CliResult j = run_cli("run " + sc.string() + " --summary-json - --no-output --quiet", dir);
  ASSERT_EQ(j.status, 0) << j.err;
  const auto s = nlohmann::json::parse(j.out);
  EXPECT_EQ(s["arrived"], 1);
  EXPECT_EQ(s["still_walking"], 1);
  EXPECT_EQ(s["without_path"], 1);
  // Without navigation nothing is planned, so nothing is counted.
  const CliResult n =
      run_cli("run " + sc.string() + " --no-navigation --summary-json - --no-output --quiet", dir);
  ASSERT_EQ(n.status, 0) << n.err;
  EXPECT_EQ(nlohmann::json::parse(n.out)["without_path"], 0);
}

TEST(Convert, ImportedFileConvertsToAScenarioThatRunsTheSame) {
  TempDir dir;
  const auto xml = dir.write("pair.xml", kCase);
  const CliResult c = run_cli("convert " + xml.string() + " --to json", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  const auto json = dir.write("pair.json", c.out);
  const CliResult a = run_cli("run " + xml.string() + " --summary-json - --no-output --quiet", dir);
  const CliResult b =
      run_cli("run " + json.string() + " --summary-json - --no-output --quiet", dir);
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  const auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(ja["state_hash"], jb["state_hash"]);
  EXPECT_EQ(ja["format"], "steersuite");
  EXPECT_EQ(jb["format"], "crowddb");
  EXPECT_EQ(ja["arrived"], 2);
  const CliResult bad = run_cli("convert " + xml.string() + " --to yaml", dir);
  EXPECT_EQ(bad.status, 2);
}

// --set changes the run of a crowddb file and of an import alike; a bad value names its field.
TEST(Set, OverridesReachEveryFormatAndBadValuesNameTheirField) {
  TempDir dir;
  const auto sc = dir.write("walk.json", kWalk);
  const auto xml = dir.write("pair.xml", kCase);
  for (const auto& file : {sc, xml}) {
    const CliResult a =
        run_cli("run " + file.string() + " --summary-json - --no-output --quiet", dir);
    const CliResult b = run_cli(
        "run " + file.string() + " --set steering.model=cfsm --summary-json - --no-output --quiet",
        dir);
    ASSERT_EQ(a.status, 0) << a.err;
    ASSERT_EQ(b.status, 0) << b.err;
    EXPECT_EQ(nlohmann::json::parse(a.out)["model"], "orca");
    EXPECT_EQ(nlohmann::json::parse(b.out)["model"], "cfsm");
  }
  const CliResult c = run_cli("convert " + xml.string() + " --set steering.orca.time_gap=0.5", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_EQ(nlohmann::json::parse(c.out)["steering"]["orca"]["time_gap"], 0.5);
  const CliResult bad =
      run_cli("validate " + sc.string() + " --set steering.orca.time_gap=-1", dir);
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("/steering/orca/time_gap: must be >= 0"), std::string::npos) << bad.err;
  const CliResult usage = run_cli("bench " + sc.string() + " --set steering", dir);
  EXPECT_EQ(usage.status, 2);
  EXPECT_NE(usage.err.find("--set 'steering': expected KEY=VALUE"), std::string::npos) << usage.err;
}

// A folder laid out as Menge's examples (projects beside folders holding their scene, behaviour
// and viewer files) gives one row per project: the scenes the projects name, the behaviours and
// the <View> files are not scenarios of their own.
TEST(Bench, MengeFoldersGiveOneRowPerProject) {
  TempDir dir;
  namespace fs = std::filesystem;
  fs::copy(fs::path(CROWDDB_SOURCE_DIR) / "tests/data/import/menge/core", dir / "core",
           fs::copy_options::recursive);
  dir.write("core/4square/4squareV.xml", "<?xml version=\"1.0\"?>\n<View width=\"640\"/>\n");
  const CliResult r = run_cli("bench " + (dir / "core").string() + " --duration 1 --quiet", dir);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("3 scenarios: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0 failed"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("4squareS.xml"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("4squareV.xml"), std::string::npos) << r.out;
}

TEST(Bench, OneRowPerScenarioAndErrorsDoNotStopTheOthers) {
  TempDir dir;
  std::filesystem::create_directories(dir / "set");
  dir.write("set/walk.json", kWalk);
  dir.write("set/pair.xml", kCase);
  dir.write("set/broken.json", "{\"bounds\": [0, 0, 1]}");
  const CliResult r = run_cli(
      "bench " + (dir / "set").string() + " --quiet --csv " + (dir / "b.csv").string(), dir);
  EXPECT_EQ(r.status, 1) << r.err;  // one scenario failed
  EXPECT_NE(r.out.find("3 scenarios: 2 with everyone arrived, 0 with someone left, 1 failed"),
            std::string::npos)
      << r.out;
  const std::string csv = slurp(dir / "b.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4) << csv;
  EXPECT_NE(csv.find("broken.json,,,,error,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",steersuite,pair,orca,ok,2,2,1,"), std::string::npos) << csv;
  EXPECT_FALSE(std::filesystem::exists(dir / "b.csv.partial"));
  const CliResult missing = run_cli("bench " + (dir / "nothing").string(), dir);
  EXPECT_EQ(missing.status, 1);
}

}  // namespace
}  // namespace crowddb::test
