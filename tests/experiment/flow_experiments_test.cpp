// `crowddb experiment fd|bottleneck --quick` run end to end: CSV, summary and plot, with numbers
// that make physical sense (the quick sizes are too small to compare with data; docs/validation.md
// has the full runs).
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace crowddb::test
