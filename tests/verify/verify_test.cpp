#include "verify/verify.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "crowddb/simulation.hpp"
#include "support/cli.hpp"

namespace crowddb::verify {
namespace {

// The acceptance of the issue "crowds that flow": the default model passes every case. Runs are
// deterministic, so this is a fixed outcome of the code, not a sample.
TEST(Verify, TheDefaultModelPassesEveryCase) {
  const std::string model = SimConfig{}.steering.model;
  for (const Case& c : cases()) {
    const CaseResult r = run_case(c, model, 1);
    std::string failed;
    for (const Check& k : r.checks)
      if (!k.pass()) failed += " " + k.name + "=" + std::to_string(k.value);
    EXPECT_TRUE(r.pass()) << c.name << ":" << failed;
  }
}

TEST(Verify, CasesAreNamedOnceAndEvaluateWhatTheyRun) {
  std::set<std::string> names;
  for (const Case& c : cases()) {
    EXPECT_TRUE(names.insert(c.name).second) << c.name;
    EXPECT_FALSE(c.scenarios.empty()) << c.name;
    EXPECT_FALSE(c.family.empty()) << c.name;
  }
  EXPECT_GE(cases().size(), 13u);
}

// A check that cannot be computed fails: no vacuous pass when a shortest path is missing or an
// agent never arrives.
TEST(Verify, UncomputableRatiosFail) {
  RunStats r;
  r.agents = r.arrived = 2;
  r.arrival = {10, std::nan("")};
  r.walked = {10, 10};
  r.shortest = {10, INFINITY};
  r.free_time = {8, INFINITY};
  const std::vector<Check> c = standard_checks(r, Limits{2, 2, 2, 2});
  std::size_t failed = 0;
  for (const Check& k : c) failed += !k.pass();
  EXPECT_EQ(failed, 4u);  // the two time ratios and the two path ratios
}

TEST(VerifyCli, ListsRunsWritesCsvAndFailsWithStatus3) {
  test::TempDir dir;
  const test::CliResult list = test::run_cli("verify --list", dir);
  EXPECT_EQ(list.status, 0);
  EXPECT_NE(list.out.find("rimea-01-corridor"), std::string::npos);
  const test::CliResult bad = test::run_cli("verify --case nonsense", dir);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("unknown case 'nonsense'"), std::string::npos) << bad.err;
  const test::CliResult ok =
      test::run_cli("verify --case oncoming-pair --csv " + (dir / "v.csv").string(), dir);
  EXPECT_EQ(ok.status, 0) << ok.out << ok.err;
  EXPECT_NE(test::slurp(dir / "v.csv").find("oncoming-pair,"), std::string::npos);
  // The thesis's rule brakes for the far end wall of RiMEA 1's corridor: a failed case, status 3.
  const test::CliResult fail = test::run_cli("verify --model thesis --case rimea-01-corridor", dir);
  EXPECT_EQ(fail.status, 3) << fail.out;
  EXPECT_NE(fail.out.find("FAIL"), std::string::npos);
  const test::CliResult written = test::run_cli("verify --write " + (dir / "cases").string(), dir);
  EXPECT_EQ(written.status, 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "cases" / "rimea-09-large-room-2.json"));
  EXPECT_EQ(test::run_cli("validate " + (dir / "cases" / "u-trap.json").string(), dir).status, 0);
}

// --set reaches every run of the cases (a pair cannot pass each other in one second), and a bad
// field is the command's usage error before any case runs.
TEST(VerifyCli, SetChangesTheRunsAndABadFieldStopsFirst) {
  test::TempDir dir;
  const test::CliResult short_run =
      test::run_cli("verify --case oncoming-pair --set duration=1", dir);
  EXPECT_EQ(short_run.status, 3) << short_run.out << short_run.err;
  EXPECT_NE(short_run.out.find("FAIL arrived / agents"), std::string::npos) << short_run.out;
  const test::CliResult typo =
      test::run_cli("verify --case oncoming-pair --set steering.orca.time_gapp=1", dir);
  EXPECT_EQ(typo.status, 1) << typo.out;
  EXPECT_NE(typo.err.find("--set: /steering/orca/time_gapp: unknown key"), std::string::npos)
      << typo.err;
  EXPECT_EQ(typo.out.find("crowddb verify: model"), std::string::npos) << typo.out;
  const test::CliResult malformed = test::run_cli("verify --set steering", dir);
  EXPECT_EQ(malformed.status, 2);
  EXPECT_NE(malformed.err.find("expected KEY=VALUE"), std::string::npos) << malformed.err;
}

}  // namespace
}  // namespace crowddb::verify
