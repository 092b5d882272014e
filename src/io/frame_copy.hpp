// A frame's rows copied out of the agent table, for a writer's thread (io/write_behind.hpp) to
// write while the simulation goes on. At most `most` frames are held at once: copy() waits for
// a buffer the writer's thread is done with (a frame of 10^6 agents is 64 MB).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "io/trajectory.hpp"

namespace crowddb::io {

// The trajectory writers' frames held at once (copied, waiting or being written). One is as fast
// as two: the next frame is copied once the last one is written, the tick between them
// overlapping the writing (airport-20k).
inline constexpr std::size_t kWriterFrameBuffers = 1;

struct FrameRow {
  uint64_t id;
  double x, y, vx, vy, radius;
  const char* state;  // agent_state_name: a string literal
  uint32_t goal;
};

class FrameCopies {
 public:
  using Rows = std::shared_ptr<std::vector<FrameRow>>;

  explicit FrameCopies(std::size_t most) : most_(most ? most : 1) {
    spare_.reserve(most_);  // giving back never allocates
  }
  // Waits for every copy to be given back: they point here.
  ~FrameCopies() {
    std::unique_lock lock(m_);
    freed_.wait(lock, [&] { return spare_.size() == made_; });
  }
  FrameCopies(const FrameCopies&) = delete;
  FrameCopies& operator=(const FrameCopies&) = delete;

  // The rows of `t` in the table's order, each with its state (agent_state_name); the buffer
  // goes back to be reused when the last copy of the pointer is gone (the job done or dropped).
  Rows copy(const AgentTable& t, uint64_t stall_after) {
    std::unique_ptr<std::vector<FrameRow>> buffer;
    {
      std::unique_lock lock(m_);
      freed_.wait(lock, [&] { return !spare_.empty() || made_ < most_; });
      if (spare_.empty()) {
        buffer = std::make_unique<std::vector<FrameRow>>();
        ++made_;
      } else {
        buffer = std::move(spare_.back());
        spare_.pop_back();
      }
    }
    // Owned by the pointer before it grows: a resize that throws (out of memory) gives it back.
    Rows rows(buffer.release(), [this](std::vector<FrameRow>* done) { give_back(done); });
    rows->resize(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) {
      FrameRow& r = (*rows)[i];
      r.id = t.id[i];
      r.x = t.x[i];
      r.y = t.y[i];
      r.vx = t.vx[i];
      r.vy = t.vy[i];
      r.radius = t.radius[i];
      r.state = agent_state_name(t, i, stall_after);
      r.goal = t.goal[i];
    }
    return rows;
  }

 private:
  void give_back(std::vector<FrameRow>* done) {
    {
      std::lock_guard lock(m_);
      spare_.emplace_back(done);
    }
    freed_.notify_all();
  }

  const std::size_t most_;
  std::mutex m_;
  std::condition_variable freed_;
  std::vector<std::unique_ptr<std::vector<FrameRow>>> spare_;
  std::size_t made_ = 0;
};

}  // namespace crowddb::io
