// The crowddb CLI end to end: exit statuses, one-line errors, outputs.
#include "support/cli.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace crowddb::test {
namespace {

int lines(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

TEST(Cli, UsageErrorsExitWith2) {
  TempDir dir;
  for (const char* args :
       {"", "frobnicate", "run", "query", "query ftc --agents x.csv", "run x.json --ticks -3",
        "run x.json --threads 0", "query collisions --no-such-option",
        "query field --agents x.csv --kernel gauss"}) {
    const CliResult r = run_cli(args, dir);
    EXPECT_EQ(r.status, 2) << args << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
  }
}

// Numbers on the command line: NaN, infinities and fractions where a whole number is due are
// usage errors naming the option and the bound in plain words.
TEST(Cli, BadNumbersAreUsageErrorsInPlainWords) {
  TempDir dir;
  const auto sc = dir.write("walk.json", R"({"bounds": [0, 0, 10, 10], "duration": 1,
    "goals": [{"name": "g", "x": 8, "y": 5}], "agents": [{"x": 2, "y": 5, "goal": "g"}]})");
  const auto agents = dir.write("a.csv", "id,x,y,vx,vy,radius\n1,0,0,0,0,1\n");
  const std::string run = "run " + sc.string() + " --no-output --quiet ";
  const std::pair<std::string, std::string> cases[] = {
      {run + "--duration nan", "--duration: must be a finite number >= 0 and <= 1e9 (got nan)"},
      {run + "--nudge-after inf", "--nudge-after: must be a finite number >= 0"},
      {run + "--every 0", "--every: must be a whole number >= 1 (got 0)"},
      {run + "--every 2.5", "--every: must be a whole number >= 1 (got 2.5)"},
      {run + "--threads 300", "--threads: must be a whole number from 1 to 256 (got 300)"},
      {"query ftc --agents " + agents.string() + " --horizon nan",
       "--horizon: must be a finite number >= 0 and <= 1e9 (got nan)"},
      {"query ftc --agents " + agents.string() + " --horizon 1e12",
       "--horizon: must be a finite number >= 0 and <= 1e9 (got 1e12)"},
      {"bench " + sc.string() + " --duration -1", "--duration: must be a finite number >= 0"},
  };
  for (const auto& [args, message] : cases) {
    const CliResult r = run_cli(args, dir);
    EXPECT_EQ(r.status, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
  }
  EXPECT_EQ(run_cli(run + "--duration 0.5 --every 2", dir).status, 0);
}

// Errors the engine finds after loading (a navigation mesh that cannot be built) name the file
// and the field, in validate and run alike; 1e-300 used to overflow into "-9223372036854775808
// tiles at cell_size 0.000000".
TEST(Cli, NavigationMeshErrorsNameFileAndField) {
  TempDir dir;
  const auto scenario = [&](const std::string& navigation, const std::string& size) {
    return dir.write("nav.json", R"({"bounds": [0, 0, )" + size + ", " + size +
                                     R"(], "duration": 1, "navigation": )" + navigation + R"(,
      "obstacles": [{"type": "circle", "x": 50, "y": 50, "radius": 5}],
      "goals": [{"name": "g", "x": 80, "y": 50}], "agents": [{"x": 20, "y": 50, "goal": "g"}]})");
  };
  const std::tuple<std::string, std::string, std::string> cases[] = {
      {R"({"cell_size": 0.001})", "100",
       "nav.json: /navigation/cell_size: 0.001 is too small for agents of radius 0.25"},
      {R"({"cell_size": 1e-300})", "100", "nav.json: /navigation/cell_size: 1e-300 is too small"},
      {R"({"cell_size": 0.01, "tile_size": 16})", "1000",
       "nav.json: /navigation: the navigation mesh would need 39062500 tiles at cell_size 0.01"},
  };
  for (const auto& [navigation, size, message] : cases) {
    const auto file = scenario(navigation, size);
    for (const std::string command : {"validate ", "run --no-output "}) {
      const CliResult r = run_cli(command + file.string(), dir);
      EXPECT_EQ(r.status, 1) << command << navigation;
      EXPECT_NE(r.err.find(message), std::string::npos) << command << navigation << ": " << r.err;
      EXPECT_EQ(lines(r.err), 1) << r.err;
    }
  }
}

TEST(Cli, UnknownMethodIsAUsageError) {
  TempDir dir;
  const auto agents = dir.write("a.csv", "id,x,y,vx,vy,radius\n1,0,0,0,0,1\n");
  const CliResult r =
      run_cli("query ftc --horizon 3 --agents " + agents.string() + " --method psychic", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("psychic"), std::string::npos);
}

TEST(Cli, BadCsvFilesExitWith1NamingFileLineAndField) {
  TempDir dir;
  struct Case {
    std::string text, expect;
  };
  const Case cases[] = {
      {"id,x,y,vx,vy,radius\n1,0,0,0,0,-1\n", ":2: field radius"},
      {"id,x,y,vx,vy,radius\n1,0,0,0,0,1\n2,inf,0,0,0,1\n", ":3: field x"},
      {"id,x,y,vx,vy,radius\n1,0,0,nan,0,1\n", ":2: field vx"},
      // Beyond these ranges first-to-collide's arithmetic could overflow (query.hpp).
      {"id,x,y,vx,vy,radius\n1,0,0,1e160,0,1\n", ":2: field vx: must lie within +-1e9 (got 1e160)"},
      {"id,x,y,vx,vy,radius\n1,0,-2e9,0,0,1\n", ":2: field y: must lie within +-1e9"},
      {"id,x,y,vx,vy,radius\n1,0,0,0,0,1e300\n", ":2: field radius: must lie within +-1e9"},
      // A NUL byte used to cut a field short silently ("1\0junk" read as 1).
      {std::string("id,x,y,vx,vy,radius\n1,0,0,0,0,1\n2,5,0,0,0,1\0junk\n", 49),
       ":3: contains a NUL byte"},
      {"id,x,y,vx,vy,radius\n1,0,0,0,0\n", "line 2"},
      {"id,x,y,vx,vy\n1,0,0,0,0\n", "missing column 'radius'"},
      {"id,x,y,vx,vy,radius,mood\n1,0,0,0,0,1,happy\n", "mood"},
      {"id,x,y,vx,vy,radius\n-4,0,0,0,0,1\n", ":2: field id"},
      {"id,x,y,vx,vy,radius\n1,0,0,0,0,1\n1,2,2,0,0,1\n", "duplicate id 1"},
      {"", "a.csv"},
  };
  for (const Case& c : cases) {
    const auto agents = dir.write("a.csv", c.text);
    const CliResult r = run_cli("query collisions --agents " + agents.string(), dir);
    EXPECT_EQ(r.status, 1) << c.text;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(agents.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.text << " -> " << r.err;
    EXPECT_TRUE(r.out.empty());
  }
  // Devices and directories are refused at once (reading /dev/zero would never end).
  const std::string device_cases[] = {"validate /dev/zero", "run /dev/zero",
                                      "query collisions --agents /dev/zero",
                                      "validate " + dir.path().string()};
  for (const std::string& args : device_cases) {
    const CliResult r = run_cli(args, dir);
    EXPECT_EQ(r.status, 1) << args << ": " << r.err;
    EXPECT_TRUE(r.err.find("not a regular file") != std::string::npos ||
                r.err.find("is a directory") != std::string::npos)
        << args << ": " << r.err;
  }
  const CliResult missing =
      run_cli("query collisions --agents " + (dir / "nope.csv").string(), dir);
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("cannot open"), std::string::npos) << missing.err;
}

TEST(Cli, CrlfAndSpacesAndOptionalChargeAreAccepted) {
  TempDir dir;
  const auto agents = dir.write(
      "a.csv",
      "id, x, y, vx, vy, radius, charge\r\n2, 1.5, 0, 0, 0, 1, 2\r\n1, 0, 0, 0, 0, 1, 1\r\n");
  const CliResult r = run_cli("query collisions --agents " + agents.string(), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "1\n2\n");
}

TEST(Cli, QueryFieldWithObstaclesAndOutFile) {
  TempDir dir;
  const auto agents = dir.write("a.csv", "id,x,y,vx,vy,radius\n1,0,0,0,0,1\n");
  const auto obstacles = dir.write("o.csv", "x,y,radius,charge\n3,4,1,2\n");
  const CliResult r =
      run_cli("query field --kernel exp --metric l2 --A 1 --k 1 --agents " + agents.string() +
                  " --obstacles " + obstacles.string() + " --out " + (dir / "f.csv").string(),
              dir);
  EXPECT_EQ(r.status, 0) << r.err;
  // one charged point of charge 2 at Euclidean distance 5: 2 e^-5; gradient -k sign... = 2 e^-5 *
  // (3/5, 4/5)
  const std::string text = slurp(dir / "f.csv");
  EXPECT_EQ(text.rfind("id,potential,grad_x,grad_y\n1,", 0), 0u) << text;
  double pot, gx, gy;
  ASSERT_EQ(std::sscanf(text.c_str() + text.find("\n1,") + 3, "%lf,%lf,%lf", &pot, &gx, &gy), 3);
  EXPECT_NEAR(pot, 2 * std::exp(-5.0), 1e-15);
  EXPECT_NEAR(gx, 2 * std::exp(-5.0) * 0.6, 1e-15);
  EXPECT_NEAR(gy, 2 * std::exp(-5.0) * 0.8, 1e-15);
}

TEST(Cli, QueryFtcNamesObstaclesByRow) {
  TempDir dir;
  const auto agents = dir.write("a.csv", "id,x,y,vx,vy,radius\n4,0,0,1,0,1\n");
  const auto obstacles = dir.write("o.csv", "x,y,radius\n0,50,1\n10,0,1\n");
  const CliResult r = run_cli(
      "query ftc --horizon 30 --agents " + agents.string() + " --obstacles " + obstacles.string(),
      dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "id,first_id,time\n4,o1,8\n");
}

std::string tiny_scenario(const TempDir& dir) {
  return dir
      .write("s.json", R"({"name": "tiny", "bounds": [0, 0, 100, 100], "ticks": 20,
        "goals": [{"name": "g", "x": 90, "y": 50, "arrival_radius": 3}],
        "groups": [{"count": 30, "radius": 1, "max_speed": 2,
                    "placement": {"type": "uniform", "region": [5, 5, 40, 95]}, "goal": "g"}]})")
      .string();
}

TEST(Cli, RunWritesSqliteAndSummary) {
  TempDir dir;
  const std::string sc = tiny_scenario(dir);
  const auto out = dir / "t.sqlite";
  const CliResult r = run_cli("run " + sc + " --out " + out.string(), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("tiny: 20 ticks"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("final state hash"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(out));
  EXPECT_TRUE(r.err.empty()) << r.err;  // no progress line when stderr is not a terminal
}

TEST(Cli, RunHashDoesNotDependOnThreads) {
  TempDir dir;
  const std::string sc = tiny_scenario(dir);
  const CliResult one = run_cli("run " + sc + " --no-output --threads 1", dir);
  const CliResult two = run_cli("run " + sc + " --no-output --threads 2", dir);
  auto hash = [](const std::string& s) { return s.substr(s.find("final state hash"), 34); };
  ASSERT_EQ(one.status, 0);
  ASSERT_EQ(two.status, 0);
  EXPECT_EQ(hash(one.out), hash(two.out));
}

TEST(Cli, RunExplainPrintsThePlanWithoutRunning) {
  TempDir dir;
  const CliResult r =
      run_cli("run " + tiny_scenario(dir) + " --explain --out " + (dir / "x.sqlite").string(), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("TICK PLAN"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.sqlite"));
}

TEST(Cli, RunToAnUnwritablePathFailsCleanly) {
  TempDir dir;
  const CliResult r =
      run_cli("run " + tiny_scenario(dir) + " --out /nonexistent-dir/t.sqlite", dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("/nonexistent-dir/t.sqlite"), std::string::npos) << r.err;
}

TEST(Cli, BadScenarioIsOneLineAndNoOutputIsLeft) {
  TempDir dir;
  const auto sc =
      dir.write("bad.json", R"({"bounds": [0, 0, 10, 10], "goals": [{"name": "g", "x": 1, "y": 1}],
    "agents": [{"x": 1, "y": 1, "radius": 0, "goal": "g"}]})");
  const CliResult r = run_cli("run " + sc.string() + " --out " + (dir / "o.sqlite").string(), dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("/agents/0/radius"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "o.sqlite"));
  const CliResult v = run_cli("validate " + sc.string(), dir);
  EXPECT_EQ(v.status, 1);
  EXPECT_EQ(v.err, r.err);
}

TEST(Cli, OverlappingSpawnIsAWarningAndTheRunGoesOn) {
  TempDir dir;
  const auto sc = dir.write("o.json", R"({"bounds": [0, 0, 100, 100], "ticks": 3,
    "goals": [{"name": "g", "x": 90, "y": 50}],
    "agents": [{"x": 10, "y": 50, "radius": 1, "goal": "g"}, {"x": 11, "y": 50, "radius": 1, "goal": "g"}]})");
  const CliResult r = run_cli("run " + sc.string() + " --no-output", dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("overlapping"), std::string::npos) << r.err;
}

TEST(Cli, ValidateShippedScenarios) {
  TempDir dir;
  for (const char* name : {"airport", "circle", "crossing", "bottleneck"}) {
    const CliResult r =
        run_cli("validate " + source_path(std::string("scenarios/") + name + ".json"), dir);
    EXPECT_EQ(r.status, 0) << name << ": " << r.err;
    EXPECT_NE(r.out.find(": ok: "), std::string::npos) << r.out;
  }
}

}  // namespace
}  // namespace crowddb::test
