// Runs the set-at-a-time stages of a tick on a few threads without hurting a busy machine.
//
// DESIGN.md §3: a statically split parallel loop ends in a barrier that waits for a descheduled
// worker (RVO2's step ran 24x slower at 2 threads with one core taken). So: the calling thread
// works too, chunks are handed out on demand (oneTBB's work stealing), and idle workers sleep
// rather than spin. Results never depend on how chunks land on threads: every body writes only
// the rows of its own chunk, and reductions are done afterwards in row order. A body keeps its
// counters and appends in locals and stores them into its per-chunk slot once, at its end:
// neighbouring chunks' slots share a cache line, and the threads work on neighbouring chunks.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <memory>

namespace crowddb {

// Rows per chunk for a cheap pass over n rows: `most`, but no more than gives 16 chunks, and no
// fewer than 512 rows (or `most`, when that is less): at most 16 chunks of n, or chunks of `most`
// rows. A coarse grain that suits 10^6 rows leaves a few thousand in two or three chunks, and two
// threads sharing three chunks take two thirds of the one thread's time. It depends on n alone,
// never on the number of threads, so per-chunk results stay the same on any.
inline std::size_t chunk_rows(std::size_t n, std::size_t most) {
  constexpr std::size_t kChunks = 16, kLeast = 512;
  return std::max(std::min(most, (n + kChunks - 1) / kChunks), std::min(most, kLeast));
}

class Executor {
 public:
  // threads >= 1; 1 runs everything inline on the caller, with no thread pool at all.
  explicit Executor(int threads = 1);
  ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  int threads() const { return threads_; }

  // Calls body(begin, end) for the chunks [k*grain, min(n, (k+1)*grain)) covering [0, n), in any
  // order and on any thread; the boundaries are fixed, so per-chunk buffers may be indexed by
  // begin / grain.
  // A body may itself call for_each_chunk (nested loops share the threads); so may the two
  // tasks of both(). An exception thrown by a body is rethrown.
  void for_each_chunk(std::size_t n, std::size_t grain,
                      const std::function<void(std::size_t, std::size_t)>& body);

  // Runs f and g, which must not depend on each other, at once: each may run its own loops
  // (for_each_chunk), and a thread done with one helps with the other's. For a step that one
  // thread does alone (an index's placement pass) beside a parallel stage it need not wait for:
  // the second thread does not idle through it. With one thread, g then f. Both run to the end
  // whatever the other throws; then f's exception is rethrown, else g's.
  void both(const std::function<void()>& f, const std::function<void()>& g);

 private:
  struct Arena;
  int threads_;
  std::unique_ptr<Arena> arena_;
};

}  // namespace crowddb
