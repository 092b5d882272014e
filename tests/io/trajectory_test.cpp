#include "io/trajectory.hpp"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/resource.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <thread>

#include "metrics/run.hpp"
#include "support/cli.hpp"
#include "support/sqlite_query.hpp"

namespace crowddb {
namespace {

using test::query;

const char* kScenario = R"({"name": "two", "bounds": [0, 0, 100, 50], "dt": 0.5, "ticks": 10,
  "goals": [{"name": "g", "x": 90, "y": 25, "arrival_radius": 2}],
  "obstacles": [{"type": "circle", "x": 50, "y": 40, "radius": 3}],
  "agents": [{"x": 10, "y": 25, "radius": 1, "goal": "g"}, {"x": 10, "y": 30, "radius": 1, "goal": "g"}]})";

void run_to(const std::filesystem::path& out, OutputSpec::Format format, uint32_t every = 1) {
  Scenario sc = parse_scenario(kScenario, "two.json");
  sc.output = {out.string(), format, every};
  Simulation sim(std::move(sc.world), sc.config);
  auto w = io::make_writer(sc.output);
  w->begin(sc, sim.world());
  w->frame(0, sim.world());
  for (uint64_t t = 1; t <= sc.ticks; ++t) {
    w->metrics(sim.step());
    w->frame(t, sim.world());
  }
  w->finish({});
}

TEST(TrajectorySqlite, JuPedSimSchemaVersion3WithOwnTables) {
  test::TempDir dir;
  const auto db = dir / "run.sqlite";
  run_to(db, OutputSpec::Format::sqlite);
  EXPECT_FALSE(std::filesystem::exists(dir / "run.sqlite.partial"));
  EXPECT_FALSE(std::filesystem::exists(dir / "run.sqlite-wal"));
  EXPECT_EQ(query(db, "SELECT value FROM metadata WHERE key = 'version'"),
            std::vector<std::string>{"3"});
  EXPECT_EQ(std::stod(query(db, "SELECT value FROM metadata WHERE key = 'fps'").at(0)),
            2.0);  // dt = 0.5
  EXPECT_EQ(query(db, "SELECT count(DISTINCT frame) FROM trajectory_data"),
            std::vector<std::string>{"11"});
  EXPECT_EQ(query(db, "SELECT count(*) FROM frame_data"), std::vector<std::string>{"11"});
  EXPECT_EQ(
      query(db, "SELECT count(*) FROM frame_data f JOIN geometry g ON f.geometry_hash = g.hash"),
      std::vector<std::string>{"11"});
  const std::string wkt = query(db, "SELECT wkt FROM geometry").at(0);
  EXPECT_EQ(wkt.rfind("POLYGON((", 0), 0u) << wkt;
  EXPECT_NE(wkt.find("),("), std::string::npos) << "the obstacle should be a hole: " << wkt;
  EXPECT_EQ(query(db, "SELECT count(*) FROM trajectory_data WHERE frame = 0"),
            std::vector<std::string>{"2"});
  EXPECT_EQ(query(db, "SELECT pos_x FROM trajectory_data WHERE frame = 0 AND id = 0"),
            std::vector<std::string>{"10.0"});
  EXPECT_EQ(query(db, "SELECT count(*) FROM crowddb_tick_metrics"), std::vector<std::string>{"10"});
  EXPECT_EQ(query(db, "SELECT count(*) FROM crowddb_agent_state"),
            query(db, "SELECT count(*) FROM trajectory_data"));
  EXPECT_EQ(query(db, "SELECT value FROM crowddb_run WHERE key = 'scenario_name'"),
            std::vector<std::string>{"two"});
  EXPECT_EQ(query(db, "PRAGMA journal_mode"), std::vector<std::string>{"delete"});
}

TEST(TrajectorySqlite, EveryNthFrameAndFps) {
  test::TempDir dir;
  const auto db = dir / "run.sqlite";
  run_to(db, OutputSpec::Format::sqlite, 5);
  EXPECT_EQ(query(db,
                  "SELECT group_concat(frame) FROM (SELECT DISTINCT frame FROM trajectory_data "
                  "ORDER BY frame)"),
            std::vector<std::string>{"0,1,2"});
  EXPECT_EQ(std::stod(query(db, "SELECT value FROM metadata WHERE key = 'fps'").at(0)), 0.4);
}

// Begins `w` and writes frame 0, then `ticks` ticks (frame, then metrics, as the run loop does).
void write_ticks(io::TrajectoryWriter& w, const Scenario& sc, Simulation& sim, uint64_t ticks) {
  w.begin(sc, sim.world());
  w.frame(0, sim.world());
  for (uint64_t t = 1; t <= ticks; ++t) {
    const TickMetrics& m = sim.step();
    w.frame(t, sim.world());
    w.metrics(m);
  }
}

// n agents on a grid 2 m apart (48 a row), half of them towards each of two goals; agent i in
// cell 97 i mod n (n not a multiple of 97), rows put in curve order: not in id order.
std::string many_agents(int n = 150) {
  std::string agents;
  for (int i = 0; i < n; ++i) {
    if (i) agents += ", ";
    const int cell = static_cast<int>((97ll * i) % n);
    agents += "{\"x\": " + std::to_string(2 + (cell % 48) * 2) +
              ", \"y\": " + std::to_string(2 + (cell / 48) * 2) +
              ", \"radius\": 0.3, \"goal\": \"" + (i % 2 ? "g" : "h") + "\"}";
  }
  return R"({"name": "many", "bounds": [0, 0, 100, 50], "dt": 0.5, "access": {"row_order": "curve"},
    "goals": [{"name": "g", "x": 95, "y": 25, "arrival_radius": 2},
              {"name": "h", "x": 2, "y": 25, "arrival_radius": 2}],
    "agents": [)" +
         agents + "]}";
}

// A frame's rows go in ascending id whatever the agent table's row order (the simulation keeps
// rows in a space-filling curve's order), in statements of many rows and one (150 agents: two
// statements of 64 rows, the rest one by one): every row holds its own agent's values.
TEST(TrajectorySqlite, AFramesRowsGoInIdOrderWithTheirAgentsValues) {
  const std::string doc = many_agents();
  test::TempDir dir;
  const auto out = dir / "run.sqlite";
  Scenario sc = parse_scenario(doc, "many.json");
  Simulation sim(std::move(sc.world), sc.config);
  auto w = io::make_sqlite_writer(out, 1);
  write_ticks(*w, sc, sim, 20);
  const AgentTable& t = sim.world().agents();
  ASSERT_GT(t.size(), 128u);  // some have arrived
  ASSERT_FALSE(std::is_sorted(t.id.begin(), t.id.end())) << "the rows never left id order";
  std::vector<std::size_t> rows(t.size());  // the last frame, by id, as the table holds it
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i] = i;
  std::sort(rows.begin(), rows.end(), [&](auto a, auto b) { return t.id[a] < t.id[b]; });
  w->finish({});
  test::Rows r(out,
               "SELECT p.id, p.pos_x, p.pos_y, s.id, s.vel_x, s.vel_y, s.goal FROM "
               "trajectory_data p JOIN crowddb_agent_state s ON s.rowid = p.rowid WHERE "
               "p.frame = 20 ORDER BY p.rowid");
  std::size_t k = 0;
  for (; k < rows.size() && r.next(); ++k) {
    const std::size_t i = rows[k];
    EXPECT_EQ(r.i64(0), static_cast<int64_t>(t.id[i])) << "row " << k;
    EXPECT_EQ(r.real(1), t.x[i]) << "row " << k;
    EXPECT_EQ(r.real(2), t.y[i]) << "row " << k;
    EXPECT_EQ(r.i64(3), static_cast<int64_t>(t.id[i])) << "row " << k;
    EXPECT_EQ(r.real(4), t.vx[i]) << "row " << k;
    EXPECT_EQ(r.real(5), t.vy[i]) << "row " << k;
    EXPECT_EQ(r.i64(6), static_cast<int64_t>(t.goal[i])) << "row " << k;
  }
  EXPECT_EQ(k, rows.size());
  EXPECT_FALSE(r.next()) << "frame 20 has more rows than agents";
  // Every frame: ids ascend with the row id, in both tables.
  for (const char* table : {"trajectory_data", "crowddb_agent_state"})
    EXPECT_EQ(
        query(out, std::string("SELECT count(*) FROM ") + table + " a JOIN " + table +
                       " b ON b.rowid = a.rowid + 1 AND b.frame = a.frame WHERE b.id <= a.id"),
        std::vector<std::string>{"0"})
        << table;
}

// A write that fails on the writer's thread (here the file size limit: a full disk) comes back
// to the run as an error naming the file, and stop() keeps what was written before it.
TEST(TrajectoryOutput, AFailedWriteComesBackAndTheOutputIsKept) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const auto run = [](const char* name) {
    test::TempDir dir;
    Scenario sc = parse_scenario(many_agents(), "many.json");
    sc.config.dt = 0.01;  // no one arrives in 2,000 ticks
    Simulation sim(std::move(sc.world), sc.config);
    const bool csv = std::string(name) == "run.csv";
    auto w = io::make_writer(
        {(dir / name).string(), csv ? OutputSpec::Format::csv : OutputSpec::Format::sqlite, 1});
    std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit{4 << 20, 4 << 20};  // frames of 150 agents: 4 MiB is some hundred of them
    setrlimit(RLIMIT_FSIZE, &limit);
    try {
      write_ticks(*w, sc, sim, 2000);
      w->finish({});
    } catch (const Error& e) {
      const auto kept = w->stop(sim.ticks(), e.what());
      std::string frames = "no";
      if (csv) {  // whole frames of 150 rows, and a last one cut short
        const std::string text = test::slurp(kept);
        frames = std::to_string(std::count(text.begin(), text.end(), '\n') / 150);
      } else {
        const auto n = query(kept, "SELECT count(DISTINCT frame) FROM trajectory_data");
        if (!n.empty()) frames = n[0];
      }
      std::fprintf(stderr, "error: %s\nkept %s with %s frames\n", e.what(), kept.c_str(),
                   frames.c_str());
      std::exit(3);
    }
    std::exit(0);
  };
  EXPECT_EXIT(
      run("run.sqlite"), ::testing::ExitedWithCode(3),
      "error: [^\n]*run\\.sqlite[^\n]*\nkept [^\n]*run\\.sqlite\\.partial with [1-9][0-9]* frames");
  EXPECT_EXIT(run("run.csv"), ::testing::ExitedWithCode(3),
              "error: [^\n]*run\\.csv: write failed\nkept [^\n]*run\\.csv\\.partial with "
              "[1-9][0-9]* frames");
}

// A stopped run keeps what it wrote, marked incomplete, under a name no finished run has.
TEST(TrajectorySqlite, StopKeepsEverythingWrittenMarkedIncomplete) {
  test::TempDir dir;
  Scenario sc = parse_scenario(kScenario, "two.json");
  Simulation sim(std::move(sc.world), sc.config);
  auto w = io::make_sqlite_writer(dir / "run.sqlite", 1);
  write_ticks(*w, sc, sim, 3);
  EXPECT_EQ(w->stop(3, "interrupted at tick 3"), dir / "run.sqlite.partial");
  EXPECT_FALSE(std::filesystem::exists(dir / "run.sqlite"));
  EXPECT_FALSE(std::filesystem::exists(dir / "run.sqlite.lock"));
  EXPECT_FALSE(std::filesystem::exists(dir / "run.sqlite.partial-wal"));
  const auto db = dir / "run.sqlite.partial";
  auto run_key = [&](const std::string& k) {
    return query(db, "SELECT value FROM crowddb_run WHERE key = '" + k + "'");
  };
  EXPECT_EQ(run_key("status"), std::vector<std::string>{"stopped"});
  EXPECT_EQ(run_key("last_tick"), std::vector<std::string>{"3"});
  EXPECT_EQ(run_key("stop_reason"), std::vector<std::string>{"interrupted at tick 3"});
  EXPECT_EQ(query(db, "SELECT count(DISTINCT frame) FROM trajectory_data"),
            std::vector<std::string>{"4"});
  EXPECT_EQ(query(db, "SELECT max(tick) FROM crowddb_tick_metrics"), std::vector<std::string>{"3"});
  // The kept run is not overwritten by the next one.
  auto again = io::make_sqlite_writer(dir / "run.sqlite", 1);
  try {
    again->begin(sc, sim.world());
    ADD_FAILURE() << "an earlier run's .partial was overwritten";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("run.sqlite.partial: an earlier run's unfinished output"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(run_key("status"), std::vector<std::string>{"stopped"});
}

TEST(TrajectorySqlite, StopBeforeBeginKeepsNothing) {
  test::TempDir dir;
  auto w = io::make_sqlite_writer(dir / "run.sqlite", 1);
  EXPECT_EQ(w->stop(0, "never begun"), std::filesystem::path());
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

// Frames are committed in batches while the run goes on: another reader (or the file left by
// kill -9) sees every batch but the open one.
TEST(TrajectorySqlite, BatchesAreCommittedWhileTheRunGoesOn) {
  test::TempDir dir;
  Scenario sc = parse_scenario(kScenario, "two.json");
  Simulation sim(std::move(sc.world), sc.config);
  auto w = io::make_sqlite_writer(dir / "run.sqlite", 1);
  write_ticks(*w, sc, sim, 250);
  const auto db = dir / "run.sqlite.partial";
  {  // closed before finish(): a reader's open transaction keeps it from switching journals
    // One statement, one snapshot: the writer's thread may commit its next batch meanwhile.
    test::Rows seen(db,
                    "SELECT (SELECT value FROM crowddb_run WHERE key = 'last_tick'), (SELECT value "
                    "= 'running' FROM crowddb_run WHERE key = 'status'), (SELECT max(tick) FROM "
                    "crowddb_tick_metrics), (SELECT max(frame) FROM frame_data)");
    ASSERT_TRUE(seen.next());
    const int64_t last = seen.i64(0);
    EXPECT_EQ(seen.i64(1), 1) << "status is not running";
    EXPECT_GE(last, 199);  // 100 frames per batch at most (or 2 s, whichever comes first)
    EXPECT_EQ(seen.i64(2), last);
    EXPECT_EQ(seen.i64(3), last);
  }
  w->finish({});
  EXPECT_EQ(query(dir / "run.sqlite", "SELECT value FROM crowddb_run WHERE key = 'status'"),
            std::vector<std::string>{"complete"});
}

// 250 ticks written to dir/run.sqlite, then finished while a reader is in the middle of a query
// on the .partial (its read transaction open until the statement is done), which lets go of the
// file after `hold`. Finishing must not fail; the output must be complete, frames 0 to 250.
void finish_during_a_query(const test::TempDir& dir, std::chrono::milliseconds hold) {
  Scenario sc = parse_scenario(kScenario, "two.json");
  Simulation sim(std::move(sc.world), sc.config);
  auto w = io::make_sqlite_writer(dir / "run.sqlite", 1);
  write_ticks(*w, sc, sim, 250);  // 100 frames a batch at most: two committed
  auto reader =
      std::make_unique<test::Rows>(dir / "run.sqlite.partial", "SELECT frame FROM trajectory_data");
  ASSERT_TRUE(reader->next());
  std::thread done_reading([&reader, hold] {
    std::this_thread::sleep_for(hold);
    reader.reset();
  });
  try {
    w->finish({});
  } catch (const Error& e) {
    ADD_FAILURE() << e.what();
  }
  done_reading.join();
  EXPECT_FALSE(std::filesystem::exists(dir / "run.sqlite.partial"));
  EXPECT_EQ(query(dir / "run.sqlite", "SELECT value FROM crowddb_run WHERE key = 'status'"),
            std::vector<std::string>{"complete"});
  EXPECT_EQ(query(dir / "run.sqlite", "SELECT count(*) FROM frame_data"),
            std::vector<std::string>{"251"});
}

// A reader with the file open when the run ends (in the middle of a query here) that closes it
// within 2 s delays the end only: the output is finished in a rollback journal, one file.
TEST(TrajectorySqlite, AReaderThatClosesTheFileSoonDelaysTheEndOnly) {
  test::TempDir dir;
  finish_during_a_query(dir, std::chrono::milliseconds(300));
  EXPECT_EQ(query(dir / "run.sqlite", "PRAGMA journal_mode"), std::vector<std::string>{"delete"});
}

// A reader that keeps the file open through the run's end (a viewer following the run, between
// two of its queries): the run still ends complete, with every row in the file, which is left in
// WAL mode (a rollback journal would need the file to itself); the reader reads on.
TEST(TrajectorySqlite, AReaderThatKeepsTheFileOpenDoesNotCostTheEnd) {
  test::TempDir dir;
  Scenario sc = parse_scenario(kScenario, "two.json");
  Simulation sim(std::move(sc.world), sc.config);
  auto w = io::make_sqlite_writer(dir / "run.sqlite", 1);
  write_ticks(*w, sc, sim, 250);
  sqlite3* viewer = nullptr;
  ASSERT_EQ(
      sqlite3_open_v2((dir / "run.sqlite.partial").c_str(), &viewer, SQLITE_OPEN_READONLY, nullptr),
      SQLITE_OK);
  const auto frames_seen = [viewer] {
    sqlite3_stmt* st = nullptr;
    sqlite3_prepare_v2(viewer, "SELECT count(*) FROM frame_data", -1, &st, nullptr);
    const int64_t n = sqlite3_step(st) == SQLITE_ROW ? sqlite3_column_int64(st, 0) : -1;
    sqlite3_finalize(st);  // the query done, the connection stays open
    return n;
  };
  EXPECT_GT(frames_seen(), 100);
  try {
    w->finish({});
  } catch (const Error& e) {
    ADD_FAILURE() << e.what();
  }
  for (const char* left :
       {"run.sqlite.partial", "run.sqlite.partial-wal", "run.sqlite.partial-shm"})
    EXPECT_FALSE(std::filesystem::exists(dir / left)) << left;
  EXPECT_EQ(query(dir / "run.sqlite", "SELECT value FROM crowddb_run WHERE key = 'status'"),
            std::vector<std::string>{"complete"});
  EXPECT_EQ(query(dir / "run.sqlite", "SELECT count(*) FROM frame_data"),
            std::vector<std::string>{"251"});  // frames 0 to 250
  EXPECT_EQ(query(dir / "run.sqlite", "PRAGMA journal_mode"), std::vector<std::string>{"wal"});
  EXPECT_EQ(frames_seen(), 251);
  sqlite3_close(viewer);
}

// A reader in the middle of a long query at the run's end (one that outlasts the 2 s wait for
// the file): the end waits for the query, then empties the log into the file.
TEST(TrajectorySqlite, AReaderInALongQueryIsWaitedFor) {
  test::TempDir dir;
  finish_during_a_query(dir, std::chrono::milliseconds(2500));
}

// 8,000 agents interrupted before tick 13 with the output at `out`, whose checkpoint records are
// kept in pieces of at most `piece` bytes (0: the default). Returns the simulation's state then.
std::string interrupted_after_12(const std::filesystem::path& out, std::size_t piece) {
  Scenario sc = parse_scenario(R"({"bounds": [0, 0, 400, 400], "seed": 2,
    "goals": [{"name": "g", "x": 399, "y": 200}],
    "groups": [{"count": 8000, "radius": 0.3, "goal": "g",
                "placement": {"type": "uniform", "region": [0, 0, 400, 400]}}]})",
                               "big.json");
  sc.ticks = 100;
  Simulation sim(std::move(sc.world), sc.config);
  auto w = io::make_sqlite_writer(out, 1, piece);
  w->begin(sc, sim.world());
  metrics::RunControl control;
  control.writer = w.get();
  control.checkpoint_every = 1e9;  // only the one an interruption writes
  int asked = 0;
  control.interrupted = [&asked] { return ++asked == 13; };  // before tick 13: after tick 12
  EXPECT_THROW(metrics::run_to_end(sc, sim, control), Error);
  EXPECT_EQ(sim.ticks(), 12u);
  return sim.save_state();
}

// A checkpoint goes into the output streamed, a megabyte at a time, never whole in memory: what
// the file holds is the simulation's save_state() of that tick, byte for byte (8,000 agents: a
// record of more than one piece).
TEST(TrajectorySqlite, ACheckpointInTheOutputIsTheSimulationsStateByteForByte) {
  test::TempDir dir;
  const std::string state = interrupted_after_12(dir / "run.sqlite", 0);
  ASSERT_GT(state.size(), std::size_t{1} << 20);
  test::Rows saved(dir / "run.sqlite.partial",
                   "SELECT tick, engine, length(progress) FROM crowddb_checkpoint");
  ASSERT_TRUE(saved.next());
  EXPECT_EQ(saved.i64(0), 12);
  EXPECT_TRUE(saved.blob(1) == state) << "the checkpoint is not save_state()";
  EXPECT_GT(saved.i64(2), 0);
  EXPECT_FALSE(saved.next());
  EXPECT_EQ(query(dir / "run.sqlite.partial", "SELECT count(*) FROM crowddb_checkpoint_piece"),
            std::vector<std::string>{"0"});
}

// A record longer than SQLite keeps in one value (10^9 bytes: the state of some 5·10^6 agents)
// is kept in pieces and read back whole: here pieces of 100,003 bytes, an odd size, so that the
// streamed words straddle them. `crowddb resume` of such a file ends as the run uninterrupted.
TEST(TrajectorySqlite, ACheckpointInPiecesIsReadBackByteForByte) {
  test::TempDir dir;
  const std::size_t piece = 100'003;
  const std::string state = interrupted_after_12(dir / "run.sqlite", piece);
  const auto partial = dir / "run.sqlite.partial";
  const auto parts = [&](const char* record) {
    return std::stoull(
        query(partial, std::string("SELECT count(*) FROM crowddb_checkpoint_piece WHERE "
                                   "record = '") +
                           record + "'")
            .at(0));
  };
  const io::PartialRun saved = io::read_partial_run(partial);
  EXPECT_EQ(saved.tick, 12u);
  EXPECT_TRUE(saved.engine == state) << "not save_state(): " << saved.engine.size() << " bytes";
  EXPECT_EQ(parts("engine"), (state.size() - 1) / piece);  // the first piece is not a part
  ASSERT_GT(saved.progress.size(), piece);
  EXPECT_EQ(parts("progress"), (saved.progress.size() - 1) / piece);

  const test::CliResult r = test::run_cli("resume --quiet " + partial.string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  Scenario sc = parse_scenario(saved.value("scenario_json"), "big.json");
  Simulation sim(std::move(sc.world), sc.config);
  for (int t = 0; t < 100; ++t) sim.step();
  char hash[24];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(sim.state_hash()));
  EXPECT_EQ(
      query(dir / "run.sqlite", "SELECT value FROM crowddb_run WHERE key = 'final_state_hash'"),
      std::vector<std::string>{hash});
  // A finished run has nothing to resume: no checkpoint, no piece of one.
  EXPECT_EQ(query(dir / "run.sqlite",
                  "SELECT (SELECT count(*) FROM crowddb_checkpoint) + "
                  "(SELECT count(*) FROM crowddb_checkpoint_piece)"),
            std::vector<std::string>{"0"});
}

// The .partial of a crowddb from before checkpoints in pieces has no crowddb_checkpoint_piece:
// it is read, resumed and finished all the same.
TEST(TrajectorySqlite, AnInterruptedRunWithoutTheTableOfPiecesIsResumed) {
  test::TempDir dir;
  const std::string state = interrupted_after_12(dir / "run.sqlite", 0);
  const auto partial = dir / "run.sqlite.partial";
  ASSERT_NO_FATAL_FAILURE(test::execute(partial, "DROP TABLE crowddb_checkpoint_piece"));
  EXPECT_TRUE(io::read_partial_run(partial).engine == state);
  const test::CliResult r = test::run_cli("resume --quiet " + partial.string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(query(dir / "run.sqlite", "SELECT value FROM crowddb_run WHERE key = 'status'"),
            std::vector<std::string>{"complete"});
}

// A piece gone from the file is named, not read as a shorter record.
TEST(TrajectorySqlite, ACheckpointWithAPieceMissingIsRefusedByName) {
  test::TempDir dir;
  interrupted_after_12(dir / "run.sqlite", 100'003);
  const std::string partial = (dir / "run.sqlite.partial").string();
  ASSERT_NO_FATAL_FAILURE(test::execute(
      partial, "DELETE FROM crowddb_checkpoint_piece WHERE record = 'engine' AND part = 2"));
  try {
    io::read_partial_run(partial);
    ADD_FAILURE() << "read a checkpoint without its part 2";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), partial + ": checkpoint record engine: part 2 missing");
  }
}

// Text the file holds, quoted in an error (a piece's record name, SQLite's message about a
// damaged schema), keeps the error on one line (partial_fuzz would trap on a line break).
TEST(TrajectorySqlite, ErrorsQuotingThePartialFileAreOneLine) {
  test::TempDir dir;
  interrupted_after_12(dir / "run.sqlite", 100'003);
  const std::string partial = (dir / "run.sqlite.partial").string();
  ASSERT_NO_FATAL_FAILURE(
      test::execute(partial,
                    "UPDATE crowddb_checkpoint_piece SET record = 'eng' || char(10) || 'ine' "
                    "WHERE record = 'engine' AND part = 1"));
  try {
    io::read_partial_run(partial);
    ADD_FAILURE() << "read a checkpoint piece of an unknown record";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              partial + ": a checkpoint piece of an unknown record 'eng ine'");
  }
}

// A checkpoint whose record fails half way while it is streamed into the file leaves the
// previous checkpoint as it was (a stop then commits everything else written).
TEST(TrajectorySqlite, ACheckpointThatFailsHalfWayLeavesThePreviousOne) {
  // In one blob each, and in pieces of 1,000,003 bytes: the failed record's first pieces are
  // written before it fails.
  for (const std::size_t piece : {std::size_t{0}, std::size_t{1'000'003}}) {
    SCOPED_TRACE(piece);
    test::TempDir dir;
    Scenario sc = parse_scenario(kScenario, "two.json");
    Simulation sim(std::move(sc.world), sc.config);
    auto w = io::make_sqlite_writer(dir / "run.sqlite", 1, piece);
    write_ticks(*w, sc, sim, 6);
    const std::size_t mb = std::size_t{1} << 20;
    std::string good(3 * mb, 'a');
    for (std::size_t k = 0; k < good.size(); ++k) good[k] = static_cast<char>(k % 251);
    const std::string run(100, 'r');
    const auto pieces_of = [mb](const std::string& bytes) {
      return [&bytes, mb](const ByteSink& sink) {
        for (std::size_t at = 0; at < bytes.size(); at += mb)
          sink(std::string_view(bytes).substr(at, mb));
      };
    };
    w->checkpoint(5, pieces_of(good), pieces_of(run));
    int passes = 0;
    const auto fails_when_written = [&](const ByteSink& sink) {
      const std::string written(mb, 'b');
      sink(written);
      if (++passes == 2) throw Error(Error::Kind::io, "serializing failed");
      sink(written);
    };
    EXPECT_THROW(w->checkpoint(6, fails_when_written, pieces_of(run)), Error);
    EXPECT_EQ(passes, 2);
    w->stop(6, "test");
    const io::PartialRun saved = io::read_partial_run(dir / "run.sqlite.partial");
    EXPECT_EQ(saved.tick, 5u);
    EXPECT_TRUE(saved.engine == good);
    EXPECT_EQ(saved.progress, run);
    EXPECT_EQ(query(dir / "run.sqlite.partial", "SELECT count(*) FROM crowddb_checkpoint"),
              std::vector<std::string>{"1"});
    EXPECT_EQ(query(dir / "run.sqlite.partial", "SELECT count(*) FROM crowddb_checkpoint_piece"),
              std::vector<std::string>{piece ? "3" : "0"});
    EXPECT_EQ(query(dir / "run.sqlite.partial", "SELECT max(tick) FROM crowddb_tick_metrics"),
              std::vector<std::string>{"6"});
  }
}

// Each checkpoint replaces every piece of the one before, whether it needs more pieces or fewer,
// and a record of exactly two pieces or of none reads back as it was.
TEST(TrajectorySqlite, ACheckpointReplacesEveryPieceOfTheOneBefore) {
  test::TempDir dir;
  Scenario sc = parse_scenario(kScenario, "two.json");
  Simulation sim(std::move(sc.world), sc.config);
  const std::size_t piece = 1'000'003;
  auto w = io::make_sqlite_writer(dir / "run.sqlite", 1, piece);
  write_ticks(*w, sc, sim, 8);
  const auto record = [](std::size_t bytes, char first) {
    std::string r(bytes, first);
    for (std::size_t k = 0; k < bytes; ++k) r[k] = static_cast<char>(first + k % 7);
    return r;
  };
  const auto whole = [](const std::string& bytes) {
    return [&bytes](const ByteSink& sink) { sink(bytes); };
  };
  struct Case {
    std::size_t engine, progress, parts;
  };
  uint64_t tick = 1;
  for (const Case& c : {Case{3'500'000, 10, 3}, Case{1'500'000, 10, 1}, Case{2 * piece, 0, 1},
                        Case{0, piece + 1, 1}, Case{2'500'000, 10, 2}}) {
    SCOPED_TRACE(c.engine);
    const std::string engine = record(c.engine, 'a'), run = record(c.progress, 'r');
    w->checkpoint(tick, whole(engine), whole(run));
    const io::PartialRun saved = io::read_partial_run(dir / "run.sqlite.partial");
    EXPECT_EQ(saved.tick, tick);
    EXPECT_TRUE(saved.engine == engine);
    EXPECT_EQ(saved.progress, run);
    EXPECT_EQ(query(dir / "run.sqlite.partial", "SELECT count(*) FROM crowddb_checkpoint_piece"),
              std::vector<std::string>{std::to_string(c.parts)});
    ++tick;
  }
  w->stop(8, "test");
}

// Two runs writing one output: the second stops at once and the first is untouched.
TEST(TrajectoryOutput, ASecondWriterOfTheSameOutputIsRefused) {
  for (const auto format : {OutputSpec::Format::sqlite, OutputSpec::Format::csv}) {
    test::TempDir dir;
    Scenario sc = parse_scenario(kScenario, "two.json");
    Simulation sim(std::move(sc.world), sc.config);
    const auto out = dir / (format == OutputSpec::Format::csv ? "run.csv" : "run.sqlite");
    auto first = io::make_writer({out.string(), format, 1});
    first->begin(sc, sim.world());
    first->frame(0, sim.world());
    EXPECT_TRUE(std::filesystem::exists(out.string() + ".lock"));
    auto second = io::make_writer({out.string(), format, 1});
    try {
      second->begin(sc, sim.world());
      ADD_FAILURE() << "two writers of " << out;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("another crowddb run is writing this output"),
                std::string::npos)
          << e.what();
    }
    second.reset();
    const TickMetrics& m = sim.step();
    first->frame(1, sim.world());
    first->metrics(m);
    first->finish({});
    EXPECT_TRUE(std::filesystem::exists(out));
    EXPECT_FALSE(std::filesystem::exists(out.string() + ".lock"));
  }
}

TEST(TrajectorySqlite, UnwritablePathFailsAtBegin) {
  Scenario sc = parse_scenario(kScenario, "two.json");
  Simulation sim(std::move(sc.world), sc.config);
  auto w = io::make_sqlite_writer("/nonexistent-dir/run.sqlite", 1);
  EXPECT_THROW(w->begin(sc, sim.world()), Error);
}

// One run written as CSV and as SQLite holds the same numbers, bit for bit, in every frame (800
// agents: more than one buffer of the CSV writer's formatted rows).
TEST(TrajectoryCsv, HoldsTheSameNumbersAsTheSqliteOutput) {
  test::TempDir dir;
  for (const char* name : {"run.csv", "run.sqlite"}) {
    Scenario sc = parse_scenario(many_agents(800), "many.json");
    Simulation sim(std::move(sc.world), sc.config);
    const auto format =
        std::string(name) == "run.csv" ? OutputSpec::Format::csv : OutputSpec::Format::sqlite;
    auto w = io::make_writer({(dir / name).string(), format, 1});
    write_ticks(*w, sc, sim, 5);
    w->finish({});
  }
  // frame,id -> the rest of the row, as the CSV file and as SQLite's doubles printed exactly
  std::map<std::pair<long long, long long>, std::vector<double>> csv, db;
  std::istringstream in(test::slurp(dir / "run.csv"));
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    ASSERT_EQ(f.size(), 9u) << line;
    csv[{std::stoll(f[0]), std::stoll(f[1])}] = {
        std::strtod(f[2].c_str(), nullptr), std::strtod(f[3].c_str(), nullptr),
        std::strtod(f[4].c_str(), nullptr), std::strtod(f[5].c_str(), nullptr),
        std::strtod(f[6].c_str(), nullptr), static_cast<double>(std::stoll(f[8]))};
  }
  for (test::Rows r(dir / "run.sqlite",
                    "SELECT p.frame, p.id, pos_x, pos_y, vel_x, vel_y, radius, goal FROM "
                    "trajectory_data p JOIN crowddb_agent_state s USING (frame, id)");
       r.next();) {
    std::vector<double> v;
    for (int c = 2; c < 8; ++c) v.push_back(r.real(c));
    db[{r.i64(0), r.i64(1)}] = v;
  }
  EXPECT_GT(csv.size(), 5u * 800u);  // 6 frames, a few agents arrive on the way
  EXPECT_EQ(csv.size(), db.size());
  EXPECT_TRUE(csv == db);
}

TEST(TrajectoryCsv, RoundTripsExactly) {
  test::TempDir dir;
  run_to(dir / "run.csv", OutputSpec::Format::csv);
  const std::string text = test::slurp(dir / "run.csv");
  EXPECT_EQ(text.rfind("frame,id,x,y,vx,vy,radius,state,goal\n0,0,10,25,0,0,1,active,0\n", 0), 0u)
      << text.substr(0, 120);
  const std::string metrics = test::slurp(dir / "run.metrics.csv");
  // Stalemates are reported per tick (seconds in seconds, not ticks).
  EXPECT_EQ(metrics.rfind("tick,time,agents,entered,arrived,frozen,freeze_iterations,"
                          "overlapping_pairs,obstacle_overlaps,gridlocked,stalled,queueing,"
                          "longest_stall,tick_seconds,state_hash\n",
                          0),
            0u)
      << metrics.substr(0, 200);
  EXPECT_EQ(std::count(metrics.begin(), metrics.end(), '\n'), 11);
  EXPECT_FALSE(std::filesystem::exists(dir / "run.csv.partial"));
}

}  // namespace
}  // namespace crowddb

namespace crowddb::io {
namespace {

// Frames record "stalled" for an active agent past the stall watch's threshold (not for one
// held exactly at it, as queueing agents are), and never for frozen or arrived ones.
TEST(TrajectoryStates, StalledActiveFrozenArrived) {
  AgentTable t;  // the two columns the state is read from
  t.state = {AgentState::active, AgentState::active, AgentState::active, AgentState::frozen,
             AgentState::arrived};
  t.stall_ticks = {0, 40, 41, 90, 90};
  const char* want[] = {"active", "active", "stalled", "frozen", "arrived"};
  for (std::size_t i = 0; i < 5; ++i) EXPECT_STREQ(agent_state_name(t, i, 40), want[i]) << i;
}

// A real run: the bottleneck's stalls show in the frames, never more per frame than the tick's
// metrics count as stalled.
TEST(TrajectoryStates, TheBottlenecksStallsAreInTheFrames) {
  test::TempDir dir;
  const auto out = dir / "bn.sqlite";
  ASSERT_EQ(test::run_cli("run " + test::source_path("scenarios/bottleneck.json") +
                              " --ticks 300 --quiet --out " + out.string(),
                          dir)
                .status,
            0);
  const auto rows = test::query(
      out,
      "SELECT s.frame || ' ' || s.n || ' ' || m.stalled FROM (SELECT frame, count(*) AS n FROM "
      "crowddb_agent_state WHERE state = 'stalled' GROUP BY frame) s JOIN crowddb_tick_metrics m "
      "ON m.tick = s.frame");
  ASSERT_FALSE(rows.empty());
  for (const std::string& r : rows) {
    std::istringstream in(r);
    uint64_t frame = 0, n = 0, stalled = 0;
    in >> frame >> n >> stalled;
    EXPECT_LE(n, stalled) << "frame " << frame;
  }
}

}  // namespace
}  // namespace crowddb::io
