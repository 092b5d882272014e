// `crowddb experiment fd|bottleneck --quick` run end to end: CSV, summary and plot, with numbers
// that make physical sense (the quick sizes are too small to compare with data; docs/validation.md
// has the full runs).
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>

#include "support/cli.hpp"

namespace crowddb::test {
namespace {

std::vector<std::vector<std::string>> csv_rows(const std::filesystem::path& p) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(slurp(p));
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::istringstream ls(line);
    std::string c;
    while (std::getline(ls, c, ',')) cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

TEST(FlowExperiments, FundamentalDiagramQuick) {
  TempDir dir;
  const CliResult r = run_cli("experiment fd --quick --out " + (dir / "out").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = csv_rows(dir / "out" / "fd.csv");
  ASSERT_EQ(rows.size(), 1u + 2 * 2);  // models (orca, cfsm) x densities (1, 3)
  EXPECT_EQ(rows[0][2], "density");
  for (std::size_t i = 1; i < rows.size(); i += 2) {
    const double v_low = std::stod(rows[i][3]), v_high = std::stod(rows[i + 1][3]);
    EXPECT_GT(v_low, v_high) << rows[i][0] << ": the denser ring must walk slower";
    EXPECT_GT(v_high, 0) << rows[i][0] << ": a ring at 3 per m^2 still moves";
    EXPECT_LT(v_low, 1.5);
  }
  EXPECT_GT(std::filesystem::file_size(dir / "out" / "fd.png"), 1000u);
}

TEST(FlowExperiments, BottleneckQuick) {
  TempDir dir;
  const CliResult r = run_cli("experiment bottleneck --quick --out " + (dir / "out").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = csv_rows(dir / "out" / "bottleneck.csv");
  ASSERT_EQ(rows.size(), 1u + 2 * 2);  // models x widths (1, 2 m)
  for (std::size_t i = 1; i < rows.size(); i += 2) {
    EXPECT_EQ(rows[i][5], rows[i][4]) << "everyone passed";
    EXPECT_GT(std::stod(rows[i + 1][2]), std::stod(rows[i][2]))
        << rows[i][0] << ": wider, more flow";
  }
  EXPECT_GT(std::filesystem::file_size(dir / "out" / "bottleneck.png"), 1000u);
}

// --model picks the models and --set reaches every run: a 2 s time gap keeps people about 2.6 m
// apart at full speed, so the ring at 1 per m^2 walks far below its 1.07 m/s without it.
TEST(FlowExperiments, ModelAndSetReachTheRuns) {
  TempDir dir;
  const CliResult r =
      run_cli("experiment fd --quick --model orca --set steering.orca.time_gap=2 --out " +
                  (dir / "out").string(),
              dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = csv_rows(dir / "out" / "fd.csv");
  ASSERT_EQ(rows.size(), 1u + 2);  // orca x densities (1, 3)
  EXPECT_EQ(rows[1][0], "orca");
  EXPECT_LT(std::stod(rows[1][3]), 0.8) << "the time gap was not applied";
  const CliResult e1 =
      run_cli("experiment e1 --quick --set seed=2 --out " + (dir / "e1").string(), dir);
  EXPECT_EQ(e1.status, 2);
  EXPECT_NE(e1.err.find("not to e1"), std::string::npos) << e1.err;
  const CliResult model =
      run_cli("experiment fd --quick --set steering.model=cfsm --out " + (dir / "m").string(), dir);
  EXPECT_EQ(model.status, 2);
  EXPECT_NE(model.err.find("pick models with --model"), std::string::npos) << model.err;
}

// --seeds K runs every case with K seeds and reports the mean flow and its range: the mean of
// seeds 1 and 2 is the mean of the two single-seed runs, and only the bottleneck takes it.
TEST(FlowExperiments, BottleneckAveragesOverSeeds) {
  TempDir dir;
  auto run = [&](const std::string& args, const std::string& out) {
    const CliResult r = run_cli(
        "experiment bottleneck --quick --model orca " + args + " --out " + (dir / out).string(),
        dir);
    EXPECT_EQ(r.status, 0) << r.err;
    return csv_rows(dir / out / "bottleneck.csv");
  };
  const auto one = run("--seed 1", "s1"), two = run("--seed 2", "s2");
  const auto both = run("--seed 1 --seeds 2", "both");
  ASSERT_EQ(both.size(), 3u);  // header + widths (1, 2 m)
  EXPECT_EQ(both[0][7], "flow_min");
  for (std::size_t i = 1; i < both.size(); ++i) {
    const double a = std::stod(one[i][2]), b = std::stod(two[i][2]);
    EXPECT_NEAR(std::stod(both[i][2]), (a + b) / 2, 1e-5) << "width " << both[i][1];
    EXPECT_NEAR(std::stod(both[i][7]), std::min(a, b), 1e-5);
    EXPECT_NEAR(std::stod(both[i][8]), std::max(a, b), 1e-5);
    EXPECT_EQ(both[i][4], "120");  // 60 people x 2 seeds
    EXPECT_EQ(both[i][9], "2");
  }
  const CliResult fd =
      run_cli("experiment fd --quick --seeds 2 --out " + (dir / "fd").string(), dir);
  EXPECT_EQ(fd.status, 2);
  EXPECT_NE(fd.err.find("--seeds applies to the bottleneck experiment"), std::string::npos)
      << fd.err;
  const CliResult zero =
      run_cli("experiment bottleneck --quick --seeds 0 --out " + (dir / "z").string(), dir);
  EXPECT_EQ(zero.status, 2);
  EXPECT_NE(zero.err.find("--seeds"), std::string::npos) << zero.err;
}

}  // namespace
}  // namespace crowddb::test
