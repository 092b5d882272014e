#include "util/executor.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <utility>

namespace crowddb {
namespace {

// Chunk boundaries are part of the contract (per-chunk buffers are indexed by begin / grain), so
// they must be the same on one thread and on several, whatever the timing.
TEST(Executor, ChunksStartAtMultiplesOfTheGrainAndCoverEachRowOnce) {
  for (int threads : {1, 2, 4}) {
    Executor ex(threads);
    for (std::size_t n : {1u, 63u, 64u, 65u, 700u, 10007u}) {
      std::mutex m;
      std::set<std::pair<std::size_t, std::size_t>> seen;
      std::atomic<std::size_t> rows{0};
      ex.for_each_chunk(n, 64, [&](std::size_t b, std::size_t e) {
        rows += e - b;
        std::lock_guard lock(m);
        seen.insert({b, e});
      });
      EXPECT_EQ(rows.load(), n);
      std::size_t expect_begin = 0;
      for (const auto& [b, e] : seen) {
        EXPECT_EQ(b, expect_begin) << "threads=" << threads << " n=" << n;
        EXPECT_EQ(e, std::min(n, b + 64));
        expect_begin = e;
      }
      EXPECT_EQ(expect_begin, n);
    }
  }
}

TEST(Executor, ABodyExceptionReachesTheCaller) {
  Executor ex(2);
  EXPECT_THROW(ex.for_each_chunk(1000, 10,
                                 [](std::size_t b, std::size_t) {
                                   if (b == 500) throw std::runtime_error("boom");
                                 }),
               std::runtime_error);
  EXPECT_THROW(Executor(0), std::invalid_argument);
}

}  // namespace
}  // namespace crowddb
