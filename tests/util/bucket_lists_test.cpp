// fill_bucket_lists (util/bucket_lists.hpp) against a list per bucket filled in item order.
#include "util/bucket_lists.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "util/rng.hpp"

namespace crowddb {
namespace {

TEST(BucketLists, AsAListPerBucketInItemOrder) {
  Rng rng(17);
  for (int trial = 0; trial < 50; ++trial) {
    // Empty buckets, empty items, items in no bucket, in one, in several (and repeated).
    const std::size_t buckets = rng.below(20), items = rng.below(60);
    std::vector<std::vector<std::size_t>> of(items);
    for (auto& bs : of)
      if (buckets > 0)
        for (std::size_t m = rng.below(5); m-- > 0;) bs.push_back(rng.below(buckets));
    std::vector<std::vector<uint32_t>> want(buckets);
    for (std::size_t k = 0; k < items; ++k)
      for (std::size_t b : of[k]) want[b].push_back(static_cast<uint32_t>(k));
    std::vector<uint32_t> start = {7, 7}, ids = {1, 2, 3};  // overwritten
    fill_bucket_lists(
        buckets, items,
        [&](std::size_t k, auto&& to) {
          for (std::size_t b : of[k]) to(b);
        },
        start, ids);
    ASSERT_EQ(start.size(), buckets + 1) << "trial " << trial;
    EXPECT_EQ(start[0], 0u);
    EXPECT_EQ(start.back(), ids.size());
    for (std::size_t b = 0; b < buckets; ++b)
      EXPECT_EQ(std::vector<uint32_t>(ids.begin() + start[b], ids.begin() + start[b + 1]), want[b])
          << "trial " << trial << " bucket " << b;
  }
}

}  // namespace
}  // namespace crowddb
