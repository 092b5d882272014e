// One background thread that runs a writer's jobs in the order they were posted, so that its
// I/O overlaps the simulation's next ticks instead of adding to them.
//
// A job that throws stops the rest (they are dropped unrun: the output may be in a bad state)
// and its error comes back to the posting thread, from the next post() or drain(). At most
// `max_waiting` jobs wait at once: post() blocks beyond that, so what the jobs hold (a frame's
// rows each) stays bounded.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace crowddb::io {

// The trajectory writers' queues: a frame and its tick's metrics may wait.
inline constexpr std::size_t kWriterJobsWaiting = 2;

class WriteBehind {
 public:
  explicit WriteBehind(std::size_t max_waiting) : max_waiting_(max_waiting ? max_waiting : 1) {
    thread_ = std::thread([this] { loop(); });
  }
  // Runs the jobs still waiting, then stops the thread.
  ~WriteBehind() {
    {
      std::lock_guard lock(m_);
      quit_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  WriteBehind(const WriteBehind&) = delete;
  WriteBehind& operator=(const WriteBehind&) = delete;

  // Queues `job`; first rethrows the error of a job that failed.
  void post(std::function<void()> job) {
    std::unique_lock lock(m_);
    changed_.wait(lock, [&] { return error_ || jobs_.size() < max_waiting_; });
    if (error_) std::rethrow_exception(error_);
    jobs_.push_back(std::move(job));
    lock.unlock();
    changed_.notify_all();
  }

  // Waits until every job posted has run (or been dropped after a failure); rethrows the error
  // of a job that failed.
  void drain() {
    wait_idle();
    std::lock_guard lock(m_);
    if (error_) std::rethrow_exception(error_);
  }

  // As drain(), without the error: for a writer that stops whatever happened.
  void wait_idle() noexcept {
    std::unique_lock lock(m_);
    changed_.wait(lock, [&] { return jobs_.empty() && !busy_; });
  }

 private:
  void loop() {
    std::unique_lock lock(m_);
    for (;;) {
      changed_.wait(lock, [&] { return quit_ || !jobs_.empty(); });
      if (jobs_.empty()) return;  // quit_, nothing left
      std::function<void()> job = std::move(jobs_.front());
      jobs_.pop_front();
      busy_ = true;
      const bool skip = static_cast<bool>(error_);
      lock.unlock();
      changed_.notify_all();  // room for a waiting post()
      std::exception_ptr error;
      if (!skip) {
        try {
          job();
        } catch (...) {
          error = std::current_exception();
        }
      }
      job = nullptr;  // release what the job held before reporting it done
      lock.lock();
      busy_ = false;
      if (error && !error_) error_ = error;
      changed_.notify_all();
    }
  }

  const std::size_t max_waiting_;
  std::mutex m_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> jobs_;
  bool busy_ = false;
  bool quit_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: started once the rest is built
};

}  // namespace crowddb::io
