// Trajectory output of a run. SQLite in JuPedSim's trajectory format (version 3), so tools for
// that format (PedPy) read our runs, plus crowddb's own tables; or CSV files.
//
// Output appears atomically: everything is written to PATH.partial and renamed to PATH only by
// finish(). A run that fails or is interrupted leaves no file that looks complete.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "metrics/steerbench.hpp"

namespace crowddb::io {

// Facts about the run stored with the trajectories.
struct RunInfo {
  std::string crowddb_version = "0.1.0";
  int threads = 1;
  uint64_t ticks = 0;
  uint64_t final_hash = 0;
  double seconds = 0;
  std::string summary_json;                                    // the run's summary (JSON)
  const std::vector<metrics::AgentScore>* scores = nullptr;  // SteerBench, per agent
};

class TrajectoryWriter {
 public:
  virtual ~TrajectoryWriter() = default;
  // Creates PATH.partial and writes the static parts (metadata, geometry).
  virtual void begin(const Scenario& scenario, const World& world) = 0;
  // One frame: positions (and velocities, states) of every agent after `tick` ticks.
  virtual void frame(uint64_t tick, const World& world) = 0;
  // The metrics of one tick (written for every tick, whatever the frame stride).
  virtual void metrics(const TickMetrics& m) = 0;
  // Flushes, closes and renames PATH.partial to PATH.
  virtual void finish(const RunInfo& info) = 0;
  // Removes the partial output; safe to call at any time, never throws.
  virtual void abort() noexcept = 0;
};

std::unique_ptr<TrajectoryWriter> make_sqlite_writer(const std::filesystem::path& path,
                                                     uint32_t every);
std::unique_ptr<TrajectoryWriter> make_csv_writer(const std::filesystem::path& path,
                                                  uint32_t every);

inline std::unique_ptr<TrajectoryWriter> make_writer(const OutputSpec& out) {
  return out.format == OutputSpec::Format::csv ? make_csv_writer(out.path, out.every)
                                               : make_sqlite_writer(out.path, out.every);
}

}  // namespace crowddb::io
