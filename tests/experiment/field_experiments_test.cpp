// `crowddb experiment e4|e5 --quick` run end to end and write their CSV, summary and plot.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "support/cli.hpp"

namespace crowddb::test {
namespace {

std::vector<std::vector<std::string>> read_csv(const std::filesystem::path& p) {
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

TEST(FieldExperiments, E5QuickComparesIndexAndNaive) {
  TempDir dir;
  const CliResult r = run_cli("experiment e5 --quick --out " + (dir / "out").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_csv(dir / "out" / "e5.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0][0], "n");
  for (std::size_t i = 1; i < rows.size(); ++i) {
    EXPECT_GT(std::stod(rows[i][4]), 0) << "index cpu seconds";
    EXPECT_GT(std::stod(rows[i][6]), 0) << "naive cpu seconds";
    EXPECT_LE(std::stod(rows[i][8]), 1.0) << "index outside DESIGN tolerance";
  }
  EXPECT_TRUE(std::filesystem::file_size(dir / "out" / "e5.png") > 1000);
  EXPECT_NE(slurp(dir / "out" / "e5.txt").find("load"), std::string::npos);
}

TEST(FieldExperiments, E4QuickRunsTheSixFunctions) {
  TempDir dir;
  const CliResult r = run_cli("experiment e4 --quick --out " + (dir / "out").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto summary = read_csv(dir / "out" / "e4.csv");
  ASSERT_EQ(summary.size(), 3u);
  ASSERT_EQ(summary[0].size(), 14u);
  EXPECT_EQ(summary[0][2], "exp-l1_mean");
  EXPECT_EQ(summary[0][13], "inv-radial_2sd");
  const auto runs = read_csv(dir / "out" / "e4_runs.csv");
  EXPECT_EQ(runs.size(), 1u + 2 * 6 * 2);  // densities x functions x seeds
  for (std::size_t i = 1; i < summary.size(); ++i)
    for (std::size_t c = 2; c < 14; ++c) EXPECT_TRUE(std::isfinite(std::stod(summary[i][c])));
  EXPECT_TRUE(std::filesystem::file_size(dir / "out" / "e4.png") > 1000);
}

}  // namespace
}  // namespace crowddb::test
