// The asynchronous path service (DESIGN.md §6): batches of path searches run on one worker
// thread while the simulation ticks on, and every batch has a due tick at which its results are
// collected. Determinism does not depend on the worker's timing: results are only ever taken at
// their due tick, in submission order, and collect() waits when a due batch is not finished yet
// (the only moment thread timing shows is how long that wait is). What is dispatched when, and
// so the per-tick budget, is decided by the caller from simulation state alone.
//
// Thread-safety: submit(), collect() and stats() are called from one thread (the tick's); the
// worker thread is internal. The meshes jobs point to must outlive the service.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "path/navmesh.hpp"

namespace crowddb::path {

struct PathJob {
  uint64_t ticket = 0;  // caller's request number
  uint64_t agent = 0;   // AgentId::value()
  // The mesh to search; none for a search restored from a checkpoint that nobody will take
  // (Navigation::restore): it is answered with no path.
  const NavMesh* mesh = nullptr;
  Vec2 start{}, goal{};
  // Polygon costs of the search (congestion; shared by the jobs of one dispatch), or none.
  std::shared_ptr<const PolygonCosts> costs;
  int32_t key = 0;  // the mesh's class (Navigation: -class for a narrow mesh), for checkpoints
};

struct PathReply {
  uint64_t ticket = 0;
  uint64_t agent = 0;
  PathResult result;
  const NavMesh* mesh = nullptr;  // the job's
};

class PathService {
 public:
  struct Options {
    int max_nodes = 16384;  // Detour search nodes per path finder
    // Called by the worker before each job: tests use it to delay the worker at random and show
    // that results do not change. Must be thread-safe.
    std::function<void(const PathJob&)> before_job;
  };
  struct Stats {
    uint64_t jobs_submitted = 0;
    uint64_t jobs_done = 0;
    uint64_t batches = 0;
    uint64_t waits = 0;       // collect() calls that had to wait for the worker
    double wait_seconds = 0;  // time the tick spent waiting
    double work_seconds = 0;  // time the worker spent searching
  };

  PathService();
  explicit PathService(Options options);
  ~PathService();  // stops the worker (unfinished batches are dropped)
  PathService(const PathService&) = delete;
  PathService& operator=(const PathService&) = delete;

  // Queues a batch due at `due_tick`. Due ticks must not decrease from one call to the next.
  void submit(uint64_t due_tick, std::vector<PathJob> jobs);
  // The replies of every batch due at or before `tick`, in submission order; blocks until those
  // batches are done. Rethrows an exception a job raised.
  std::vector<PathReply> collect(uint64_t tick);
  // Batches submitted and not collected yet.
  std::size_t pending_batches() const;
  // Their due ticks and jobs, in submission order (checkpoints save them and submit them again).
  std::vector<std::pair<uint64_t, std::vector<PathJob>>> pending_jobs() const;
  Stats stats() const;

 private:
  struct Batch {
    uint64_t due = 0;
    std::vector<PathJob> jobs;
    std::vector<PathReply> replies;
    bool done = false;
    std::exception_ptr error;
  };
  void run();

  Options options_;
  mutable std::mutex mu_;
  std::condition_variable work_cv_, done_cv_;
  std::deque<std::unique_ptr<Batch>> batches_;  // in submission (= due) order
  std::size_t next_ = 0;                        // index in batches_ of the next batch to work on
  bool stop_ = false;
  Stats stats_;
  std::thread worker_;
};

}  // namespace crowddb::path
