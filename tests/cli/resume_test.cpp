// `crowddb resume`: a run killed outright (kill -9) at a random tick and resumed from its last
// checkpoint ends exactly as the uninterrupted run: the same final state hash, the same state
// hash after every tick, the same frames (issue 13's acceptance: 20 of 20 at random ticks).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <random>
#include <thread>

#include "support/cli.hpp"
#include "support/sanitizers.hpp"
#include "support/sqlite_query.hpp"

extern char** environ;

namespace crowddb {
namespace {

using test::query;
using test::TempDir;

// Sanitizer builds run the same check on fewer kills (each run is several times slower).
#if defined(CROWDDB_TEST_ASAN)
constexpr int kKills = 4;
#else
constexpr int kKills = 20;
#endif

const std::string kTicks = "2000";

std::string scenario() {
  return test::source_path("scenarios/bottleneck.json");
}

// Everything a finished run's file says about its course: per tick its state hash and counts,
// the final hash, and a digest of every frame.
std::vector<std::string> course(const std::filesystem::path& db) {
  std::vector<std::string> out =
      query(db,
            "SELECT tick || ' ' || agents || ' ' || arrived || ' ' || state_hash FROM "
            "crowddb_tick_metrics ORDER BY tick");
  for (const char* sql :
       {"SELECT value FROM crowddb_run WHERE key IN ('status', 'final_state_hash', 'ticks') "
        "ORDER BY key",
        "SELECT count(*) || ' ' || sum(pos_x) || ' ' || sum(pos_y) FROM trajectory_data",
        "SELECT count(*) FROM frame_data"})
    for (std::string& v : query(db, sql)) out.push_back(std::move(v));
  return out;
}

// The tick of the checkpoint in a running (or killed) run's file; -1 while there is none.
int64_t checkpoint_tick(const std::filesystem::path& partial) {
  if (!std::filesystem::exists(partial)) return -1;
  sqlite3* h = nullptr;
  int64_t tick = -1;
  if (sqlite3_open_v2(partial.c_str(), &h, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(h, "SELECT tick FROM crowddb_checkpoint", -1, &st, nullptr) ==
            SQLITE_OK &&
        sqlite3_step(st) == SQLITE_ROW)
      tick = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
  }
  sqlite3_close(h);
  return tick;
}

pid_t spawn_run(const std::filesystem::path& out) {
  const std::string cli = CROWDDB_CLI, sc = scenario(), o = out.string();
  std::vector<const char*> argv = {cli.c_str(),          "run",   sc.c_str(), "--ticks",
                                   kTicks.c_str(),       "--out", o.c_str(),  "--quiet",
                                   "--checkpoint-every", "0",     nullptr};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  if (posix_spawn(&pid, cli.c_str(), &fa, nullptr, const_cast<char* const*>(argv.data()),
                  environ) != 0)
    pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  return pid;
}

TEST(Resume, KillMinus9AtRandomTicksThenResumeEndsAsTheUninterruptedRun) {
  TempDir dir;
  const auto ref = dir / "ref.sqlite";
  const test::CliResult r = test::run_cli(
      "run " + scenario() + " --ticks " + kTicks + " --quiet --out " + ref.string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::string> want = course(ref);
  ASSERT_EQ(want.size(), 2000u + 3 + 2);

  // Each trial kills the run once its checkpoint has passed a random tick, watched through the
  // file itself (a WAL reader does not disturb the writer), so the kills spread over the whole
  // run however fast or loaded the machine is; a kill timed by the clock missed it under load.
  std::mt19937 rng(13);
  int resumed = 0;
  std::vector<uint64_t> killed_at;
  for (int k = 0; k < 2 * kKills && resumed < kKills; ++k) {
    const auto out = dir / ("run" + std::to_string(k) + ".sqlite");
    const auto partial = std::filesystem::path(out.string() + ".partial");
    const int64_t target = std::uniform_int_distribution<int64_t>(50, 1950)(rng);
    const pid_t pid = spawn_run(out);
    ASSERT_GT(pid, 0);
    int status = 0;
    bool exited = false;
    for (const auto until = std::chrono::steady_clock::now() + std::chrono::minutes(5);
         std::chrono::steady_clock::now() < until;) {
      if (waitpid(pid, &status, WNOHANG) == pid) {
        exited = true;
        break;
      }
      if (checkpoint_tick(partial) >= target) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (!exited) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
    }
    if (std::filesystem::exists(out)) continue;  // it finished first: not a trial
    // Killed before its first checkpoint (on a loaded machine, even before creating the file or
    // its tables): nothing to resume, and resume says so.
    if (!std::filesystem::exists(partial)) {
      const std::string err = test::run_cli("resume " + partial.string(), dir).err;
      EXPECT_NE(err.find("no such file"), std::string::npos) << err;
      continue;
    }
    const auto checkpoint = query(partial, "SELECT tick FROM crowddb_checkpoint");
    if (checkpoint.empty()) {
      const std::string err = test::run_cli("resume " + partial.string(), dir).err;
      EXPECT_NE(err.find("no checkpoint yet"), std::string::npos) << err;
      continue;
    }
    killed_at.push_back(std::stoull(checkpoint[0]));
    const test::CliResult res = test::run_cli("resume --quiet " + partial.string(), dir);
    ASSERT_EQ(res.status, 0) << res.err;
    EXPECT_FALSE(std::filesystem::exists(partial));
    EXPECT_FALSE(std::filesystem::exists(out.string() + ".lock"));
    EXPECT_EQ(course(out), want) << "killed with its checkpoint at tick " << killed_at.back();
    ++resumed;
  }
  EXPECT_EQ(resumed, kKills);
  std::string ticks;
  for (uint64_t t : killed_at) ticks += " " + std::to_string(t);
  RecordProperty("checkpoint_ticks", ticks);
  std::printf("resumed from checkpoints at ticks:%s\n", ticks.c_str());
}

TEST(Resume, CtrlCLeavesACheckpointAtItsLastTick) {
  TempDir dir;
  const auto out = dir / "run.sqlite";
  const auto partial = std::filesystem::path(out.string() + ".partial");
  const pid_t pid = spawn_run(out);
  ASSERT_GT(pid, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  if (std::filesystem::exists(out)) GTEST_SKIP() << "the run finished before the signal";
  const std::string last =
      query(partial, "SELECT value FROM crowddb_run WHERE key = 'last_tick'").at(0);
  EXPECT_EQ(query(partial, "SELECT tick FROM crowddb_checkpoint"), std::vector<std::string>{last});
  EXPECT_EQ(test::run_cli("resume --quiet " + partial.string(), dir).status, 0);
  EXPECT_EQ(query(out, "SELECT value FROM crowddb_run WHERE key = 'status'"),
            std::vector<std::string>{"complete"});
}

TEST(Resume, WhatCannotBeResumedSaysWhy) {
  TempDir dir;
  const auto done = dir / "done.sqlite";
  ASSERT_EQ(
      test::run_cli("run " + scenario() + " --ticks 5 --quiet --out " + done.string(), dir).status,
      0);
  const std::pair<std::string, std::string> cases[] = {
      {done.string(), "nothing to resume"},
      {(dir / "nothing.sqlite").string(), "no such file"},
      {test::source_path("scenarios/bottleneck.json"), "nothing to resume"},
  };
  for (const auto& [file, message] : cases) {
    const test::CliResult r = test::run_cli("resume " + file, dir);
    EXPECT_EQ(r.status, 1) << file;
    EXPECT_NE(r.err.find(message), std::string::npos) << file << ": " << r.err;
  }
  const auto junk = dir / "junk.sqlite.partial";
  {
    std::FILE* f = std::fopen(junk.c_str(), "w");
    std::fputs("not a database", f);
    std::fclose(f);
  }
  const test::CliResult r = test::run_cli("resume " + junk.string(), dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(junk.string()), std::string::npos) << r.err;
  // An empty file (a run killed while creating it) and an SQLite file of something else.
  const auto empty = dir / "empty.sqlite.partial";
  std::fclose(std::fopen(empty.c_str(), "w"));
  EXPECT_NE(test::run_cli("resume " + empty.string(), dir).err.find("no checkpoint yet"),
            std::string::npos);
  const auto other = dir / "other.sqlite.partial";
  {
    sqlite3* h = nullptr;
    ASSERT_EQ(sqlite3_open(other.c_str(), &h), SQLITE_OK);
    sqlite3_exec(h, "CREATE TABLE t(x)", nullptr, nullptr, nullptr);
    sqlite3_close(h);
  }
  EXPECT_NE(test::run_cli("resume " + other.string(), dir).err.find("not a crowddb run's output"),
            std::string::npos);
}

}  // namespace
}  // namespace crowddb
