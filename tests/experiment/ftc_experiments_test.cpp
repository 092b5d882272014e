// `crowddb experiment e1|e2|e3 --quick` write their CSV tables and PNG plots, with the expected
// columns and sane values (the full runs are for the report; these only check the machinery).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli.hpp"

namespace crowddb {
namespace {

namespace fs = std::filesystem;

using Row = std::map<std::string, std::string>;

std::vector<Row> read_csv(const fs::path& path, std::vector<std::string>& header) {
  std::ifstream f(path);
  std::string line;
  std::vector<Row> rows;
  auto split = [](const std::string& s) {
    std::vector<std::string> cells;
    std::stringstream ss(s);
    std::string c;
    while (std::getline(ss, c, ',')) cells.push_back(c);
    if (!s.empty() && s.back() == ',') cells.emplace_back();
    return cells;
  };
  if (!std::getline(f, line)) return rows;
  header = split(line);
  while (std::getline(f, line)) {
    const auto cells = split(line);
    EXPECT_EQ(cells.size(), header.size()) << path << ": " << line;
    Row r;
    for (std::size_t i = 0; i < cells.size() && i < header.size(); ++i) r[header[i]] = cells[i];
    rows.push_back(r);
  }
  return rows;
}

double num(const Row& r, const std::string& key) {
  const auto it = r.find(key);
  if (it == r.end() || it->second.empty()) return NAN;
  return std::stod(it->second);
}

bool is_png(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  char magic[8] = {};
  f.read(magic, 8);
  return f && std::string(magic + 1, 3) == "PNG" && fs::file_size(p) > 5000;
}

// Runs `crowddb experiment NAME --quick` into a fresh folder.
struct Quick {
  explicit Quick(const std::string& name) {
    const auto r =
        test::run_cli("experiment " + name + " --quick --out " + (tmp / "out").string(), tmp);
    EXPECT_EQ(r.status, 0) << r.err;
  }
  fs::path dir() const { return tmp / "out"; }
  test::TempDir tmp;
};

TEST(FtcExperiments, E1Quick) {
  const Quick run("e1");
  const fs::path dir = run.dir();
  std::vector<std::string> head;
  const auto rows = read_csv(dir / "e1.csv", head);
  EXPECT_EQ(head, (std::vector<std::string>{"n", "runs", "build_ms", "build_2sd_ms", "query_ms",
                                            "query_2sd_ms", "total_ms", "total_2sd_ms",
                                            "naive_runs", "naive_ms", "naive_2sd_ms", "speedup",
                                            "nodes_per_query", "pops_per_query", "pairs_per_query",
                                            "mismatches", "wall_total_ms"}));
  ASSERT_EQ(rows.size(), 3u);
  for (const Row& r : rows) {
    EXPECT_GT(num(r, "build_ms"), 0);
    EXPECT_GT(num(r, "query_ms"), 0);
    EXPECT_NEAR(num(r, "total_ms"), num(r, "build_ms") + num(r, "query_ms"),
                1e-6 * num(r, "total_ms") + 1e-9);
    EXPECT_GE(num(r, "naive_runs"), 1);
    EXPECT_GT(num(r, "naive_ms"), 0);
    EXPECT_GT(num(r, "nodes_per_query"), 0);
    EXPECT_GE(num(r, "pops_per_query"), 0);
    EXPECT_EQ(num(r, "mismatches"), 0);  // the index agreed with naive on every checked run
  }
  const auto dense = read_csv(dir / "e1_density.csv", head);
  ASSERT_EQ(dense.size(), 2u);
  EXPECT_EQ(head.front(), "n");
  for (const Row& r : dense) EXPECT_GT(num(r, "total_ms"), 0);
  EXPECT_TRUE(is_png(dir / "e1.png"));
  EXPECT_TRUE(is_png(dir / "e1_density.png"));
}

TEST(FtcExperiments, E2Quick) {
  const Quick run("e2");
  const fs::path dir = run.dir();
  std::vector<std::string> head;
  const auto rows = read_csv(dir / "e2.csv", head);
  EXPECT_EQ(head,
            (std::vector<std::string>{"radii", "world", "method", "n", "runs", "total_ms",
                                      "total_2sd_ms", "build_ms", "query_ms", "nodes_per_query",
                                      "pops_per_query", "pairs_per_query", "mismatches"}));
  // 2 radii x (3 worlds x 2 indexed methods + 2 worlds x naive) x 2 sizes.
  EXPECT_EQ(rows.size(), 2u * (3 * 2 + 2) * 2);
  int naive_rows = 0;
  for (const Row& r : rows) {
    EXPECT_GT(num(r, "total_ms"), 0);
    if (r.at("method") == "naive") {
      ++naive_rows;
      EXPECT_EQ(num(r, "mismatches"), 0);
    } else {
      EXPECT_GT(num(r, "nodes_per_query"), 0);
    }
  }
  EXPECT_EQ(naive_rows, 8);
  EXPECT_TRUE(is_png(dir / "e2.png"));
}

TEST(FtcExperiments, E3Quick) {
  const Quick run("e3");
  const fs::path dir = run.dir();
  std::vector<std::string> head;
  const auto rows = read_csv(dir / "e3.csv", head);
  EXPECT_EQ(head, (std::vector<std::string>{
                      "radii", "world", "method", "n", "runs", "pops_per_query", "pops_2sd",
                      "pushes_per_query", "nodes_per_query", "pairs_per_query", "max_pops_query"}));
  EXPECT_EQ(rows.size(), 2u * 3 * 2 * 2);
  for (const Row& r : rows) {
    const double pops = num(r, "pops_per_query");
    EXPECT_GE(pops, 0);
    EXPECT_LE(pops, num(r, "pushes_per_query") + 1e-9);  // nothing is popped that was not pushed
    EXPECT_GE(num(r, "max_pops_query"), pops);
    // Best-first from the root sends every visited node through the queue.
    if (r.at("method") == "thesis") {
      EXPECT_GE(pops, num(r, "nodes_per_query") - 1e-9);
    }
  }
  EXPECT_TRUE(is_png(dir / "e3.png"));
}

}  // namespace
}  // namespace crowddb
