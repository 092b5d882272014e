// SQLite trajectories in JuPedSim's format, version 3 (its SqliteTrajectoryWriter defines it):
//   trajectory_data(frame, id, pos_x, pos_y), metadata(key, value) with version and fps,
//   geometry(hash, wkt), frame_data(frame, geometry_hash)
// and crowddb's own tables beside them:
//   crowddb_agent_state(frame, id, vel_x, vel_y, radius, state, goal): state active, frozen,
//                            stalled or arrived (agent_state_name)
//   crowddb_tick_metrics(tick, time, agents, entered, arrived, frozen, freeze_iterations,
//                        overlapping_pairs, obstacle_overlaps, gridlocked, stalled, queueing,
//                        longest_stall, tick_seconds, state_hash)
//   crowddb_run(key, value): scenario name and text, seed, threads, ticks, final state hash;
//                            status (running, complete, stopped), last_tick, stop_reason;
//                            resume_options (the command line's settings, for crowddb resume)
//   crowddb_checkpoint(tick, engine, progress): the latest checkpoint of an unfinished run
//                            (Simulation::save_state and the run's counters; emptied at finish)
//   crowddb_checkpoint_piece(record, part, bytes): the rest of a record longer than one piece
//                            (kCheckpointPiece), parts 1, 2, ... in order after the first piece
//                            in crowddb_checkpoint (SQLite keeps a value to 10^9 bytes; the state
//                            is ~200 bytes an agent, 10^9 bytes at 5·10^6 agents)
// WAL journal, frames committed in batches (io/trajectory.hpp); renamed into place at the end.
// A frame's rows go in ascending id, so the (frame, id) indices, made with the tables, grow at
// their ends as rows come (no index to build at the end, and a .partial file has them too).
// Frames and metrics are written by a thread of the writer's own (io/write_behind.hpp) while
// the simulation goes on; checkpoints, finish and stop wait for it and run on the caller's.
#include <sqlite3.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "io/frame_copy.hpp"
#include "io/output_lock.hpp"
#include "io/trajectory.hpp"
#include "io/walkable_wkt.hpp"
#include "io/write_behind.hpp"
#include "util/utf8.hpp"

namespace crowddb::io {
namespace {

constexpr uint64_t kFramesPerBatch = 100;
// A frame's rows go in statements of this many rows (the rest one by one): SQLite's work per
// statement run is then shared, a third less time inserting than one row per statement.
constexpr std::size_t kRowsPerInsert = 64;
// One thread at a time writes through the connection: SQLite's per-call mutex is not needed.
constexpr int kOpenFlags = SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX;
constexpr std::chrono::seconds kSecondsPerBatch{2};
// How long finishing waits for other connections to the output (a viewer following the run) to
// close, for a file in a rollback journal (which needs it to itself); after that the file is
// finished in WAL mode instead.
constexpr std::chrono::seconds kOthersTimeout{2};
// And how long it then waits for them to finish a query, to take every row into the file.
constexpr std::chrono::seconds kQueriesTimeout{10};
// The longest blob a checkpoint record is kept in (a record may be longer: the rest goes into
// crowddb_checkpoint_piece). Below SQLite's 10^9 bytes a value and blob I/O's 2^31 offsets.
constexpr std::size_t kCheckpointPiece = std::size_t{1} << 28;

// INSERT INTO table VALUES (?, ...), ... with `rows` rows of `columns` values.
std::string insert_rows_sql(const char* table, int columns, std::size_t rows) {
  std::string row = "(?";
  for (int c = 1; c < columns; ++c) row += ", ?";
  row += ')';
  std::string sql = std::string("INSERT INTO ") + table + " VALUES " + row;
  for (std::size_t r = 1; r < rows; ++r) sql += ", " + row;
  return sql;
}

std::string hex(uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// FNV-1a of the WKT, folded to a non-negative SQLite integer.
int64_t text_hash(const std::string& s) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ull;
  return static_cast<int64_t>(h >> 1);
}

class Statement {
 public:
  Statement() = default;
  Statement(sqlite3* db, const char* sql, const std::string& path) {
    if (sqlite3_prepare_v2(db, sql, -1, &s_, nullptr) != SQLITE_OK)
      throw Error(Error::Kind::io, path + ": " + sqlite3_errmsg(db));
  }
  ~Statement() { sqlite3_finalize(s_); }
  Statement(Statement&& o) noexcept : s_(o.s_) { o.s_ = nullptr; }
  Statement& operator=(Statement&& o) noexcept {
    std::swap(s_, o.s_);
    return *this;
  }
  sqlite3_stmt* get() const { return s_; }

 private:
  sqlite3_stmt* s_ = nullptr;
};

// The settings a run took from its command line rather than its document: `crowddb resume`
// applies them again to the stored document.
std::string resume_options(const Scenario& sc) {
  nlohmann::json j;
  j["ticks"] = sc.ticks;
  j["stop_when_all_arrived"] = sc.stop_when_all_arrived;
  j["format"] = sc.format;
  j["threads"] = sc.config.threads;
  j["model"] = sc.config.steering.model;
  j["backoff"] = sc.config.backoff;
  j["nudge_after"] = sc.config.nudge_after;
  j["navigation"] = sc.config.navigation.enabled;
  j["ftc"] = sc.config.access.ftc;
  j["field"] = sc.config.access.field;
  j["collisions"] = sc.config.access.collisions;
  return j.dump();
}

class SqliteWriter final : public TrajectoryWriter {
 public:
  SqliteWriter(std::filesystem::path path, uint32_t every, std::size_t checkpoint_piece)
      : path_(std::move(path)),
        partial_(path_.string() + ".partial"),
        every_(every ? every : 1),
        piece_(checkpoint_piece ? checkpoint_piece : kCheckpointPiece) {}
  ~SqliteWriter() override {
    // UINT64_MAX: stop() takes the last tick written once the writer's thread is done.
    if (db_) stop(UINT64_MAX, "the run ended without finishing its output");
    lock_.reset();
  }

  void begin(const Scenario& sc, const World& world) override {
    dt_ = sc.config.dt;
    stall_after_ = sc.config.ticks_for(sc.config.stall.after);
    format_ = sc.format;
    lock_.emplace(path_);
    std::error_code ec;
    if (std::filesystem::exists(partial_, ec))
      throw Error(Error::Kind::io, partial_ +
                                       ": an earlier run's unfinished output is kept here; move "
                                       "or remove it first");
    if (sqlite3_open_v2(partial_.c_str(), &db_, kOpenFlags | SQLITE_OPEN_CREATE, nullptr) !=
        SQLITE_OK) {
      const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      db_ = nullptr;
      throw Error(Error::Kind::io, path_.string() + ": cannot create output (" + msg + ")");
    }
    // 64 KiB pages: a third less time inserting than SQLite's 4 KiB (a fresh file takes the page
    // size set before its first table).
    exec("PRAGMA page_size=65536");
    exec("PRAGMA journal_mode=WAL");
    exec("PRAGMA synchronous=NORMAL");
    exec("BEGIN");
    exec(
        "CREATE TABLE trajectory_data (frame INTEGER NOT NULL, id INTEGER NOT NULL, pos_x REAL NOT "
        "NULL, "
        "pos_y REAL NOT NULL)");
    exec("CREATE TABLE metadata (key TEXT NOT NULL UNIQUE PRIMARY KEY, value TEXT NOT NULL)");
    exec("CREATE TABLE geometry (hash INTEGER NOT NULL, wkt TEXT NOT NULL)");
    exec("CREATE UNIQUE INDEX geometry_hash ON geometry(hash)");
    exec("CREATE TABLE frame_data (frame INTEGER NOT NULL, geometry_hash INTEGER NOT NULL)");
    exec(
        "CREATE TABLE crowddb_agent_state (frame INTEGER NOT NULL, id INTEGER NOT NULL, vel_x REAL "
        "NOT NULL, "
        "vel_y REAL NOT NULL, radius REAL NOT NULL, state TEXT NOT NULL, goal INTEGER NOT NULL)");
    exec(
        "CREATE TABLE crowddb_tick_metrics (tick INTEGER PRIMARY KEY, time REAL NOT NULL, "
        "agents INTEGER NOT NULL, entered INTEGER NOT NULL, arrived INTEGER NOT NULL, frozen "
        "INTEGER NOT NULL, freeze_iterations INTEGER NOT NULL, overlapping_pairs INTEGER NOT "
        "NULL, obstacle_overlaps INTEGER NOT NULL, gridlocked INTEGER NOT NULL, stalled INTEGER "
        "NOT NULL, queueing INTEGER NOT NULL, longest_stall REAL NOT NULL, tick_seconds REAL NOT "
        "NULL, state_hash TEXT NOT NULL)");
    exec("CREATE TABLE crowddb_run (key TEXT NOT NULL UNIQUE PRIMARY KEY, value TEXT NOT NULL)");
    exec(
        "CREATE TABLE crowddb_checkpoint (tick INTEGER PRIMARY KEY, engine BLOB NOT NULL, "
        "progress BLOB NOT NULL)");
    create_piece_table();
    exec(
        "CREATE TABLE crowddb_goals (goal INTEGER PRIMARY KEY, name TEXT NOT NULL, x REAL NOT "
        "NULL, "
        "y REAL NOT NULL, arrival_radius REAL NOT NULL)");
    create_indices();
    const Bounds& b = world.bounds();
    const double fps = 1.0 / (sc.config.dt * every_);
    Statement meta(db_, "INSERT INTO metadata VALUES (?, ?)", path_.string());
    for (const auto& [k, v] : {std::pair<std::string, std::string>{"version", "3"},
                               {"fps", num(fps)},
                               {"xmin", num(b.xmin)},
                               {"xmax", num(b.xmax)},
                               {"ymin", num(b.ymin)},
                               {"ymax", num(b.ymax)}})
      insert_text(meta, k, v);
    Statement run(db_, "INSERT INTO crowddb_run VALUES (?, ?)", path_.string());
    for (const auto& [k, v] : {std::pair<std::string, std::string>{"scenario_name", sc.name},
                               {"scenario_source", sc.source},
                               {"scenario_json", sc.text},
                               {"seed", std::to_string(sc.config.seed)},
                               {"dt", num(sc.config.dt)},
                               {"frame_every", std::to_string(every_)},
                               {"resume_options", resume_options(sc)},
                               {"status", "running"},
                               {"last_tick", "0"}})
      insert_text(run, k, v);
    wkt_ = walkable_area_wkt(world);
    geometry_hash_ = text_hash(wkt_);
    Statement geo(db_, "INSERT INTO geometry VALUES (?, ?)", path_.string());
    sqlite3_bind_int64(geo.get(), 1, geometry_hash_);
    sqlite3_bind_text(geo.get(), 2, wkt_.c_str(), -1, SQLITE_TRANSIENT);
    step(geo);
    Statement goals(db_, "INSERT INTO crowddb_goals VALUES (?, ?, ?, ?, ?)", path_.string());
    for (std::size_t i = 0; i < world.goals().size(); ++i) {
      const Goal& g = world.goals()[i];
      sqlite3_bind_int64(goals.get(), 1, static_cast<int64_t>(i));
      sqlite3_bind_text(goals.get(), 2, g.name.c_str(), -1, SQLITE_TRANSIENT);
      sqlite3_bind_double(goals.get(), 3, g.x);
      sqlite3_bind_double(goals.get(), 4, g.y);
      sqlite3_bind_double(goals.get(), 5, g.arrival_radius);
      step(goals);
    }
    prepare();
    batch_start_ = std::chrono::steady_clock::now();
  }

  // Statements, and the thread that writes frames and metrics through them.
  void prepare() {
    behind_.emplace(kWriterJobsWaiting);
    for (std::size_t k = 0; k < 2; ++k) {
      const std::size_t rows = k == 0 ? 1 : kRowsPerInsert;
      traj_[k] =
          Statement(db_, insert_rows_sql("trajectory_data", 4, rows).c_str(), path_.string());
      state_[k] =
          Statement(db_, insert_rows_sql("crowddb_agent_state", 7, rows).c_str(), path_.string());
    }
    frame_ = Statement(db_, "INSERT INTO frame_data VALUES (?, ?)", path_.string());
    metric_ = Statement(
        db_,
        "INSERT INTO crowddb_tick_metrics VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
        path_.string());
    set_run_ = Statement(db_, "INSERT OR REPLACE INTO crowddb_run VALUES (?, ?)", path_.string());
  }

  // The frame's rows are copied now and written by the writer's thread.
  void frame(uint64_t tick, const World& world) override {
    if (tick % every_ != 0) return;
    const auto frame = static_cast<int64_t>(tick / every_);
    FrameCopies::Rows rows = copies_.copy(world.agents(), stall_after_);
    behind_->post([this, frame, rows] { write_frame(frame, *rows); });
  }

  void metrics(const TickMetrics& m) override {
    behind_->post([this, m] { write_metrics(m); });
  }

  void write_frame(int64_t frame, std::vector<FrameRow>& rows) {
    std::sort(rows.begin(), rows.end(),
              [](const FrameRow& a, const FrameRow& b) { return a.id < b.id; });
    // Rows [at, at + n) through statement k of each table.
    auto insert = [&](std::size_t k, std::size_t at, std::size_t n) {
      sqlite3_stmt* traj = traj_[k].get();
      sqlite3_stmt* state = state_[k].get();
      for (std::size_t r = 0; r < n; ++r) {
        const FrameRow& a = rows[at + r];
        const auto id = static_cast<int64_t>(a.id);
        const int tc = static_cast<int>(4 * r), sc = static_cast<int>(7 * r);
        sqlite3_bind_int64(traj, tc + 1, frame);
        sqlite3_bind_int64(traj, tc + 2, id);
        sqlite3_bind_double(traj, tc + 3, a.x);
        sqlite3_bind_double(traj, tc + 4, a.y);
        sqlite3_bind_int64(state, sc + 1, frame);
        sqlite3_bind_int64(state, sc + 2, id);
        sqlite3_bind_double(state, sc + 3, a.vx);
        sqlite3_bind_double(state, sc + 4, a.vy);
        sqlite3_bind_double(state, sc + 5, a.radius);
        sqlite3_bind_text(state, sc + 6, a.state, -1, SQLITE_STATIC);
        sqlite3_bind_int64(state, sc + 7, a.goal);
      }
      step(traj_[k]);
      step(state_[k]);
    };
    std::size_t at = 0;
    for (; at + kRowsPerInsert <= rows.size(); at += kRowsPerInsert) insert(1, at, kRowsPerInsert);
    for (; at < rows.size(); ++at) insert(0, at, 1);
    sqlite3_bind_int64(frame_.get(), 1, frame);
    sqlite3_bind_int64(frame_.get(), 2, geometry_hash_);
    step(frame_);
    ++frames_in_batch_;
  }

  void write_metrics(const TickMetrics& m) {
    sqlite3_stmt* s = metric_.get();
    int col = 0;
    auto i64 = [&](uint64_t v) { sqlite3_bind_int64(s, ++col, static_cast<int64_t>(v)); };
    i64(m.tick);
    sqlite3_bind_double(s, ++col, m.time);
    i64(m.agents);
    i64(m.entered);
    i64(m.arrived);
    i64(m.frozen);
    i64(m.freeze_iterations);
    i64(m.overlapping_pairs);
    i64(m.obstacle_overlaps);
    i64(m.gridlocked);
    i64(m.stalled);
    i64(m.queueing);
    sqlite3_bind_double(s, ++col, static_cast<double>(m.longest_stall) * dt_);
    sqlite3_bind_double(s, ++col, m.seconds);
    const std::string h = hex(m.state_hash);
    sqlite3_bind_text(s, ++col, h.c_str(), -1, SQLITE_TRANSIENT);
    step(metric_);
    last_tick_ = m.tick;
    if (frames_in_batch_ >= kFramesPerBatch ||
        std::chrono::steady_clock::now() - batch_start_ >= kSecondsPerBatch) {
      insert_text(set_run_, "last_tick", std::to_string(last_tick_));
      exec("COMMIT");
      exec("BEGIN");
      frames_in_batch_ = 0;
      batch_start_ = std::chrono::steady_clock::now();
    }
  }

  // On this thread, once the frames before it are written. A record is streamed twice: once
  // to count its bytes, then into blobs of that size made in place (a zeroblob costs SQLite no
  // memory), so that neither it nor SQLite ever holds a checkpoint whole (at 10^6 agents some
  // hundred MB; checkpoints are minutes apart).
  void checkpoint(uint64_t tick, const StreamedRecord& engine, const StreamedRecord& run) override {
    behind_->drain();
    const std::size_t engine_bytes = streamed_size(engine), run_bytes = streamed_size(run);
    // In a savepoint: a record that fails half way (a full disk, an error while it is streamed)
    // leaves the previous checkpoint as it was, not a zero-filled one that a stop would commit.
    exec("SAVEPOINT checkpoint");
    try {
      exec("DELETE FROM crowddb_checkpoint");
      exec("DELETE FROM crowddb_checkpoint_piece");
      Statement cp(db_, "INSERT INTO crowddb_checkpoint VALUES (?, zeroblob(?), zeroblob(?))",
                   path_.string());
      sqlite3_bind_int64(cp.get(), 1, static_cast<int64_t>(tick));
      sqlite3_bind_int64(cp.get(), 2, static_cast<sqlite3_int64>(std::min(engine_bytes, piece_)));
      sqlite3_bind_int64(cp.get(), 3, static_cast<sqlite3_int64>(std::min(run_bytes, piece_)));
      step(cp);
      write_record("engine", static_cast<sqlite3_int64>(tick), engine, engine_bytes);
      write_record("progress", static_cast<sqlite3_int64>(tick), run, run_bytes);
    } catch (...) {
      sqlite3_exec(db_, "ROLLBACK TO checkpoint; RELEASE checkpoint", nullptr, nullptr, nullptr);
      throw;
    }
    exec("RELEASE checkpoint");
    insert_text(set_run_, "last_tick", std::to_string(last_tick_));
    exec("COMMIT");
    exec("BEGIN");
    frames_in_batch_ = 0;
    batch_start_ = std::chrono::steady_clock::now();
  }

  // Continues PATH.partial after `tick` (resume_sqlite_writer).
  void reopen(uint64_t tick, double dt, uint64_t stall_after, const std::string& format) {
    dt_ = dt;
    stall_after_ = stall_after;
    format_ = format;
    lock_.emplace(path_);
    if (sqlite3_open_v2(partial_.c_str(), &db_, kOpenFlags, nullptr) != SQLITE_OK) {
      const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      db_ = nullptr;
      throw Error(Error::Kind::io, partial_ + ": cannot open (" + msg + ")");
    }
    exec("PRAGMA journal_mode=WAL");
    exec("PRAGMA synchronous=NORMAL");
    exec("BEGIN");
    create_piece_table();  // a .partial of an older crowddb has none
    {
      Statement g(db_, "SELECT hash, wkt FROM geometry LIMIT 1", path_.string());
      if (sqlite3_step(g.get()) != SQLITE_ROW)
        throw Error(Error::Kind::input, partial_ + ": no geometry row");
      geometry_hash_ = sqlite3_column_int64(g.get(), 0);
    }
    const std::string frame = std::to_string(tick / every_);
    const std::string t = std::to_string(tick);
    for (const std::string& sql :
         {"DELETE FROM trajectory_data WHERE frame > " + frame,
          "DELETE FROM crowddb_agent_state WHERE frame > " + frame,
          "DELETE FROM frame_data WHERE frame > " + frame,
          "DELETE FROM crowddb_tick_metrics WHERE tick > " + t,
          std::string("DELETE FROM crowddb_run WHERE key = 'stop_reason'")})
      exec(sql.c_str());
    prepare();
    insert_text(set_run_, "status", "running");
    insert_text(set_run_, "last_tick", t);
    last_tick_ = tick;
    exec("COMMIT");
    exec("BEGIN");
    batch_start_ = std::chrono::steady_clock::now();
  }

  void finish(const RunInfo& info) override {
    behind_->drain();
    exec("DELETE FROM crowddb_checkpoint");  // a finished run has nothing to resume
    exec("DELETE FROM crowddb_checkpoint_piece");
    {
      Statement run(db_, "INSERT INTO crowddb_run VALUES (?, ?)", path_.string());
      for (const auto& [k, v] :
           {std::pair<std::string, std::string>{"crowddb_version", info.crowddb_version},
            {"threads", std::to_string(info.threads)},
            {"ticks", std::to_string(info.ticks)},
            {"final_state_hash", hex(info.final_hash)},
            {"run_seconds", num(info.seconds)},
            {"scenario_format", format_},
            {"summary_json", info.summary_json}})
        insert_text(run, k, v);
    }
    insert_text(set_run_, "status", "complete");
    insert_text(set_run_, "last_tick", std::to_string(info.ticks));
    if (info.steerbench) {
      exec(
          "CREATE TABLE crowddb_steerbench (id INTEGER PRIMARY KEY, collisions INTEGER NOT NULL, "
          "time REAL NOT NULL, path_length REAL NOT NULL, energy REAL NOT NULL, acceleration "
          "REAL NOT NULL, score01 REAL NOT NULL, score02 REAL NOT NULL, arrived INTEGER NOT "
          "NULL)");
      Statement sb(db_, "INSERT INTO crowddb_steerbench VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)",
                   path_.string());
      info.steerbench->for_each_score([&](const metrics::AgentScore& a) {
        sqlite3_stmt* st = sb.get();
        sqlite3_bind_int64(st, 1, static_cast<int64_t>(a.id));
        sqlite3_bind_int64(st, 2, static_cast<int64_t>(a.collisions));
        sqlite3_bind_double(st, 3, a.time);
        sqlite3_bind_double(st, 4, a.path_length);
        sqlite3_bind_double(st, 5, a.energy);
        sqlite3_bind_double(st, 6, a.acceleration);
        sqlite3_bind_double(st, 7, a.score01());
        sqlite3_bind_double(st, 8, a.score02());
        sqlite3_bind_int64(st, 9, a.arrived ? 1 : 0);
        step(sb);
      });
    }
    create_indices();  // a .partial of a crowddb before 2026-12-05 has none
    exec("COMMIT");
    release_statements();
    const bool rollback_journal = leave_wal();
    if (sqlite3_close(db_) != SQLITE_OK)
      throw Error(Error::Kind::io, path_.string() + ": cannot close output");
    db_ = nullptr;
    std::error_code ec;
    std::filesystem::rename(partial_, path_, ec);
    if (ec)
      throw Error(Error::Kind::io,
                  path_.string() + ": cannot move output into place: " + ec.message());
    if (!rollback_journal) {
      // The emptied log and its index under the old name: the other connection keeps its open
      // copies; the next run writing here must not find them.
      std::filesystem::remove(partial_ + "-wal", ec);
      std::filesystem::remove(partial_ + "-shm", ec);
    }
    lock_.reset();
  }

  std::filesystem::path stop(uint64_t tick, const std::string& reason) noexcept override {
    if (!db_) {
      lock_.reset();
      return {};
    }
    if (behind_) behind_->wait_idle();  // what is queued is written, up to a failed write
    try {
      // Commit everything written; last_tick is the last tick with both its frame and metrics.
      if (!sqlite3_get_autocommit(db_)) {
        insert_text(set_run_, "status", "stopped");
        insert_text(set_run_, "last_tick", std::to_string(std::min(tick, last_tick_)));
        insert_text(set_run_, "stop_reason", reason);
        exec("COMMIT");
      }
    } catch (...) {
      // Disk full or the like: the batches committed before stay readable.
    }
    release_statements();
    sqlite3_exec(db_, "PRAGMA journal_mode=DELETE", nullptr, nullptr, nullptr);
    sqlite3_close(db_);
    db_ = nullptr;
    lock_.reset();
    return partial_;
  }

 private:
  double dt_ = 1;                      // [s] per tick, for the metrics in seconds
  uint64_t stall_after_ = UINT64_MAX;  // [ticks] the stall watch's threshold, for the states
  std::string format_;
  static std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
  }

  void create_piece_table() {
    exec(
        "CREATE TABLE IF NOT EXISTS crowddb_checkpoint_piece (record TEXT NOT NULL, part INTEGER "
        "NOT NULL, bytes BLOB NOT NULL, PRIMARY KEY (record, part))");
    // SQLite's limit (10^9 bytes unless built otherwise) is on a row: crowddb_checkpoint's row
    // holds the first piece of both records, with room to spare for the other columns.
    const auto limit = static_cast<std::size_t>(sqlite3_limit(db_, SQLITE_LIMIT_LENGTH, -1));
    piece_ = std::max<std::size_t>(
        1, std::min(piece_, (limit - std::min<std::size_t>(limit, 4096)) / 2));
  }

  void create_indices() {
    exec("CREATE INDEX IF NOT EXISTS frame_id_idx ON trajectory_data(frame, id)");
    exec("CREATE INDEX IF NOT EXISTS state_frame_id_idx ON crowddb_agent_state(frame, id)");
  }

  void release_statements() noexcept {
    for (Statement* s :
         {&traj_[0], &traj_[1], &state_[0], &state_[1], &frame_, &metric_, &set_run_})
      *s = Statement();
  }

  // Leaves one self-contained file: checkpoints the write-ahead log into it and switches to a
  // rollback journal. The switch needs the file to itself (in WAL mode every open connection
  // holds it, even between its queries) and SQLite does not wait for that (its busy timeout
  // does not apply): we wait up to kOthersTimeout. If another connection still has the file
  // open (a viewer following the run), the log is checkpointed and emptied instead, once no
  // query of theirs is reading from it: every row is then in the file, which stays in WAL mode.
  // Returns whether it left WAL mode.
  bool leave_wal() {
    const auto retry = [&](std::chrono::seconds patience, const auto& attempt) {
      const auto give_up = std::chrono::steady_clock::now() + patience;
      for (;;) {
        const int rc = attempt();
        if (rc != SQLITE_BUSY || std::chrono::steady_clock::now() >= give_up) return rc;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    };
    int rc = retry(kOthersTimeout, [&] {
      return sqlite3_exec(db_, "PRAGMA journal_mode=DELETE", nullptr, nullptr, nullptr);
    });
    if (rc == SQLITE_OK) return true;
    if (rc == SQLITE_BUSY) {
      rc = retry(kQueriesTimeout, [&] {
        return sqlite3_wal_checkpoint_v2(db_, nullptr, SQLITE_CHECKPOINT_TRUNCATE, nullptr,
                                         nullptr);
      });
      if (rc == SQLITE_OK) return false;
      if (rc == SQLITE_BUSY)
        throw Error(Error::Kind::io,
                    path_.string() + ": another program kept reading the file for " +
                        std::to_string((kOthersTimeout + kQueriesTimeout).count()) +
                        " s at the run's end; every row is in " + partial_ + " and its -wal file");
    }
    throw Error(Error::Kind::io, path_.string() + ": " + sqlite3_errmsg(db_));
  }

  // Streams `record` (`bytes` long) into column `column` of crowddb_checkpoint's row `tick`
  // (made with a zeroblob of its first piece's size) and, past one piece, into rows of
  // crowddb_checkpoint_piece made here.
  void write_record(const char* column, sqlite3_int64 tick, const StreamedRecord& record,
                    std::size_t bytes) {
    struct Place {
      const char* table;
      const char* column;
      sqlite3_int64 row;
    };
    std::vector<Place> places{{"crowddb_checkpoint", column, tick}};
    if (bytes > piece_) {
      Statement more(db_, "INSERT INTO crowddb_checkpoint_piece VALUES (?, ?, zeroblob(?))",
                     path_.string());
      for (std::size_t part = 1; part * piece_ < bytes; ++part) {
        sqlite3_bind_text(more.get(), 1, column, -1, SQLITE_STATIC);
        sqlite3_bind_int64(more.get(), 2, static_cast<sqlite3_int64>(part));
        sqlite3_bind_int64(more.get(), 3,
                           static_cast<sqlite3_int64>(std::min(piece_, bytes - part * piece_)));
        step(more);
        places.push_back({"crowddb_checkpoint_piece", "bytes", sqlite3_last_insert_rowid(db_)});
      }
    }
    const auto failed = [&] {
      return Error(Error::Kind::io, path_.string() + ": checkpoint: " + sqlite3_errmsg(db_));
    };
    std::unique_ptr<sqlite3_blob, int (*)(sqlite3_blob*)> blob(nullptr, sqlite3_blob_close);
    std::size_t open = places.size();  // the part `blob` is open on
    stream_into(record, bytes, [&](std::string_view piece, std::size_t at) {
      while (!piece.empty()) {
        const std::size_t part = at / piece_, offset = at % piece_;
        const std::size_t n = std::min(piece.size(), piece_ - offset);
        if (part != open) {
          blob.reset();
          sqlite3_blob* b = nullptr;
          const int rc = sqlite3_blob_open(db_, "main", places[part].table, places[part].column,
                                           places[part].row, 1, &b);
          blob.reset(b);
          if (rc != SQLITE_OK) throw failed();
          open = part;
        }
        if (sqlite3_blob_write(blob.get(), piece.data(), static_cast<int>(n),
                               static_cast<int>(offset)) != SQLITE_OK)
          throw failed();
        piece.remove_prefix(n);
        at += n;
      }
    });
  }

  void exec(const char* sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
      const std::string msg = err ? err : "unknown error";
      sqlite3_free(err);
      throw Error(Error::Kind::io, path_.string() + ": " + msg);
    }
  }

  void step(const Statement& s) {
    if (sqlite3_step(s.get()) != SQLITE_DONE)
      throw Error(Error::Kind::io, path_.string() + ": " + sqlite3_errmsg(db_));
    sqlite3_reset(s.get());
  }

  void insert_text(const Statement& s, const std::string& k, const std::string& v) {
    sqlite3_bind_text(s.get(), 1, k.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(s.get(), 2, v.c_str(), -1, SQLITE_TRANSIENT);
    step(s);
  }

  std::filesystem::path path_;
  std::string partial_;
  uint32_t every_;
  std::size_t piece_;  // [bytes] the longest blob of a checkpoint record
  sqlite3* db_ = nullptr;
  Statement traj_[2], state_[2];  // one row, kRowsPerInsert rows
  Statement frame_, metric_, set_run_;
  std::string wkt_;
  int64_t geometry_hash_ = 0;
  uint64_t frames_in_batch_ = 0;
  uint64_t last_tick_ = 0;  // the last tick whose metrics were written
  std::chrono::steady_clock::time_point batch_start_;
  std::optional<OutputLock> lock_;
  FrameCopies copies_{kWriterFrameBuffers};
  std::optional<WriteBehind> behind_;  // last: stopped before the rest goes
};

// The latest checkpoint's records into p.engine and p.progress, each read straight into its
// place (SQLite's blob I/O: no copy of a piece in between): the first piece from
// crowddb_checkpoint, the rest in order from crowddb_checkpoint_piece (absent in the files of a
// crowddb before it). In one read transaction, so that a run still writing the file
// cannot mix two checkpoints; the lengths claimed are checked against the file's size before
// anything is allocated for them (a header may claim more than the file holds).
void read_checkpoint(sqlite3* db, const std::string& where, PartialRun& p) {
  const auto fail = [&](const std::string& what) {
    return Error(Error::Kind::input, where + ": " + what);
  };
  const auto step_row = [&](const Statement& q) {
    const int rc = sqlite3_step(q.get());
    if (rc != SQLITE_ROW && rc != SQLITE_DONE) throw fail(sqlite3_errmsg(db));
    return rc == SQLITE_ROW;
  };
  struct Piece {
    const char* table;
    const char* column;
    sqlite3_int64 row;
    std::string* into;
    std::size_t at, bytes;
  };
  // A blob's length, refused unless it is a blob (a NULL, a number or a text is no record).
  const auto blob_bytes = [&](const Statement& q, int type_col, const std::string& what) {
    const auto* type = reinterpret_cast<const char*>(sqlite3_column_text(q.get(), type_col));
    if (!type || std::strcmp(type, "blob") != 0)
      throw fail(what + " is " + (type ? type : "null") + ", not a blob");
    return static_cast<std::size_t>(sqlite3_column_int64(q.get(), type_col + 1));
  };
  Statement begin(db, "BEGIN", where), commit(db, "COMMIT", where);
  step_row(begin);
  std::vector<Piece> pieces;
  {
    Statement q(db,
                "SELECT rowid, tick, typeof(engine), length(engine), typeof(progress), "
                "length(progress) FROM crowddb_checkpoint",
                where);
    if (!step_row(q))
      throw fail("no checkpoint yet (the run stopped before its first; run it again)");
    const sqlite3_int64 row = sqlite3_column_int64(q.get(), 0);
    p.tick = static_cast<uint64_t>(sqlite3_column_int64(q.get(), 1));
    pieces.push_back({"crowddb_checkpoint", "engine", row, &p.engine, 0,
                      blob_bytes(q, 2, "the checkpoint's engine record")});
    pieces.push_back({"crowddb_checkpoint", "progress", row, &p.progress, 0,
                      blob_bytes(q, 4, "the checkpoint's progress record")});
  }
  bool has_pieces = false;
  {
    Statement t(db,
                "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name = "
                "'crowddb_checkpoint_piece'",
                where);
    has_pieces = step_row(t) && sqlite3_column_int64(t.get(), 0) > 0;
  }
  std::size_t end[2] = {pieces[0].bytes, pieces[1].bytes};  // engine's, progress's bytes so far
  if (has_pieces) {
    Statement q(db,
                "SELECT rowid, record, part, typeof(bytes), length(bytes) FROM "
                "crowddb_checkpoint_piece ORDER BY record, part",
                where);
    sqlite3_int64 expected[2] = {1, 1};  // the next part of engine, of progress
    while (step_row(q)) {
      const auto* r = reinterpret_cast<const char*>(sqlite3_column_text(q.get(), 1));
      const std::string record = r ? r : "";
      const int k = record == "engine" ? 0 : record == "progress" ? 1 : -1;
      if (k < 0) throw fail("a checkpoint piece of an unknown record '" + record + "'");
      const sqlite3_int64 part = sqlite3_column_int64(q.get(), 2);
      if (part != expected[k])
        throw fail("checkpoint record " + record + ": part " + std::to_string(expected[k]) +
                   " missing");
      ++expected[k];
      const std::size_t bytes =
          blob_bytes(q, 3, "checkpoint record " + record + " part " + std::to_string(part));
      pieces.push_back({"crowddb_checkpoint_piece", "bytes", sqlite3_column_int64(q.get(), 0),
                        pieces[static_cast<std::size_t>(k)].into, end[k], bytes});
      end[k] += bytes;
    }
  }
  {
    Statement q(db, "SELECT page_count * page_size FROM pragma_page_count, pragma_page_size",
                where);
    const auto file_bytes =
        step_row(q) ? static_cast<std::size_t>(sqlite3_column_int64(q.get(), 0)) : 0;
    if (end[0] > file_bytes || end[1] > file_bytes || end[0] + end[1] > file_bytes)
      throw fail("the checkpoint claims more bytes than the file holds");
  }
  p.engine.resize(end[0]);
  p.progress.resize(end[1]);
  for (const Piece& x : pieces) {
    if (x.bytes == 0) continue;
    sqlite3_blob* b = nullptr;
    const int rc = sqlite3_blob_open(db, "main", x.table, x.column, x.row, 0, &b);
    const std::unique_ptr<sqlite3_blob, int (*)(sqlite3_blob*)> blob(b, sqlite3_blob_close);
    if (rc != SQLITE_OK ||
        sqlite3_blob_read(b, x.into->data() + x.at, static_cast<int>(x.bytes), 0) != SQLITE_OK)
      throw fail(sqlite3_errmsg(db));
  }
  // (Each record's bytes are checked whole, its length and checksum, when it is restored.)
  step_row(commit);
}

}  // namespace

std::unique_ptr<TrajectoryWriter> make_sqlite_writer(const std::filesystem::path& path,
                                                     uint32_t every, std::size_t checkpoint_piece) {
  return std::make_unique<SqliteWriter>(path, every, checkpoint_piece);
}

std::string PartialRun::value(const std::string& key) const {
  for (const auto& [k, v] : run)
    if (k == key) return v;
  return {};
}

PartialRun read_partial_run(const std::filesystem::path& file) {
  const std::string name = file.string();
  PartialRun p;
  const std::string suffix = ".partial";
  std::filesystem::path partial = file;
  if (name.size() > suffix.size() &&
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
    p.path = name.substr(0, name.size() - suffix.size());
  } else {
    p.path = file;
    partial = name + suffix;
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(partial, ec)) {
    if (std::filesystem::exists(p.path, ec))
      throw Error(Error::Kind::input, p.path.string() + ": nothing to resume (no " +
                                          partial.string() +
                                          ": the run finished, or it is not a run's output)");
    throw Error(Error::Kind::io, partial.string() + ": no such file");
  }
  sqlite3* db = nullptr;
  const auto close = [&] { sqlite3_close(db); };
  const std::string where = partial.string();
  if (sqlite3_open_v2(where.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    close();
    throw Error(Error::Kind::input, where + ": not a readable SQLite file");
  }
  try {
    {
      // A run killed while creating its file leaves it without tables: say so rather than
      // "no such table".
      Statement t(db, "SELECT count(*), sum(name = 'crowddb_run') FROM sqlite_master", where);
      if (sqlite3_step(t.get()) != SQLITE_ROW)
        throw Error(Error::Kind::input, where + ": " + sqlite3_errmsg(db));
      if (sqlite3_column_int64(t.get(), 0) == 0)
        throw Error(Error::Kind::input,
                    where +
                        ": no checkpoint yet (the run stopped before writing anything; run it "
                        "again)");
      if (sqlite3_column_int64(t.get(), 1) == 0)
        throw Error(Error::Kind::input,
                    where + ": not a crowddb run's output (no crowddb_run table)");
    }
    {
      Statement q(db, "SELECT key, value FROM crowddb_run", where);
      int rc;
      while ((rc = sqlite3_step(q.get())) == SQLITE_ROW) {
        const auto* k = reinterpret_cast<const char*>(sqlite3_column_text(q.get(), 0));
        const auto* v = reinterpret_cast<const char*>(sqlite3_column_text(q.get(), 1));
        p.run.emplace_back(k ? k : "", v ? v : "");
      }
      if (rc != SQLITE_DONE) throw Error(Error::Kind::input, where + ": " + sqlite3_errmsg(db));
    }
    if (p.value("status") == "complete")
      throw Error(Error::Kind::input, where + ": this run is complete");
    if (p.value("resume_options").empty())
      throw Error(Error::Kind::input,
                  where + ": written by a crowddb without checkpoints; it cannot be resumed");
    read_checkpoint(db, where, p);
  } catch (const Error& e) {
    close();
    const std::string msg = one_line(e.what());  // (names and SQL quoted from the file)
    if (msg.rfind(where, 0) == 0) throw Error(e.kind(), msg);
    throw Error(Error::Kind::input, where + ": not an interrupted crowddb run (" + msg + ")");
  } catch (const std::exception& e) {  // out of memory for the checkpoint, say
    close();
    throw Error(Error::Kind::io,
                where + ": cannot read the checkpoint (" + one_line(e.what()) + ")");
  }
  close();
  return p;
}

std::unique_ptr<TrajectoryWriter> resume_sqlite_writer(const PartialRun& partial, double dt,
                                                       uint64_t stall_after,
                                                       const std::string& format) {
  uint64_t every = 1;
  try {
    every = std::stoull(partial.value("frame_every"));
  } catch (const std::exception&) {
    throw Error(Error::Kind::input, partial.path.string() + ".partial: bad frame_every");
  }
  if (every < 1 || every > 1u << 30)
    throw Error(Error::Kind::input, partial.path.string() + ".partial: bad frame_every");
  auto w = std::make_unique<SqliteWriter>(partial.path, static_cast<uint32_t>(every), 0);
  try {
    w->reopen(partial.tick, dt, stall_after, format);
  } catch (const Error& e) {  // SQLite's messages quote names and SQL from the file
    throw Error(e.kind(), one_line(e.what()));
  }
  return w;
}

}  // namespace crowddb::io
