#include "util/executor.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <exception>
#include <stdexcept>

namespace crowddb {

struct Executor::Arena {
  explicit Arena(int threads) : arena(threads) {}
  tbb::task_arena arena;
};

Executor::Executor(int threads) : threads_(threads) {
  if (threads < 1) throw std::invalid_argument("Executor: threads must be >= 1");
  if (threads > 1) arena_ = std::make_unique<Arena>(threads);
}

Executor::~Executor() = default;

void Executor::for_each_chunk(std::size_t n, std::size_t grain,
                              const std::function<void(std::size_t, std::size_t)>& body) {
  if (n == 0) return;
  grain = std::max<std::size_t>(grain, 1);
  if (!arena_ || n <= grain) {
    for (std::size_t b = 0; b < n; b += grain) body(b, std::min(n, b + grain));
    return;
  }
  // Split over chunk numbers, not rows: a row range split by oneTBB halves at arbitrary rows, so
  // chunk boundaries (and any per-chunk buffer indexed by begin / grain) would depend on timing.
  const std::size_t chunks = (n + grain - 1) / grain;
  arena_->arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, chunks, 1),
        [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t c = r.begin(); c < r.end(); ++c)
            body(c * grain, std::min(n, (c + 1) * grain));
        },
        tbb::simple_partitioner());
  });
}

void Executor::both(const std::function<void()>& f, const std::function<void()>& g) {
  // Each task's exception is caught in the task itself: one leaving a task of parallel_invoke
  // would cancel the group, and the cancellation would cut the other task's loops short (their
  // parallel_for returning with chunks never run) before the rethrow. Both run to the end; then
  // f's exception is rethrown, else g's.
  std::exception_ptr ef, eg;
  const auto guarded = [](const std::function<void()>& task, std::exception_ptr& caught) {
    return [&task, &caught] {
      try {
        task();
      } catch (...) {
        caught = std::current_exception();
      }
    };
  };
  const auto run_f = guarded(f, ef), run_g = guarded(g, eg);
  if (!arena_) {
    run_g();
    run_f();
  } else {
    arena_->arena.execute([&] { tbb::parallel_invoke(run_f, run_g); });
  }
  if (ef) std::rethrow_exception(ef);
  if (eg) std::rethrow_exception(eg);
}

}  // namespace crowddb
