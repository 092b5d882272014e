// The randomized buffer-sizing checks of buffer_checks.hpp on thousands of graphs (label slow).
#include "buffer_checks.hpp"

namespace sdf {
namespace {

TEST(BuffersSlow, BoundedThroughputAgreesWithBothMethods) {
  test::bounded_throughput_agrees(8001, 5000);
}

TEST(BuffersSlow, MinimalStorageMatchesEnumeration) {
  test::minimal_storage_matches(8002, 3000);
}

TEST(BuffersSlow, ParetoMatchesEnumeration) {
  test::pareto_matches(8003, 1000);
}

TEST(BuffersSlow, MinBufferScheduleIsValidAndMinimal) {
  test::min_buffer_schedule_minimal(8004, 5000);
}

}  // namespace
}  // namespace sdf
