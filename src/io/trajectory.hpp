// Trajectory output of a run. SQLite in JuPedSim's trajectory format (version 3), so tools for
// that format (PedPy) read our runs, plus crowddb's own tables; or CSV files.
//
// Output appears atomically: everything is written to PATH.partial and renamed to PATH only by
// finish(), so no file named PATH is ever incomplete. Nothing written is thrown away either:
// frames are committed in batches (at most 100 frames or 2 s of wall time each), so a run
// killed outright (kill -9, power aside) loses at most one batch, and a run stopped by a
// signal or an error keeps PATH.partial with what it wrote, marked incomplete (SQLite:
// crowddb_run keys status, last_tick and stop_reason). While a run writes PATH it holds
// PATH.lock (io/output_lock.hpp); an earlier run's PATH.partial is never overwritten. With
// checkpoints (SQLite only) `crowddb resume` continues PATH.partial where the run stopped.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "metrics/steerbench.hpp"
#include "util/streamed_record.hpp"

namespace crowddb::io {

// Facts about the run stored with the trajectories.
struct RunInfo {
  std::string crowddb_version = "0.1.0";
  int threads = 1;
  uint64_t ticks = 0;
  uint64_t final_hash = 0;
  double seconds = 0;
  std::string summary_json;  // the run's summary (JSON)
  // SteerBench's scores, per agent (for_each_score: at 10^6 agents a vector of them all is 56
  // MB more at the end of the run, when its memory is at its height).
  const metrics::SteerBench* steerbench = nullptr;
};

// The state a frame records for agent row i: "arrived", "waiting" (at a goal with a wait),
// "frozen" (put back by the backoff in the
// tick), "stalled" (active, but without progress for longer than the stall watch's `after`,
// given in ticks; an agent waiting in a queue is not stalled), else "active".
inline const char* agent_state_name(const AgentTable& t, std::size_t i, uint64_t stall_after) {
  switch (t.state[i]) {
    case AgentState::arrived:
      return "arrived";
    case AgentState::waiting:
      return "waiting";
    case AgentState::frozen:
      return "frozen";
    default:
      return t.stall_ticks[i] > stall_after ? "stalled" : "active";
  }
}

class TrajectoryWriter {
 public:
  virtual ~TrajectoryWriter() = default;
  // Locks the output, creates PATH.partial and writes the static parts (metadata, geometry).
  // Refuses (Error(io)) when another run holds the lock or an earlier run's PATH.partial is
  // there (move or remove it first: it may hold an interrupted run).
  virtual void begin(const Scenario& scenario, const World& world) = 0;
  // One frame: positions (and velocities, states) of every agent after `tick` ticks.
  virtual void frame(uint64_t tick, const World& world) = 0;
  // The metrics of one tick (written for every tick, whatever the frame stride), after that
  // tick's frame: a batch may be committed here, covering everything up to m.tick.
  virtual void metrics(const TickMetrics& m) = 0;
  // Flushes, closes and renames PATH.partial to PATH.
  virtual void finish(const RunInfo& info) = 0;
  // A checkpoint after `tick` (whose frame and metrics are written): the simulation's state
  // and the run's, committed at once with every frame up to it. Only the SQLite writer keeps
  // them (tables crowddb_checkpoint and crowddb_checkpoint_piece, latest only); the CSV writer
  // ignores them. Each record comes as a function that streams its bytes to a sink, the same bytes
  // at every call, so that it need never be in memory whole.
  virtual void checkpoint(uint64_t /*tick*/, const StreamedRecord& /*engine*/,
                          const StreamedRecord& /*run*/) {}
  // Stops an unfinished run: keeps everything written so far in PATH.partial, marked incomplete
  // up to `tick` because of `reason`, and releases the lock. Returns the file kept, or an empty
  // path when nothing was begun. Safe to call at any time, never throws.
  virtual std::filesystem::path stop(uint64_t tick, const std::string& reason) noexcept = 0;
};

// `checkpoint_piece`: the longest blob a checkpoint record is kept in, longer records in several
// (0: 256 MiB; SQLite keeps a value to 10^9 bytes); tests make records of several pieces.
std::unique_ptr<TrajectoryWriter> make_sqlite_writer(const std::filesystem::path& path,
                                                     uint32_t every,
                                                     std::size_t checkpoint_piece = 0);
std::unique_ptr<TrajectoryWriter> make_csv_writer(const std::filesystem::path& path,
                                                  uint32_t every);

// An interrupted run's PATH.partial as `crowddb resume` needs it: the crowddb_run keys and the
// latest checkpoint. Throws Error(input) naming the file when it is not a crowddb SQLite output,
// is complete, or has no checkpoint.
struct PartialRun {
  std::filesystem::path path;  // the final PATH the run writes (PATH.partial until it finishes)
  std::vector<std::pair<std::string, std::string>> run;  // crowddb_run
  std::string value(const std::string& key) const;       // "" when absent
  uint64_t tick = 0;                                     // of the checkpoint
  std::string engine, progress;                          // Simulation and run_to_end state
};
PartialRun read_partial_run(const std::filesystem::path& file);

// Reopens PATH.partial to continue a run from its checkpoint at `tick`: takes the lock, drops the
// frames and metrics written after `tick` (the resumed run writes them again) and marks the
// run as running.
std::unique_ptr<TrajectoryWriter> resume_sqlite_writer(const PartialRun& partial, double dt,
                                                       uint64_t stall_after,
                                                       const std::string& format);

inline std::unique_ptr<TrajectoryWriter> make_writer(const OutputSpec& out) {
  return out.format == OutputSpec::Format::csv ? make_csv_writer(out.path, out.every)
                                               : make_sqlite_writer(out.path, out.every);
}

}  // namespace crowddb::io
