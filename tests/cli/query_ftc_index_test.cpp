// `crowddb query ftc --method index` gives byte-for-byte the output of `--method naive` (same
// collider and the same shortest round-trip time text), with obstacles, ties and any thread count.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "scenario/builders.hpp"
#include "support/cli.hpp"
#include "util/rng.hpp"

namespace crowddb {
namespace {

void write_agents(const std::filesystem::path& path, const DiscTable& t) {
  std::ofstream f(path);
  f.precision(17);
  f << "id,x,y,vx,vy,radius\n";
  for (std::size_t i = 0; i < t.size(); ++i)
    f << t.id[i] << "," << t.x[i] << "," << t.y[i] << "," << t.vx[i] << "," << t.vy[i] << ","
      << t.radius[i] << "\n";
}

TEST(QueryFtcCli, IndexPrintsExactlyWhatNaivePrints) {
  test::TempDir dir;
  DiscTable t = build::uniform(1500, {}, 50, 1, 3, 17);
  build::shuffle_ids(t, 5);  // ids not in row order: output order and tie-breaks by id
  const DiscTable lat = build::lattice(400, 4, 1, 1, 3);  // exact ties in time
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
  const auto naive = test::run_cli(common + " --method naive", dir);
  ASSERT_EQ(naive.status, 0) << naive.err;
  ASSERT_GT(naive.out.size(), 1000u);
  EXPECT_NE(naive.out.find(",o"), std::string::npos) << "no agent hits an obstacle: weak test";
  for (const std::string threads : {"1", "2"}) {
    const auto index = test::run_cli(common + " --method index --threads " + threads, dir);
    ASSERT_EQ(index.status, 0) << index.err;
    EXPECT_TRUE(index.out == naive.out)
        << "index output differs from naive (threads " << threads << ")";
  }
  const auto planner = test::run_cli(common, dir);  // auto picks the index at this size
  EXPECT_TRUE(planner.out == naive.out);
}

TEST(QueryFtcCli, UnknownMethodNamesTheChoices) {
  test::TempDir dir;
  write_agents(dir / "a.csv", build::uniform(5, {}, 1, 1, 1, 1));
  const auto r = test::run_cli(
      "query ftc --agents " + (dir / "a.csv").string() + " --horizon 30 --method kdtree", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("index"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace crowddb
