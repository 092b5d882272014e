#include "path/path_service.hpp"

#include <stdexcept>
#include <unordered_map>

#include "util/stopwatch.hpp"

namespace crowddb::path {

PathService::PathService() : PathService(Options{}) {}

PathService::PathService(Options options) : options_(std::move(options)) {
  worker_ = std::thread([this] { run(); });
}

PathService::~PathService() {
  {
    std::lock_guard lock(mu_);
    stop_ = true;
  }
  work_cv_.notify_all();
  worker_.join();
}

void PathService::submit(uint64_t due_tick, std::vector<PathJob> jobs) {
  auto b = std::make_unique<Batch>();
  b->due = due_tick;
  b->jobs = std::move(jobs);
  {
    std::lock_guard lock(mu_);
    if (!batches_.empty() && batches_.back()->due > due_tick)
      throw std::logic_error("PathService::submit: due ticks must not decrease");
    stats_.jobs_submitted += b->jobs.size();
    ++stats_.batches;
    batches_.push_back(std::move(b));
  }
  work_cv_.notify_one();
}

std::vector<PathReply> PathService::collect(uint64_t tick) {
  std::vector<PathReply> out;
  std::unique_lock lock(mu_);
  while (!batches_.empty() && batches_.front()->due <= tick) {
    Batch& b = *batches_.front();
    if (!b.done) {
      Stopwatch waited;
      ++stats_.waits;
      done_cv_.wait(lock, [&] { return b.done; });
      stats_.wait_seconds += waited.seconds();
    }
    if (b.error) {
      std::exception_ptr e = b.error;
      batches_.pop_front();
      --next_;
      std::rethrow_exception(e);
    }
    for (PathReply& r : b.replies) out.push_back(std::move(r));
    batches_.pop_front();
    --next_;  // the worker is past the front batch (it is done)
  }
  return out;
}

std::size_t PathService::pending_batches() const {
  std::lock_guard lock(mu_);
  return batches_.size();
}

std::vector<std::pair<uint64_t, std::vector<PathJob>>> PathService::pending_jobs() const {
  std::lock_guard lock(mu_);
  std::vector<std::pair<uint64_t, std::vector<PathJob>>> out;
  for (const auto& b : batches_)
    out.emplace_back(b->due, b->jobs);  // jobs: read-only to the worker
  return out;
}

PathService::Stats PathService::stats() const {
  std::lock_guard lock(mu_);
  return stats_;
}

void PathService::run() {
  // One path finder (Detour's search state) per mesh, owned by this thread.
  std::unordered_map<const NavMesh*, std::unique_ptr<PathFinder>> finders;
  std::unique_lock lock(mu_);
  for (;;) {
    work_cv_.wait(lock, [&] { return stop_ || next_ < batches_.size(); });
    if (stop_) return;
    Batch* b = batches_[next_].get();
    lock.unlock();
    // The batch is ours until `done` is set: the tick thread only reads finished batches.
    Stopwatch clock;
    std::exception_ptr error;
    try {
      b->replies.reserve(b->jobs.size());
      for (const PathJob& j : b->jobs) {
        if (options_.before_job) options_.before_job(j);
        if (!j.mesh) {  // restored, and nobody will take it
          b->replies.push_back({j.ticket, j.agent, PathResult{}, nullptr});
          continue;
        }
        auto& f = finders[j.mesh];
        if (!f) f = std::make_unique<PathFinder>(*j.mesh, options_.max_nodes);
        b->replies.push_back({j.ticket, j.agent, f->find(j.start, j.goal, j.costs.get()), j.mesh});
      }
    } catch (...) {
      error = std::current_exception();
    }
    const double worked = clock.seconds();
    lock.lock();
    b->error = error;
    b->done = true;
    stats_.jobs_done += b->jobs.size();
    stats_.work_seconds += worked;
    ++next_;
    done_cv_.notify_all();
  }
}

}  // namespace crowddb::path
