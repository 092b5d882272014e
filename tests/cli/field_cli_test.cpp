// `crowddb query field --method index|naive` agree within DESIGN.md §4's tolerance on CSV files
// (random, lattice ties, duplicates, far-offset coordinates, obstacles); `crowddb fit-kernel`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <vector>

#include "support/cli.hpp"
#include "util/rng.hpp"

namespace crowddb::test {
namespace {

struct Row {
  double pot, gx, gy;
};

std::map<long, Row> parse_field(const std::string& csv) {
  std::map<long, Row> rows;
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "id,potential,grad_x,grad_y");
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    long id = 0;
    Row r{};
    EXPECT_EQ(std::sscanf(line.c_str(), "%ld,%lf,%lf,%lf", &id, &r.pot, &r.gx, &r.gy), 4) << line;
    rows[id] = r;
  }
  return rows;
}

std::string agents_csv(const std::vector<std::array<double, 3>>& xyc) {
  std::string s = "id,x,y,vx,vy,radius,charge\n";
  char buf[160];
  for (std::size_t i = 0; i < xyc.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%zu,%.17g,%.17g,0,0,1,%.17g\n", (i * 7919) % 100003, xyc[i][0],
                  xyc[i][1], xyc[i][2]);
    s += buf;
  }
  return s;
}

void expect_methods_agree(const std::string& agents, const std::string& obstacles,
                          const std::string& metric, double k, const TempDir& dir) {
  const std::string common =
      "query field --agents " + agents + (obstacles.empty() ? "" : " --obstacles " + obstacles) +
      " --kernel exp --metric " + metric + " --A 0.929328 --k " + std::to_string(k);
  const CliResult naive = run_cli(common + " --method naive", dir);
  const CliResult index = run_cli(common + " --method index", dir);
  ASSERT_EQ(naive.status, 0) << naive.err;
  ASSERT_EQ(index.status, 0) << index.err;
  const auto a = parse_field(naive.out), b = parse_field(index.out);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_FALSE(a.empty());
  int bad = 0;
  for (const auto& [id, r] : a) {
    ASSERT_TRUE(b.count(id)) << id;
    const Row& s = b.at(id);
    // Charges are positive here, so the naive potential is S_abs; c_max <= 3.
    const double tol = 1e-9 * r.pot + 1e-12 * 0.929328 * 9;
    if (std::abs(s.pot - r.pot) > tol || std::abs(s.gx - r.gx) > k * tol ||
        std::abs(s.gy - r.gy) > k * tol)
      if (++bad < 4)
        ADD_FAILURE() << agents << " " << metric << " id " << id << ": " << s.pot << " vs "
                      << r.pot;
  }
  EXPECT_EQ(bad, 0);
}

TEST(FieldCli, IndexAgreesWithNaiveOnFiles) {
  TempDir dir;
  Rng rng(17);
  std::vector<std::array<double, 3>> uniform, lattice, offset, dup;
  for (int i = 0; i < 400; ++i)
    uniform.push_back({rng.uniform(0, 120), rng.uniform(0, 90), rng.uniform(0.5, 3)});
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) lattice.push_back({i * 1.0, j * 1.0, 1.0 + (i + j) % 3});
  for (int i = 0; i < 300; ++i)
    offset.push_back({1e6 + rng.uniform(0, 80), -1e6 + std::floor(rng.uniform(0, 40)) * 0.5, 1.0});
  for (int i = 0; i < 300; ++i)
    dup.push_back({static_cast<double>(i % 7), static_cast<double>((i % 7) * 2), 1.0});
  const std::string files[] = {dir.write("uniform.csv", agents_csv(uniform)).string(),
                               dir.write("lattice.csv", agents_csv(lattice)).string(),
                               dir.write("offset.csv", agents_csv(offset)).string(),
                               dir.write("dup.csv", agents_csv(dup)).string()};
  const auto obstacles =
      dir.write("obstacles.csv", "x,y,radius,charge\n30,30,5,2\n3,4,1,1\n1000040,-999990,4,1\n");
  for (const std::string& f : files)
    for (const char* metric : {"l1", "radial"}) {
      expect_methods_agree(f, "", metric, 0.272194, dir);
      expect_methods_agree(f, obstacles.string(), metric, 1.5, dir);
    }
}

TEST(FieldCli, IndexRefusesKernelsItCannotSumExactly) {
  TempDir dir;
  const auto agents = dir.write("a.csv", "id,x,y,vx,vy,radius\n1,0,0,0,0,1\n2,1,1,0,0,1\n");
  for (const char* args :
       {" --kernel exp --metric l2", " --kernel inv --metric l1", " --metric radial --frames 3"}) {
    const CliResult r =
        run_cli("query field --agents " + agents.string() + args + " --method index", dir);
    EXPECT_EQ(r.status, 2) << args << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(r.out.empty());
  }
}

TEST(FieldCli, FiniteDifferenceGradientOption) {
  TempDir dir;
  const auto agents = dir.write("a.csv", "id,x,y,vx,vy,radius\n1,0,0,0,0,1\n2,3,4,0,0,1\n");
  const std::string common =
      "query field --agents " + agents.string() + " --A 1 --k 1 --fd-step 1e-4 --method ";
  const auto naive = parse_field(run_cli(common + "naive", dir).out);
  const auto index = parse_field(run_cli(common + "index", dir).out);
  ASSERT_EQ(naive.size(), 2u);
  ASSERT_EQ(index.size(), 2u);
  // Forward difference of e^{-(|x - 3| + 4)} at x = 0: (e^{-(7 - h)} - e^{-7}) / h ~ e^{-7} (1 +
  // h/2).
  const double e = std::exp(-7.0), h = 1e-4, want = e * std::expm1(h) / h;
  for (const auto* r : {&naive, &index}) {
    EXPECT_NEAR(r->at(1).gx, want, 1e-10);  // the index removes the self term: ~u / h
    EXPECT_NEAR(r->at(2).gx, e * std::expm1(-h) / h, 1e-10);
    EXPECT_NEAR(r->at(1).pot, e, 1e-15);
  }
  EXPECT_EQ(run_cli(common + "naive --fd-step 0", dir).status, 2);
}

std::map<std::string, double> parse_fit(const std::string& out) {
  std::map<std::string, double> m;
  std::istringstream in(out);
  std::string key;
  double v = 0;
  while (in >> key >> v) m[key.substr(0, key.size() - 1)] = v;
  return m;
}

TEST(FitKernelCli, PrintsParametersAndErrors) {
  TempDir dir;
  const CliResult r = run_cli("fit-kernel --from 1 --to 40", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto m = parse_fit(r.out);
  for (const char* k : {"A", "k", "max_abs_error", "max_rel_error", "rms_error"})
    EXPECT_TRUE(m.count(k)) << k;
  EXPECT_NEAR(m.at("A"), 0.884233, 2e-6);
  EXPECT_NEAR(m.at("k"), 0.259009, 2e-6);
  // Scaling x by s scales A and k by 1/s (alpha fixed): [2, 80] gives half of [1, 40].
  const auto half = parse_fit(run_cli("fit-kernel --from 2 --to 80", dir).out);
  EXPECT_NEAR(half.at("A"), m.at("A") / 2, 1e-7);
  EXPECT_NEAR(half.at("k"), m.at("k") / 2, 1e-7);
  // alpha scales A only.
  const auto three = parse_fit(run_cli("fit-kernel --from 1 --to 40 --alpha 3", dir).out);
  EXPECT_NEAR(three.at("A"), 3 * m.at("A"), 1e-7);
  EXPECT_NEAR(three.at("k"), m.at("k"), 1e-9);
}

TEST(FitKernelCli, BadArgumentsExitWith2AndOneLine) {
  TempDir dir;
  for (const char* args :
       {"fit-kernel --from 0 --to 1", "fit-kernel --from 5 --to 2", "fit-kernel --from 1",
        "fit-kernel --from 1 --to 3 --alpha -1", "fit-kernel --from 1 --to 3 --samples 1",
        "fit-kernel --from x --to 3", "fit-kernel --from 1 --to inf"}) {
    const CliResult r = run_cli(args, dir);
    EXPECT_EQ(r.status, 2) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
  }
}

}  // namespace
}  // namespace crowddb::test
