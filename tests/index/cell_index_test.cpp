#include "index/cell_index.hpp"

#include <gtest/gtest.h>

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
      for (int i = 0; i < 200; ++i)
        for (int j = 0; j < 200; ++j)
          t.push_back(static_cast<uint64_t>(i * 200 + j), i * 0.25, j * 0.25, 0, 0, 0.2);
    } else {
      t = build::uniform(shape == 0 ? 2 * CellIndex::kParallelRadix + 99 : 34000,
                         {0, 0, shape == 0 ? 600.0 : 300.0, shape == 0 ? 600.0 : 60.0}, 1, 0.25,
                         0.25, 7 + static_cast<uint64_t>(shape));
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
        ASSERT_GT(one.size(), 16384u);  // large enough to be built in chunks
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

}  // namespace
}  // namespace crowddb::index
