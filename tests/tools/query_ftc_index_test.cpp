// `crowddb query ftc --method index` gives byte-for-byte the output of `--method naive` (same
// collider and the same shortest round-trip time text), with obstacles, ties and any thread count.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "scenario/builders.hpp"
#include "util/rng.hpp"

namespace crowddb {
namespace {

namespace fs = std::filesystem;

struct Result {
  int status = -1;
  std::string out;
};

Result run(const std::string& args) {
  Result r;
  const std::string cmd = std::string(CROWDDB_CLI) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t got;
  while ((got = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, got);
  r.status = pclose(p);
  return r;
}

fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("crowddb_ftc_cli_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

void write_agents(const fs::path& path, const DiscTable& t) {
  std::ofstream f(path);
  f.precision(17);
  f << "id,x,y,vx,vy,radius\n";
  for (std::size_t i = 0; i < t.size(); ++i)
    f << t.id[i] << "," << t.x[i] << "," << t.y[i] << "," << t.vx[i] << "," << t.vy[i] << ","
      << t.radius[i] << "\n";
}

TEST(QueryFtcCli, IndexPrintsExactlyWhatNaivePrints) {
  const fs::path dir = temp_dir();
  DiscTable t = build::uniform(1500, {}, 50, 1, 3, 17);
  build::shuffle_ids(t, 5);  // ids not in row order: output order and tie-breaks by id
  DiscTable lat = build::lattice(400, 4, 1, 1, 3);  // exact ties in time
  for (std::size_t i = 0; i < lat.size(); ++i)
    t.push_back(100000 + i, 700 + lat.x[i], lat.y[i], lat.vx[i], lat.vy[i], lat.radius[i]);
  write_agents(dir / "agents.csv", t);
  {
    Rng rng(3);
    std::ofstream f(dir / "obstacles.csv");
    f.precision(17);
    f << "x,y,radius\n";
    for (int i = 0; i < 30; ++i)
      f << rng.uniform(0, 640) << "," << rng.uniform(0, 480) << "," << rng.uniform(2, 20) << "\n";
  }
  const std::string common = "query ftc --agents " + (dir / "agents.csv").string() +
                             " --obstacles " + (dir / "obstacles.csv").string() + " --horizon 30";
  const Result naive = run(common + " --method naive");
  ASSERT_EQ(naive.status, 0) << naive.out;
  ASSERT_GT(naive.out.size(), 1000u);
  EXPECT_NE(naive.out.find(",o"), std::string::npos) << "no agent hits an obstacle: weak test";
  for (const std::string threads : {"1", "2"}) {
    const Result index = run(common + " --method index --threads " + threads);
    ASSERT_EQ(index.status, 0) << index.out;
    EXPECT_TRUE(index.out == naive.out)
        << "index output differs from naive (threads " << threads << ")";
  }
  const Result planner = run(common);  // auto picks the index at this size
  EXPECT_TRUE(planner.out == naive.out);
  fs::remove_all(dir);
}

TEST(QueryFtcCli, UnknownMethodIsAUsageError) {
  const fs::path dir = temp_dir();
  write_agents(dir / "a.csv", build::uniform(5, {}, 1, 1, 1, 1));
  const Result r =
      run("query ftc --agents " + (dir / "a.csv").string() + " --horizon 30 --method kdtree");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("index"), std::string::npos) << r.out;  // names the valid choices
  fs::remove_all(dir);
}

}  // namespace
}  // namespace crowddb
