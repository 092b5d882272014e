// `crowddb query collisions --method ...` and the backoff's part of `crowddb run`, end to end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "scenario/builders.hpp"
#include "support/cli.hpp"

namespace crowddb::test {
namespace {

int line_count(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

std::string agents_csv(const DiscTable& t) {
  std::string s = "id,x,y,vx,vy,radius\n";
  char buf[160];
  for (std::size_t i = 0; i < t.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%llu,%.17g,%.17g,0,0,%.17g\n",
                  static_cast<unsigned long long>(t.id[i]), t.x[i], t.y[i], t.radius[i]);
    s += buf;
  }
  return s;
}

std::vector<long> ids(const std::string& out) {
  std::vector<long> v;
  std::istringstream is(out);
  for (long x; is >> x;) v.push_back(x);
  return v;
}

TEST(CollisionsCli, EveryMethodOnTheContractExample) {
  TempDir dir;
  // 1-2 overlap, 3-4 touch exactly (not a collision), 9 alone.
  const auto f = dir.write("c.csv",
                           "id,x,y,vx,vy,radius\n2,1.5,0,0,0,1\n1,0,0,0,0,1\n3,10,0,0,0,1\n4,12,0,"
                           "0,0,1\n9,50,50,0,0,3\n");
  for (const char* m : {"naive", "grid", "sweep", "delaunay", "auto"}) {
    const CliResult r = run_cli("query collisions --agents " + f.string() + " --method " + m, dir);
    EXPECT_EQ(r.status, 0) << m << ": " << r.err;
    EXPECT_EQ(r.out, "1\n2\n") << m;
  }
  // nn needs equal radii: a usage error, one line, nothing on stdout.
  const CliResult nn = run_cli("query collisions --agents " + f.string() + " --method nn", dir);
  EXPECT_EQ(nn.status, 2);
  EXPECT_EQ(line_count(nn.err), 1) << nn.err;
  EXPECT_NE(nn.err.find("same radius"), std::string::npos) << nn.err;
  EXPECT_TRUE(nn.out.empty());
  const CliResult bogus =
      run_cli("query collisions --agents " + f.string() + " --method quadtree", dir);
  EXPECT_EQ(bogus.status, 2);
  for (const char* m : {"naive", "grid", "sweep", "nn", "delaunay"})
    EXPECT_NE(bogus.err.find(m), std::string::npos);
}

TEST(CollisionsCli, MethodsAgreeOnRandomTablesWithObstacles) {
  TempDir dir;
  DiscTable t = build::uniform(1500, build::Box{0, 0, 400, 400}, 1, 0.5, 6, 3);
  build::shuffle_ids(t, 4);
  const auto a = dir.write("a.csv", agents_csv(t));
  const auto o = dir.write("o.csv", "x,y,radius\n100,100,20\n300,250,35\n50,350,5\n");
  auto query = [&](const std::string& m, const std::string& file) {
    const CliResult r = run_cli(
        "query collisions --agents " + file + " --obstacles " + o.string() + " --method " + m, dir);
    EXPECT_EQ(r.status, 0) << m << ": " << r.err;
    return ids(r.out);
  };
  const auto want = query("naive", a.string());
  EXPECT_GT(want.size(), 300u);
  EXPECT_TRUE(std::is_sorted(want.begin(), want.end()));
  for (const char* m : {"grid", "sweep", "auto"}) EXPECT_EQ(query(m, a.string()), want) << m;
  const auto del = query("delaunay", a.string());
  EXPECT_TRUE(std::includes(want.begin(), want.end(), del.begin(), del.end()));

  const DiscTable eq = build::uniform(1500, build::Box{0, 0, 200, 200}, 1, 2, 2, 5);
  const auto e = dir.write("e.csv", agents_csv(eq));
  const auto want_eq = query("naive", e.string());
  EXPECT_GT(want_eq.size(), 300u);
  EXPECT_EQ(query("nn", e.string()), want_eq);
  EXPECT_EQ(query("grid", e.string()), want_eq);
}

TEST(RunCli, ExplainShowsTheCollisionPlanAndTheSummaryReportsGridlock) {
  TempDir dir;
  const std::string circle = source_path("scenarios/circle.json");
  const CliResult ex = run_cli("run " + circle + " --explain", dir);
  EXPECT_EQ(ex.status, 0) << ex.err;
  EXPECT_NE(ex.out.find("access path: grid"), std::string::npos) << ex.out;
  EXPECT_NE(ex.out.find("then nn"), std::string::npos) << ex.out;  // equal radii: nn once clean

  const CliResult run = run_cli("run " + circle + " --ticks 60 --no-output --quiet", dir);
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("gridlock (frozen 5 s in a row)"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("stalled (no progress for 2 s)"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("nudge: sidestep after 0.2 s frozen"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("freeze rounds per tick"), std::string::npos) << run.out;
  const CliResult off =
      run_cli("run " + circle + " --ticks 5 --no-output --quiet --nudge-after 0", dir);
  EXPECT_NE(off.out.find("nudge: off"), std::string::npos) << off.out;

  // nn cannot serve unequal radii: rejected before the run, as a usage error.
  const CliResult nn = run_cli(
      "run " + source_path("scenarios/bottleneck.json") + " --collisions nn --no-output", dir);
  EXPECT_EQ(nn.status, 2) << nn.err;
  EXPECT_EQ(line_count(nn.err), 1) << nn.err;
}

}  // namespace
}  // namespace crowddb::test
