#include "index/cell_index.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "scenario/builders.hpp"

namespace crowddb::index {
namespace {

// A large build runs its passes in chunks on the executor's threads (the uniform square is large
// enough for the radix sort's too); the index (keys, rows in key order, the copied columns) must
// be the one thread's, entry for entry.
TEST(CellIndex, ThreadsBuildTheSameIndex) {
  for (int shape = 0; shape < 3; ++shape) {
    DiscTable t;
    if (shape == 2) {  // a lattice: runs of equal keys, where a stable sort shows
      for (int i = 0; i < 400; ++i)
        for (int j = 0; j < 400; ++j)
          t.push_back(static_cast<uint64_t>(i * 400 + j), i * 0.25, j * 0.25, 0, 0, 0.2);
    } else {
      t = build::uniform(shape == 0 ? 2 * CellIndex::kParallelRadix + 99 : 140000,
                         {0, 0, 600.0, shape == 0 ? 600.0 : 120.0}, 1, 0.25, 0.25,
                         7 + static_cast<uint64_t>(shape));
    }
    const DiscView d = t.view();
    const Frame frame = Frame::of(d);
    std::vector<uint32_t> every_other;
    for (uint32_t i = 0; i < d.n; i += 2) every_other.push_back(i);
    for (const bool subset : {false, true}) {
      const std::span<const uint32_t> rows =
          subset ? std::span<const uint32_t>(every_other) : std::span<const uint32_t>();
      CellIndex one;
      one.build(d, rows, frame, 0.25);
      for (int threads : {2, 3}) {
        Executor ex(threads);
        CellIndex many;
        many.build(d, rows, frame, 0.25, &ex);
        SCOPED_TRACE("shape " + std::to_string(shape) + " subset " + std::to_string(subset) +
                     " threads " + std::to_string(threads));
        ASSERT_EQ(many.size(), one.size());
        // Large enough to be built in chunks (the subsets of the first shape too).
        if (!subset || shape == 0) {
          ASSERT_GE(one.size(), 2 * kRadixChunk);
        }
        for (std::size_t k = 0; k < one.size(); ++k) {
          ASSERT_EQ(many.key(k), one.key(k)) << k;
          ASSERT_EQ(many.row(k), one.row(k)) << k;
          ASSERT_EQ(many.x(k), one.x(k)) << k;
          ASSERT_EQ(many.y(k), one.y(k)) << k;
          ASSERT_EQ(many.r(k), one.r(k)) << k;
        }
      }
    }
  }
}

// Sorts n random words whose key is bits [lo, lo + bits) on 1, 2 and 3 threads (see below).
void sort_and_compare(std::size_t n) {
  std::mt19937_64 rng(11);
  for (int bits : {0, 1, 9, 12, 13, 23, 24, 25, 27, 32, 40}) {
    const int lo = bits > 32 ? 20 : 28;  // the key's lowest bit (a row below it)
    const uint64_t key_mask = (uint64_t{1} << bits) - 1;
    std::vector<uint64_t> words(n);
    const uint64_t keys = std::max<uint64_t>(1, std::min<uint64_t>(key_mask + 1, n / 3));
    for (std::size_t k = 0; k < n; ++k) {
      const uint64_t key = ((rng() % keys) << (bits - std::min(bits, 20))) & key_mask;
      const uint64_t above = rng() >> (lo + bits);  // bits above the key: not part of it
      words[k] = (above << (lo + bits)) | key << lo | (k & ((uint64_t{1} << lo) - 1));
    }
    std::vector<uint64_t> expect = words;
    std::stable_sort(expect.begin(), expect.end(), [&](uint64_t a, uint64_t b) {
      return (a >> lo & key_mask) < (b >> lo & key_mask);
    });
    RadixScratch scratch;
    std::vector<uint64_t> one = words;
    radix_sort(one, scratch, lo, lo + bits);
    EXPECT_EQ(one, expect) << bits << " bits, one thread";
    for (int threads : {2, 3}) {
      Executor ex(threads);
      std::vector<uint64_t> many = words;
      radix_sort(many, scratch, lo, lo + bits, &ex);
      EXPECT_EQ(many, expect) << bits << " bits, " << threads << " threads";
    }
  }
}

// The radix sort on threads is the one-thread sort, which is std::stable_sort by the key bits:
// keys of 0 to 40 bits (no pass up to four passes, digits of 9 to 12 bits, a narrower last one),
// with many equal keys and bits set above the key that must not count, over enough words for
// several chunks and a short last one, over fewer than a chunk, and over none.
TEST(RadixSort, ThreadsSortAsOneThreadAndAsAStableSort) {
  for (std::size_t n : {3 * kRadixChunk + 17, std::size_t{1000}, std::size_t{0}}) {
    SCOPED_TRACE(n);
    sort_and_compare(n);
  }
}

}  // namespace
}  // namespace crowddb::index
