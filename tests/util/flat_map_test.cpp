// FlatMap against std::unordered_map: the same answers over random, consecutive and adversarial
// keys, through every growth.
#include "util/flat_map.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "util/rng.hpp"

namespace crowddb {
namespace {

TEST(FlatMap, AgreesWithAnUnorderedMapThroughEveryGrowth) {
  constexpr uint32_t kNone = UINT32_MAX;
  Rng rng(5);
  for (int pattern = 0; pattern < 4; ++pattern) {
    SCOPED_TRACE("pattern " + std::to_string(pattern));
    FlatMap<uint32_t, kNone> map;
    std::unordered_map<uint64_t, uint32_t> want;
    std::vector<uint64_t> keys;
    for (uint32_t k = 0; k < 5000; ++k) {
      uint64_t key = 0;
      switch (pattern) {
        case 0:  // random 64-bit keys
          key = rng.next();
          break;
        case 1:  // consecutive ids from 0
          key = k;
          break;
        case 2:  // equal low bits: multiples of 2^20, and the extremes
          key = k == 0 ? UINT64_MAX : static_cast<uint64_t>(k) << 20;
          break;
        default:  // a few keys over and over, others new
          key = rng.below(3) == 0 ? rng.below(50) : rng.next();
          break;
      }
      keys.push_back(key);
      const auto [it, fresh] = want.try_emplace(key, k);
      uint32_t& v = map.at(key);
      EXPECT_EQ(v == kNone, fresh);
      if (fresh) v = k;
      ASSERT_EQ(map.size(), want.size());
      if (k % 97 == 0) {  // everything inserted so far is found, with its value
        for (const uint64_t q : keys) ASSERT_EQ(map.find(q), want.at(q));
      }
    }
    for (int q = 0; q < 2000; ++q) {  // keys never inserted
      const uint64_t key = rng.next();
      EXPECT_EQ(map.find(key), want.count(key) ? want.at(key) : kNone);
    }
    map.reserve(100000);  // growth by reserve keeps every entry
    for (const uint64_t q : keys) ASSERT_EQ(map.find(q), want.at(q));
    map.clear();
    EXPECT_EQ(map.size(), 0u);
    EXPECT_EQ(map.find(keys.front()), kNone);
  }
}

}  // namespace
}  // namespace crowddb
