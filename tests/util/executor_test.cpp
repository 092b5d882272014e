#include "util/executor.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

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

// A cheap pass's grain: at most the coarse one, and no finer than 512 rows (nor than the coarse
// one, when that is smaller); in between, ceil(n / 16): exactly 16 chunks.
TEST(Executor, ChunkRowsGivesSixteenChunksBetweenTheCoarseGrainAnd512Rows) {
  EXPECT_EQ(chunk_rows(20000, 4096), 1250u);    // 5 chunks of the coarse grain: 16 now
  EXPECT_EQ(chunk_rows(20001, 4096), 1251u);    // rounded up, so that 16 chunks cover the rows
  EXPECT_EQ(chunk_rows(1000000, 4096), 4096u);  // plenty of chunks already
  EXPECT_EQ(chunk_rows(3000, 4096), 512u);      // small tables: 512 rows a chunk (6 chunks)
  EXPECT_EQ(chunk_rows(0, 4096), 512u);
  EXPECT_EQ(chunk_rows(100000, 256), 256u);  // never coarser than asked
  for (std::size_t n : {1u, 511u, 8191u, 8192u, 8193u, 20001u, 65536u, 1000003u})
    for (std::size_t most : {1u, 300u, 4096u, 16384u}) {
      const std::size_t g = chunk_rows(n, most);
      EXPECT_LE(g, most);
      EXPECT_GE(g, std::min<std::size_t>(most, 512));
      if (g < most && g > 512) {
        EXPECT_EQ((n + g - 1) / g, 16u) << n << " " << most;
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

// both(): each task once, the loops each runs whole (nested, on the shared threads), and on one
// thread g before f.
TEST(Executor, BothRunsEachTaskOnceWithItsOwnLoops) {
  for (int threads : {1, 2, 4}) {
    Executor ex(threads);
    for (int round = 0; round < 20; ++round) {
      std::vector<int> a(5000, 0), b(3001, 0);
      std::atomic<int> f_runs{0}, g_runs{0};
      std::vector<char> order;
      std::mutex m;
      ex.both(
          [&] {
            ++f_runs;
            {
              std::lock_guard lock(m);
              order.push_back('f');
            }
            ex.for_each_chunk(a.size(), 64, [&](std::size_t lo, std::size_t hi) {
              for (std::size_t i = lo; i < hi; ++i) a[i] += static_cast<int>(i);
            });
          },
          [&] {
            ++g_runs;
            {
              std::lock_guard lock(m);
              order.push_back('g');
            }
            ex.for_each_chunk(b.size(), 7, [&](std::size_t lo, std::size_t hi) {
              for (std::size_t i = lo; i < hi; ++i) b[i] += 2 * static_cast<int>(i);
            });
          });
      EXPECT_EQ(f_runs.load(), 1);
      EXPECT_EQ(g_runs.load(), 1);
      for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], static_cast<int>(i));
      for (std::size_t i = 0; i < b.size(); ++i) ASSERT_EQ(b[i], 2 * static_cast<int>(i));
      if (threads == 1) {
        EXPECT_EQ(order, (std::vector<char>{'g', 'f'}));
      }
    }
  }
}

TEST(Executor, BothRethrowsEitherTasksException) {
  for (int threads : {1, 2}) {
    Executor ex(threads);
    const auto throws = [] { throw std::runtime_error("f"); };
    const auto loop_throws = [&] {
      ex.for_each_chunk(100, 10, [](std::size_t b, std::size_t) {
        if (b == 50) throw std::logic_error("g");
      });
    };
    EXPECT_THROW(ex.both(throws, [] {}), std::runtime_error);
    EXPECT_THROW(ex.both([] {}, loop_throws), std::logic_error);
    // Still usable afterwards.
    int ran = 0;
    ex.both([&] { ++ran; }, [&] { ++ran; });
    EXPECT_EQ(ran, 2);
  }
}

TEST(Executor, BothRunsTheOtherTaskToTheEndWhenOneThrows) {
  // A task that throws at once beside one that runs a loop of many chunks: the loop is not cut
  // short (oneTBB would cancel it with the group) and f's exception wins over g's.
  for (int threads : {1, 2}) {
    for (int round = 0; round < 20; ++round) {
      Executor ex(threads);
      std::vector<std::atomic<int>> hits(4000);
      const auto long_loop = [&] {
        ex.for_each_chunk(hits.size(), 1, [&](std::size_t b, std::size_t e) {
          volatile double sink = 0;
          for (int k = 0; k < 200; ++k) sink = sink + k;
          for (std::size_t i = b; i < e; ++i) ++hits[i];
        });
      };
      EXPECT_THROW(ex.both([] { throw std::runtime_error("f"); }, long_loop), std::runtime_error);
      for (auto& h : hits) ASSERT_EQ(h.load(), 1) << threads;
      for (auto& h : hits) h = 0;
      EXPECT_THROW(ex.both(long_loop, [] { throw std::logic_error("g"); }), std::logic_error);
      for (auto& h : hits) ASSERT_EQ(h.load(), 1) << threads;
      EXPECT_THROW(
          ex.both([] { throw std::runtime_error("f"); }, [] { throw std::logic_error("g"); }),
          std::runtime_error);
    }
  }
}

}  // namespace
}  // namespace crowddb
