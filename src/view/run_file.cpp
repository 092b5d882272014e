#include "view/run_file.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "crowddb/error.hpp"
#include "io/walkable_wkt.hpp"
#include "util/utf8.hpp"

namespace crowddb::view {
namespace {

std::string valid_utf8(std::string s);

// Errors are one line: SQLite's messages quote names from the file, which may hold anything.
[[noreturn]] void fail(const std::string& path, std::string what) {
  throw Error(Error::Kind::input, path + ": " + valid_utf8(one_line(std::move(what))));
}

std::string text_of(sqlite3_stmt* st, int col) {
  const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(st, col));
  return p ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(st, col))) : "";
}

constexpr double kMaxCoordinate = 1e9;  // [m] as for scenarios (World::set_bounds)

// `s` with every byte that is not part of valid UTF-8 replaced by '?' (names end up in JSON and
// in pictures, both of which need valid text).
std::string valid_utf8(std::string s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    const std::size_t n = c < 0x80         ? 1
                          : (c >> 5) == 6  ? 2
                          : (c >> 4) == 14 ? 3
                          : (c >> 3) == 30 ? 4
                                           : 0;
    bool ok = n > 0 && i + n <= s.size();
    for (std::size_t k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(s[i + k]) >> 6) == 2;
    if (!ok) {
      s[i++] = '?';
      continue;
    }
    i += n;
  }
  return s;
}

Shade shade_of(const std::string& s) {
  if (s == "active") return Shade::active;
  if (s == "frozen") return Shade::frozen;
  if (s == "arrived") return Shade::arrived;
  if (s == "stalled") return Shade::stalled;
  if (s == "waiting") return Shade::waiting;
  return Shade::unknown;
}

// Goal areas from the scenario document a crowddb run keeps; anything unexpected in it (an
// imported scenario's own format, a hand-edited file) leaves the goals out, it never fails.
std::vector<GoalShape> goals_of(const std::string& doc) {
  std::vector<GoalShape> out;
  const nlohmann::json j = nlohmann::json::parse(doc, nullptr, false);
  if (!j.is_object() || !j.contains("goals") || !j["goals"].is_array()) return out;
  for (const auto& g : j["goals"]) {
    if (!g.is_object()) return {};
    GoalShape s;
    if (g.contains("name") && g["name"].is_string()) s.name = g["name"].get<std::string>();
    if (g.contains("area") && g["area"].is_array()) {
      for (const auto& p : g["area"]) {
        if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) return {};
        s.ring.push_back({p[0].get<double>(), p[1].get<double>()});
      }
      if (s.ring.size() < 3) return {};
    } else if (g.contains("x") && g.contains("y") && g["x"].is_number() && g["y"].is_number()) {
      s.x = g["x"].get<double>();
      s.y = g["y"].get<double>();
      s.radius = g.contains("arrival_radius") && g["arrival_radius"].is_number()
                     ? g["arrival_radius"].get<double>()
                     : 0.5;
    } else {
      return {};
    }
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace

struct RunFile::Db {
  sqlite3* h = nullptr;
  ~Db() { sqlite3_close(h); }

  // Prepares `sql`; a failure names the file and SQLite's reason.
  sqlite3_stmt* prepare(const std::string& path, const char* sql) const {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(h, sql, -1, &st, nullptr) != SQLITE_OK) {
      const std::string why = sqlite3_errmsg(h);
      sqlite3_finalize(st);
      fail(path, why);
    }
    return st;
  }
  bool has_table(const std::string& path, const char* name) const {
    sqlite3_stmt* st =
        prepare(path, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?");
    sqlite3_bind_text(st, 1, name, -1, SQLITE_STATIC);
    const bool yes = step(path, st);
    sqlite3_finalize(st);
    return yes;
  }
  // Steps `st`: true on a row, false when done; an error (a damaged file, a lock held by a
  // writer beyond the busy timeout) finalizes it and names the file.
  bool step(const std::string& path, sqlite3_stmt* st) const {
    const int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    const std::string why = sqlite3_errmsg(h);
    sqlite3_finalize(st);
    fail(path, "cannot read: " + why);
  }
  // Whether `table` has a column of this name (one that would shadow SQLite's rowid).
  bool has_column(const std::string& path, const char* table, const char* column) const {
    const std::string sql = std::string("SELECT 1 FROM pragma_table_info('") + table +
                            "') WHERE lower(name) = lower(?)";
    sqlite3_stmt* st = prepare(path, sql.c_str());
    sqlite3_bind_text(st, 1, column, -1, SQLITE_STATIC);
    const bool yes = step(path, st);
    sqlite3_finalize(st);
    return yes;
  }
  // The value of `key` in a (key, value) table, or "" when absent.
  std::string value(const std::string& path, const char* table, const char* key) const {
    const std::string sql = std::string("SELECT value FROM ") + table + " WHERE key = ?";
    sqlite3_stmt* st = prepare(path, sql.c_str());
    sqlite3_bind_text(st, 1, key, -1, SQLITE_STATIC);
    std::string v = step(path, st) ? text_of(st, 0) : "";
    sqlite3_finalize(st);
    return v;
  }
};

RunFile::~RunFile() = default;
RunFile::RunFile(RunFile&&) noexcept = default;
RunFile& RunFile::operator=(RunFile&&) noexcept = default;

RunFile RunFile::open(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw Error(Error::Kind::io, path + ": no such file");
  if (!std::filesystem::is_regular_file(status))
    throw Error(Error::Kind::io, path + ": not a regular file");
  RunFile f;
  f.path_ = path;
  f.db_ = std::make_unique<Db>();
  if (sqlite3_open_v2(path.c_str(), &f.db_->h, SQLITE_OPEN_READONLY | SQLITE_OPEN_FULLMUTEX,
                      nullptr) != SQLITE_OK)
    fail(path, std::string("cannot open: ") + sqlite3_errmsg(f.db_->h));
  // A file from elsewhere is data, never code: no triggers or functions from its schema, no
  // writes through it, and a writer's lock is waited for a while, not failed at once.
  sqlite3_db_config(f.db_->h, SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, nullptr);
  sqlite3_db_config(f.db_->h, SQLITE_DBCONFIG_DEFENSIVE, 1, nullptr);
  sqlite3_busy_timeout(f.db_->h, 2000);
  // The first read tells whether it is a database at all.
  {
    sqlite3_stmt* st = nullptr;
    const int rc =
        sqlite3_prepare_v2(f.db_->h, "SELECT count(*) FROM sqlite_master", -1, &st, nullptr);
    const int step = rc == SQLITE_OK ? sqlite3_step(st) : rc;
    sqlite3_finalize(st);
    if (step == SQLITE_NOTADB || rc == SQLITE_NOTADB)
      fail(path, "not an SQLite file (a crowddb run's output or a JuPedSim trajectory is)");
    if (step != SQLITE_ROW) fail(path, std::string("cannot read: ") + sqlite3_errmsg(f.db_->h));
  }
  if (!f.db_->has_table(path, "trajectory_data"))
    fail(path,
         "not a trajectory file: no table trajectory_data (a crowddb run's output or a JuPedSim "
         "trajectory is)");
  f.crowddb_ =
      f.db_->has_table(path, "crowddb_agent_state") && f.db_->has_table(path, "crowddb_run");

  {
    // Every row's types, once: integer frames and ids, numeric positions (anything else would
    // read as 0 or drop out of its frame silently).
    sqlite3_stmt* st = f.db_->prepare(
        path,
        "SELECT frame, id, typeof(frame), typeof(id), typeof(pos_x), typeof(pos_y) FROM "
        "trajectory_data WHERE typeof(frame) <> 'integer' OR typeof(id) <> 'integer' OR "
        "typeof(pos_x) NOT IN ('integer', 'real') OR typeof(pos_y) NOT IN ('integer', 'real') "
        "LIMIT 1");
    if (f.db_->step(path, st)) {
      const std::string where = "trajectory_data: the row of frame " + text_of(st, 0) + ", id " +
                                text_of(st, 1) + " holds ";
      const std::string types[4] = {text_of(st, 2), text_of(st, 3), text_of(st, 4), text_of(st, 5)};
      sqlite3_finalize(st);
      const char* cols[4] = {"frame", "id", "pos_x", "pos_y"};
      for (int c = 0; c < 4; ++c)
        if ((c < 2 && types[c] != "integer") ||
            (c >= 2 && types[c] != "integer" && types[c] != "real"))
          fail(path, where + types[c] + " in " + cols[c] + " (" +
                         (c < 2 ? "an integer" : "a number") + " is expected)");
    }
    sqlite3_finalize(st);
  }
  {
    sqlite3_stmt* st = f.db_->prepare(
        path,
        "SELECT min(frame), max(frame), min(pos_x), min(pos_y), max(pos_x), max(pos_y) FROM "
        "trajectory_data");
    if (f.db_->step(path, st) && sqlite3_column_type(st, 0) != SQLITE_NULL) {
      f.first_ = sqlite3_column_int64(st, 0);
      f.last_ = sqlite3_column_int64(st, 1);
      f.bounds_ = {sqlite3_column_double(st, 2), sqlite3_column_double(st, 3),
                   sqlite3_column_double(st, 4), sqlite3_column_double(st, 5)};
      if (f.first_ < 0 || f.last_ > INT32_MAX) {
        sqlite3_finalize(st);
        fail(path, "trajectory_data: frame numbers " + std::to_string(f.first_) + " to " +
                       std::to_string(f.last_) + " lie outside 0 to 2147483647");
      }
      for (double v : {f.bounds_.xmin, f.bounds_.ymin, f.bounds_.xmax, f.bounds_.ymax})
        if (!(std::abs(v) <= kMaxCoordinate)) {
          sqlite3_finalize(st);
          fail(path, "trajectory_data: positions must lie within +-1e9 m (got " +
                         std::to_string(v) + ")");
        }
    } else {
      f.first_ = 0;
      f.last_ = -1;
    }
    sqlite3_finalize(st);
  }

  const bool meta = f.db_->has_table(path, "metadata");
  if (meta) {
    const std::string fps = f.db_->value(path, "metadata", "fps");
    if (!fps.empty()) {
      char* end = nullptr;
      const double v = std::strtod(fps.c_str(), &end);
      if (end == fps.c_str() || *end || !(v > 0) || !std::isfinite(v))
        fail(path, "metadata fps: '" + fps + "' is not a positive number");
      f.fps_ = v;
    }
  }
  if (f.db_->has_table(path, "geometry")) {
    sqlite3_stmt* st = f.db_->prepare(path, "SELECT wkt FROM geometry LIMIT 1");
    if (f.db_->step(path, st)) f.wkt_ = text_of(st, 0);
    sqlite3_finalize(st);
    if (!f.wkt_.empty()) {
      try {
        f.bounds_ = io::WalkableArea::parse(f.wkt_).envelope();
      } catch (const Error& e) {
        fail(path, std::string("geometry: ") + e.what());
      }
      f.has_geometry_ = true;
    }
  }
  if (meta && f.crowddb_) {  // crowddb's own bounds (the walls) win over the envelopes (in
                             // JuPedSim's files these keys are the positions' envelope)
    double b[4];
    bool all = true;
    const char* keys[4] = {"xmin", "ymin", "xmax", "ymax"};
    for (int k = 0; k < 4; ++k) {
      const std::string v = f.db_->value(path, "metadata", keys[k]);
      char* end = nullptr;
      b[k] = std::strtod(v.c_str(), &end);
      all = all && !v.empty() && !*end && std::isfinite(b[k]);
    }
    if (all && b[0] < b[2] && b[1] < b[3]) f.bounds_ = {b[0], b[1], b[2], b[3]};
  }
  if (!(f.bounds_.width() > 0) || !(f.bounds_.height() > 0)) {  // one agent, or none: 10 m
    const double cx = (f.bounds_.xmin + f.bounds_.xmax) / 2,
                 cy = (f.bounds_.ymin + f.bounds_.ymax) / 2;
    const double h = std::max({f.bounds_.width(), f.bounds_.height(), 10.0}) / 2;
    f.bounds_ = {cx - h, cy - h, cx + h, cy + h};
  }
  if (!std::isfinite(f.bounds_.xmin + f.bounds_.xmax + f.bounds_.ymin + f.bounds_.ymax))
    fail(path, "the positions or bounds are not finite numbers");

  if (f.has_geometry_) {  // what is not walkable within the drawing area, once
    try {
      f.blocked_ = io::WalkableArea::parse(f.wkt_).blocked_pieces(f.bounds_);
    } catch (const Error& e) {
      fail(path, std::string("geometry: ") + e.what());
    }
  }
  f.name_ = std::filesystem::path(path).stem().string();
  if (f.crowddb_) {
    const std::string n = f.db_->value(path, "crowddb_run", "scenario_name");
    if (!n.empty()) f.name_ = n;
    f.goals_ = goals_of(f.db_->value(path, "crowddb_run", "scenario_json"));
    // Every goal by its row (also those a group made, antipodal or per-agent targets): the
    // table the writer keeps; the areas' outlines come from the scenario, by name.
    if (f.db_->has_table(path, "crowddb_goals")) {
      // The scenario's areas by name (the last of a name, as a scan would leave it): a converted
      // SteerSuite case names 20,000 goals, and a scan per row was 4 * 10^8 comparisons.
      std::unordered_map<std::string, const GoalShape*> areas;
      for (const GoalShape& area : f.goals_)
        if (!area.ring.empty()) areas[area.name] = &area;
      std::vector<GoalShape> rows;
      sqlite3_stmt* st = f.db_->prepare(
          path, "SELECT goal, name, x, y, arrival_radius FROM crowddb_goals ORDER BY goal");
      while (f.db_->step(path, st)) {
        if (sqlite3_column_int64(st, 0) != static_cast<int64_t>(rows.size())) break;
        GoalShape g;
        g.name = text_of(st, 1);
        g.x = sqlite3_column_double(st, 2);
        g.y = sqlite3_column_double(st, 3);
        g.radius = sqlite3_column_double(st, 4);
        if (!(std::abs(g.x) <= kMaxCoordinate && std::abs(g.y) <= kMaxCoordinate && g.radius >= 0 &&
              g.radius <= kMaxCoordinate))
          break;
        if (const auto it = areas.find(g.name); it != areas.end()) g.ring = it->second->ring;
        rows.push_back(std::move(g));
      }
      sqlite3_finalize(st);
      if (!rows.empty()) f.goals_ = std::move(rows);
    }
  }
  f.name_ = valid_utf8(f.name_);
  for (GoalShape& g : f.goals_) g.name = valid_utf8(g.name);
  return f;
}

sqlite3_stmt* RunFile::frame_rows(const char* what, const std::unordered_map<int64_t, Rows>& rows,
                                  int64_t k) const {
  const auto it = rows.find(k);
  const std::string sql = std::string("SELECT ") + what + " WHERE " +
                          (it != rows.end() ? "rowid BETWEEN ? AND ? AND " : "") +
                          "frame = ? ORDER BY id";
  sqlite3_stmt* st = db_->prepare(path_, sql.c_str());
  int at = 1;
  if (it != rows.end()) {
    sqlite3_bind_int64(st, at++, it->second.first);
    sqlite3_bind_int64(st, at++, it->second.last);
  }
  sqlite3_bind_int64(st, at, k);
  return st;
}

std::vector<FrameAgent> RunFile::frame(int64_t k) const {
  if (k < first_ || k > last_)
    throw Error(Error::Kind::usage,
                path_ + ": no frame " + std::to_string(k) +
                    (last_ < first_ ? " (the file has no frames)"
                                    : " (frames " + std::to_string(first_) + " to " +
                                          std::to_string(last_) + ")"));
  std::vector<FrameAgent> out;
  // Indexed: a frame without rows (a gap in the numbering) is empty, without a scan.
  if (indexed_ && !traj_rows_.count(k)) return out;
  {
    sqlite3_stmt* st = frame_rows("id, pos_x, pos_y FROM trajectory_data", traj_rows_, k);
    while (db_->step(path_, st)) {
      FrameAgent a;
      a.id = sqlite3_column_int64(st, 0);
      a.x = sqlite3_column_double(st, 1);
      a.y = sqlite3_column_double(st, 2);
      a.radius = kDefaultRadius;
      if (!std::isfinite(a.x) || !std::isfinite(a.y)) {
        sqlite3_finalize(st);
        fail(path_, "frame " + std::to_string(k) + ", agent " + std::to_string(a.id) +
                        ": position is not a finite number");
      }
      out.push_back(a);
    }
    sqlite3_finalize(st);
  }
  if (!crowddb_) return out;
  sqlite3_stmt* st =
      frame_rows("id, vel_x, vel_y, radius, state, goal FROM crowddb_agent_state", state_rows_, k);
  std::size_t at = 0;  // both lists are sorted by id: merge
  while (db_->step(path_, st)) {
    const int64_t id = sqlite3_column_int64(st, 0);
    while (at < out.size() && out[at].id < id) ++at;
    if (at == out.size() || out[at].id != id) continue;
    FrameAgent& a = out[at];
    const double vx = sqlite3_column_double(st, 1), vy = sqlite3_column_double(st, 2);
    const double r = sqlite3_column_double(st, 3);
    // Values beyond any pedestrian's are left at their defaults (0, 0.2 m) rather than drawn.
    if (std::abs(vx) <= kMaxCoordinate && std::abs(vy) <= kMaxCoordinate) {
      a.vx = vx;
      a.vy = vy;
    }
    if (r > 0 && r <= kMaxCoordinate) a.radius = r;
    a.shade = shade_of(text_of(st, 4));
    const int64_t g =
        sqlite3_column_type(st, 5) == SQLITE_INTEGER ? sqlite3_column_int64(st, 5) : -1;
    a.goal = g >= 0 && static_cast<std::size_t>(g) < goals_.size() ? g : -1;
  }
  sqlite3_finalize(st);
  return out;
}

namespace {

// One pass over a table: each frame's least and greatest rowid, when every frame's rows come in
// one run (else nothing: the reader scans); a reader still filters by frame within the range.
// Also the largest frame's row count.
template <class Rows>
bool row_ranges(sqlite3* h, const char* table, std::unordered_map<int64_t, Rows>& out,
                std::size_t& most) {
  out.clear();
  const std::string sql = std::string("SELECT rowid, frame FROM ") + table;
  sqlite3_stmt* st = nullptr;
  if (sqlite3_prepare_v2(h, sql.c_str(), -1, &st, nullptr) != SQLITE_OK) {
    sqlite3_finalize(st);
    return false;
  }
  bool ok = true, any = false;
  int64_t frame = 0;
  std::size_t count = 0;
  Rows cur;
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
    const int64_t rowid = sqlite3_column_int64(st, 0), f = sqlite3_column_int64(st, 1);
    if (!any || f != frame) {
      if (any) {
        if (!out.emplace(frame, cur).second) ok = false;  // the frame came back later
        most = std::max(most, count);
      }
      if (out.count(f)) ok = false;
      any = true;
      frame = f;
      cur = {rowid, rowid};
      count = 0;
    }
    cur.first = std::min(cur.first, rowid);  // an index on frame returns a frame's rows by id
    cur.last = std::max(cur.last, rowid);
    ++count;
    if (!ok) break;
  }
  sqlite3_finalize(st);
  if (ok && rc != SQLITE_DONE) ok = false;  // a read error part-way: no ranges from half a scan
  if (any && ok) {
    ok = out.emplace(frame, cur).second;
    most = std::max(most, count);
  }
  if (!ok) out.clear();
  return ok;
}

}  // namespace

void RunFile::index_frames() {
  // A column of the table's own named like SQLite's row id would be read instead of it.
  auto shadowed = [&](const char* table) {
    for (const char* c : {"rowid", "oid", "_rowid_"})
      if (db_->has_column(path_, table, c)) return true;
    return false;
  };
  std::size_t most = 0;
  indexed_ =
      !shadowed("trajectory_data") && row_ranges(db_->h, "trajectory_data", traj_rows_, most);
  if (!indexed_) {
    traj_rows_.clear();
    // Rows not stored frame by frame: count the largest frame the slow way.
    sqlite3_stmt* st = db_->prepare(
        path_, "SELECT max(c) FROM (SELECT count(*) AS c FROM trajectory_data GROUP BY frame)");
    if (db_->step(path_, st)) most = static_cast<std::size_t>(sqlite3_column_int64(st, 0));
    sqlite3_finalize(st);
  }
  max_agents_ = most;
  if (crowddb_ && !shadowed("crowddb_agent_state")) {
    std::size_t ignored = 0;
    row_ranges(db_->h, "crowddb_agent_state", state_rows_, ignored);
  }
}

RunFile::Metrics RunFile::metrics() const {
  Metrics m;
  if (!crowddb_ || !db_->has_table(path_, "crowddb_tick_metrics")) return m;
  sqlite3_stmt* st = db_->prepare(path_,
                                  "SELECT time, arrived, frozen, stalled, overlapping_pairs, "
                                  "tick_seconds FROM crowddb_tick_metrics ORDER BY tick");
  while (db_->step(path_, st)) {
    m.time.push_back(sqlite3_column_double(st, 0));
    m.arrived.push_back(sqlite3_column_double(st, 1));
    m.frozen.push_back(sqlite3_column_double(st, 2));
    m.stalled.push_back(sqlite3_column_double(st, 3));
    m.overlaps.push_back(sqlite3_column_double(st, 4));
    m.ms.push_back(sqlite3_column_double(st, 5) * 1e3);
  }
  sqlite3_finalize(st);
  return m;
}

}  // namespace crowddb::view
