// CSV trajectories: PATH holds frame,id,x,y,vx,vy,radius,state,goal; PATH with its extension
// replaced by .metrics.csv holds one row of tick metrics per tick, and by .steerbench.csv the
// SteerBench metrics per agent (src/metrics/steerbench.hpp). Numbers are written in shortest
// round-trip form, so a CSV run reads back bit-identical. The streams are flushed in batches
// (io/trajectory.hpp); a stopped run keeps its .partial files (the metrics file's last row is
// the last tick). Frames and metrics are written by a thread of the writer's own
// (io/write_behind.hpp) while the simulation goes on; finish and stop wait for it.
#include <charconv>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <optional>
#include <vector>

#include "io/frame_copy.hpp"
#include "io/output_lock.hpp"
#include "io/trajectory.hpp"
#include "io/write_behind.hpp"

namespace crowddb::io {
namespace {

class CsvWriter final : public TrajectoryWriter {
 public:
  CsvWriter(std::filesystem::path path, uint32_t every)
      : path_(std::move(path)), every_(every ? every : 1) {
    metrics_path_ = path_;
    metrics_path_.replace_extension(".metrics.csv");
    steerbench_path_ = path_;
    steerbench_path_.replace_extension(".steerbench.csv");
  }
  ~CsvWriter() override { stop(0, "the run ended without finishing its output"); }

  void begin(const Scenario& sc, const World&) override {
    dt_ = sc.config.dt;
    stall_after_ = sc.config.ticks_for(sc.config.stall.after);
    lock_.emplace(path_);
    for (const auto* p : {&path_, &metrics_path_, &steerbench_path_}) {
      std::error_code ec;
      if (std::filesystem::exists(partial(*p), ec))
        throw Error(Error::Kind::io, partial(*p).string() +
                                         ": an earlier run's unfinished output is kept here; "
                                         "move or remove it first");
    }
    batch_start_ = std::chrono::steady_clock::now();
    open(traj_, partial(path_), "frame,id,x,y,vx,vy,radius,state,goal\n");
    open(metrics_, partial(metrics_path_),
         "tick,time,agents,entered,arrived,frozen,freeze_iterations,overlapping_pairs,"
         "obstacle_overlaps,gridlocked,stalled,queueing,longest_stall,tick_seconds,state_hash\n");
    behind_.emplace(kWriterJobsWaiting);
  }

  // The frame's rows are copied now and written by the writer's thread.
  void frame(uint64_t tick, const World& world) override {
    if (tick % every_ != 0) return;
    const uint64_t frame = tick / every_;
    FrameCopies::Rows rows = copies_.copy(world.agents(), stall_after_);
    behind_->post([this, frame, rows] { write_frame(frame, *rows); });
  }

  void metrics(const TickMetrics& m) override {
    behind_->post([this, m] { write_metrics(m); });
  }

  void write_frame(uint64_t frame, const std::vector<FrameRow>& rows) {
    // Formatted into one buffer with to_chars (no string per number), written in pieces.
    constexpr std::size_t kRowChars = 2 * 21 + 5 * 25 + 9 + 11 + 9;  // widest row, with commas
    buf_.resize(1 << 16);
    char* const buf = buf_.data();
    char* const end = buf + buf_.size();
    char* at = buf;
    const auto put = [&](auto v) { at = std::to_chars(at, end, v).ptr; };
    for (const FrameRow& r : rows) {
      if (end - at < static_cast<std::ptrdiff_t>(kRowChars)) {
        traj_.write(buf, at - buf);
        at = buf;
      }
      put(frame);
      *at++ = ',';
      put(r.id);
      for (double v : {r.x, r.y, r.vx, r.vy, r.radius}) {
        *at++ = ',';
        put(v);
      }
      *at++ = ',';
      for (const char* c = r.state; *c;) *at++ = *c++;
      *at++ = ',';
      put(r.goal);
      *at++ = '\n';
    }
    traj_.write(buf, at - buf);
    check(traj_, path_);
  }

  void write_metrics(const TickMetrics& m) {
    char hash[24];
    std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(m.state_hash));
    metrics_ << m.tick << "," << num(m.time) << "," << m.agents << "," << m.entered << ","
             << m.arrived << "," << m.frozen << "," << m.freeze_iterations << ","
             << m.overlapping_pairs << "," << m.obstacle_overlaps << "," << m.gridlocked << ","
             << m.stalled << "," << m.queueing << ","
             << num(static_cast<double>(m.longest_stall) * dt_) << "," << num(m.seconds) << ","
             << hash << "\n";
    check(metrics_, metrics_path_);
    if (std::chrono::steady_clock::now() - batch_start_ >= std::chrono::seconds(2)) {
      traj_.flush();
      metrics_.flush();
      check(traj_, path_);
      check(metrics_, metrics_path_);
      batch_start_ = std::chrono::steady_clock::now();
    }
  }

  void finish(const RunInfo& info) override {
    behind_->drain();
    traj_.close();
    metrics_.close();
    check(traj_, path_);
    check(metrics_, metrics_path_);
    open(steerbench_, partial(steerbench_path_),
         "id,collisions,time,path_length,energy,acceleration,score01,score02,arrived\n");
    if (info.steerbench)
      info.steerbench->for_each_score([&](const metrics::AgentScore& a) {
        steerbench_ << a.id << "," << a.collisions << "," << num(a.time) << ","
                    << num(a.path_length) << "," << num(a.energy) << "," << num(a.acceleration)
                    << "," << num(a.score01()) << "," << num(a.score02()) << ","
                    << (a.arrived ? 1 : 0) << "\n";
      });
    steerbench_.close();
    check(steerbench_, steerbench_path_);
    for (const auto* p : {&path_, &metrics_path_, &steerbench_path_}) {
      std::error_code ec;
      std::filesystem::rename(partial(*p), *p, ec);
      if (ec)
        throw Error(Error::Kind::io,
                    p->string() + ": cannot move output into place: " + ec.message());
    }
    lock_.reset();
  }

  std::filesystem::path stop(uint64_t, const std::string&) noexcept override {
    if (behind_) behind_->wait_idle();  // what is queued is written, up to a failed write
    const bool begun = traj_.is_open();
    if (traj_.is_open()) traj_.close();
    if (metrics_.is_open()) metrics_.close();
    if (steerbench_.is_open()) steerbench_.close();
    lock_.reset();
    return begun ? partial(path_) : std::filesystem::path();
  }

 private:
  double dt_ = 1;                      // [s] per tick, for the metrics in seconds
  uint64_t stall_after_ = UINT64_MAX;  // [ticks] the stall watch's threshold, for the states
  static std::filesystem::path partial(const std::filesystem::path& p) {
    return p.string() + ".partial";
  }
  static std::string num(double v) {
    char buf[32];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, end);
  }
  static void open(std::ofstream& f, const std::filesystem::path& p, const char* header) {
    f.open(p, std::ios::binary | std::ios::trunc);
    if (!f) throw Error(Error::Kind::io, p.string() + ": cannot create output");
    f << header;
  }
  static void check(const std::ofstream& f, const std::filesystem::path& p) {
    if (!f) throw Error(Error::Kind::io, p.string() + ": write failed");
  }

  std::filesystem::path path_, metrics_path_, steerbench_path_;
  uint32_t every_;
  std::ofstream traj_, metrics_, steerbench_;
  std::vector<char> buf_;  // a frame's rows, formatted
  std::chrono::steady_clock::time_point batch_start_;
  std::optional<OutputLock> lock_;
  FrameCopies copies_{kWriterFrameBuffers};
  std::optional<WriteBehind> behind_;  // last: stopped before the rest goes
};

}  // namespace

std::unique_ptr<TrajectoryWriter> make_csv_writer(const std::filesystem::path& path,
                                                  uint32_t every) {
  return std::make_unique<CsvWriter>(path, every);
}

}  // namespace crowddb::io
