// Runs that are stopped keep their output: Ctrl-C keeps every committed frame and says so,
// kill -9 loses at most the open batch, and two runs cannot write one file.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "support/cli.hpp"
#include "support/sqlite_query.hpp"

extern char** environ;

namespace crowddb {
namespace {

using test::TempDir;

using test::query;

// crowddb_run's last_tick and status, in that order.
std::vector<std::string> last_tick_and_status(const std::filesystem::path& db) {
  return query(db,
               "SELECT value FROM crowddb_run WHERE key IN ('status', 'last_tick') ORDER BY key");
}

// `crowddb run SCENARIO --out OUT` in the background, its stderr to ERR.
class Background {
 public:
  Background(const std::filesystem::path& out, const std::filesystem::path& err) {
    const std::string cli = CROWDDB_CLI,
                      scenario = test::source_path("scenarios/airport-5000.json");
    const std::string o = out.string();
    std::vector<const char*> argv = {cli.c_str(), "run",     scenario.c_str(), "--out",
                                     o.c_str(),   "--quiet", nullptr};
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    const int rc = posix_spawn(&pid_, cli.c_str(), &fa, nullptr,
                               const_cast<char* const*>(argv.data()), environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) pid_ = -1;
  }
  ~Background() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      wait();
    }
  }
  bool started() const { return pid_ > 0; }
  // Waits until `file` exists (the run has begun writing); false when it does not appear
  // within a minute.
  static bool wait_for(const std::filesystem::path& file) {
    for (int i = 0; i < 600; ++i) {
      if (std::filesystem::exists(file)) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }
  void signal(int sig) const { kill(pid_, sig); }
  // The raw wait status.
  int wait() {
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return status;
  }

 private:
  pid_t pid_ = -1;
};

TEST(DurableRun, CtrlCKeepsEveryFrameMarkedIncomplete) {
  TempDir dir;
  const auto out = dir / "run.sqlite", partial = dir / "run.sqlite.partial";
  Background run(out, dir / "err.txt");
  ASSERT_TRUE(run.started());
  ASSERT_TRUE(Background::wait_for(partial));
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  run.signal(SIGINT);
  const int status = run.wait();
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  const std::string err = test::slurp(dir / "err.txt");
  EXPECT_NE(err.find("interrupted at tick "), std::string::npos) << err;
  EXPECT_NE(err.find("is kept in " + partial.string() + " (incomplete)"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(dir / "run.sqlite.lock"));
  const std::vector<std::string> status_tick = last_tick_and_status(partial);
  ASSERT_EQ(status_tick.size(), 2u);
  EXPECT_EQ(status_tick[1], "stopped");
  const std::string last = status_tick[0];
  EXPECT_GT(std::stoi(last), 0);
  // Every tick up to the interruption: its frame and its metrics.
  EXPECT_EQ(query(partial, "SELECT max(tick) FROM crowddb_tick_metrics"),
            std::vector<std::string>{last});
  EXPECT_EQ(query(partial, "SELECT count(*) FROM frame_data"),
            std::vector<std::string>{std::to_string(std::stoi(last) + 1)});
  EXPECT_NE(err.find("interrupted at tick " + last), std::string::npos) << err;
}

TEST(DurableRun, KillMinus9LosesAtMostTheOpenBatch) {
  TempDir dir;
  const auto out = dir / "run.sqlite", partial = dir / "run.sqlite.partial";
  Background run(out, dir / "err.txt");
  ASSERT_TRUE(run.started());
  ASSERT_TRUE(Background::wait_for(partial));
  std::this_thread::sleep_for(std::chrono::milliseconds(4000));  // past the first batch
  run.signal(SIGKILL);
  run.wait();
  EXPECT_FALSE(std::filesystem::exists(out));
  const std::vector<std::string> status_tick = last_tick_and_status(partial);
  ASSERT_EQ(status_tick.size(), 2u);
  EXPECT_EQ(status_tick[1], "running");  // killed: it could not say more
  const int last = std::stoi(status_tick[0]);
  EXPECT_GT(last, 0);
  // Batches of at most 100 frames or 2 s: the file holds at least what last_tick says.
  EXPECT_GE(std::stoi(query(partial, "SELECT max(tick) FROM crowddb_tick_metrics").at(0)), last);
  EXPECT_GE(std::stoi(query(partial, "SELECT max(frame) FROM frame_data").at(0)), last);
  // The next run on the same output does not overwrite it.
  const test::CliResult again =
      test::run_cli("run " + test::source_path("scenarios/airport-5000.json") +
                        " --ticks 2 --out " + out.string(),
                    dir);
  EXPECT_EQ(again.status, 1);
  EXPECT_NE(again.err.find("an earlier run's unfinished output is kept here"), std::string::npos)
      << again.err;
  EXPECT_GE(std::stoi(query(partial, "SELECT max(tick) FROM crowddb_tick_metrics").at(0)), last);
}

TEST(DurableRun, TwoRunsCannotWriteOneFile) {
  TempDir dir;
  const auto out = dir / "run.sqlite";
  Background first(out, dir / "err.txt");
  ASSERT_TRUE(first.started());
  ASSERT_TRUE(Background::wait_for(dir / "run.sqlite.partial"));
  const test::CliResult second =
      test::run_cli("run " + test::source_path("scenarios/airport-5000.json") +
                        " --ticks 2 --out " + out.string(),
                    dir);
  EXPECT_EQ(second.status, 1);
  EXPECT_NE(second.err.find(out.string() + ": another crowddb run is writing this output"),
            std::string::npos)
      << second.err;
  // The first run goes on undisturbed: stop it and find its output intact.
  first.signal(SIGINT);
  first.wait();
  EXPECT_EQ(query(dir / "run.sqlite.partial", "SELECT value FROM crowddb_run WHERE key = 'status'"),
            std::vector<std::string>{"stopped"});
}

}  // namespace
}  // namespace crowddb
