// A finished or interrupted run's trajectory file, read back for pictures and the viewer:
// crowddb's SQLite output or any JuPedSim trajectory file (its format, versions 1-3: the tables
// trajectory_data and geometry; crowddb's own tables add radii, velocities, states and goals).
// Opened read-only; nothing is ever written to it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "crowddb/world.hpp"

struct sqlite3_stmt;

namespace crowddb::view {

// Codes fixed by the viewer's frame layout (src/view/server.hpp).
enum class Shade : uint8_t {
  active = 0,
  frozen = 1,
  arrived = 2,
  unknown = 3,
  stalled = 4,
  waiting = 5
};

struct FrameAgent {
  int64_t id = 0;
  double x = 0, y = 0;
  double vx = 0, vy = 0;  // [m/s]; 0 in files without crowddb's tables
  double radius = 0;      // [m]; kDefaultRadius in files without crowddb's tables
  Shade shade = Shade::unknown;
  int64_t goal = -1;  // index into goals(); -1 when unknown
};

// A goal area of the scenario (crowddb files only): a disc or a polygon.
struct GoalShape {
  std::string name;
  double x = 0, y = 0, radius = 0;  // a disc when `ring` is empty
  std::vector<Vec2> ring;
};

class RunFile {
 public:
  // Radius drawn for agents of files that do not record one (JuPedSim's own output).
  static constexpr double kDefaultRadius = 0.2;

  // Throws Error (input or io) with one line naming the file: missing, not SQLite, not a
  // trajectory file (no trajectory_data table), malformed metadata or geometry.
  static RunFile open(const std::string& path);
  ~RunFile();
  RunFile(RunFile&&) noexcept;
  RunFile& operator=(RunFile&&) noexcept;

  const std::string& path() const { return path_; }
  const std::string& name() const { return name_; }  // the scenario's name, or the file's stem
  bool crowddb() const { return crowddb_; }          // crowddb's tables present
  int64_t first_frame() const { return first_; }
  int64_t last_frame() const { return last_; }  // first_frame() - 1 when the file has no frames
  double fps() const { return fps_; }
  // The drawing area: the file's bounds (crowddb metadata), else the geometry's envelope, else
  // the positions' envelope.
  const Bounds& bounds() const { return bounds_; }
  const std::string& geometry_wkt() const { return wkt_; }  // empty when the file has none
  // Everything within bounds() that is not walkable, as simple polygons (none without geometry).
  const std::vector<std::vector<Vec2>>& blocked() const { return blocked_; }
  const std::vector<GoalShape>& goals() const { return goals_; }
  // The agents of frame k, by id. Throws Error(usage) outside [first_frame, last_frame].
  std::vector<FrameAgent> frame(int64_t k) const;

  // Reads where each frame's rows lie (one scan of the file), so that frame() reads only them
  // instead of scanning: for files stored frame by frame, as crowddb's and JuPedSim's writers
  // store them (others keep working, by scanning). Also counts max_agents().
  void index_frames();
  std::size_t max_agents() const { return max_agents_; }
  bool indexed() const { return indexed_; }  // frames are read by row ranges

  // Per-tick metrics of a crowddb run (empty otherwise), in tick order.
  struct Metrics {
    std::vector<double> time, arrived, frozen, stalled, overlaps, ms;
  };
  Metrics metrics() const;

 private:
  struct Db;
  RunFile() = default;
  std::string path_, name_, wkt_;
  bool crowddb_ = false;
  int64_t first_ = 0, last_ = -1;
  double fps_ = 0;
  Bounds bounds_;
  std::vector<GoalShape> goals_;
  bool has_geometry_ = false;
  std::vector<std::vector<Vec2>> blocked_;
  std::unique_ptr<Db> db_;
  struct Rows {
    int64_t first = 0, last = -1;  // rowids
  };
  std::unordered_map<int64_t, Rows> traj_rows_, state_rows_;  // by frame; empty: scan
  // "SELECT what WHERE frame = k ORDER BY id", within the frame's row range when known.
  sqlite3_stmt* frame_rows(const char* what, const std::unordered_map<int64_t, Rows>& rows,
                           int64_t k) const;
  std::size_t max_agents_ = 0;
  bool indexed_ = false;
};

}  // namespace crowddb::view
