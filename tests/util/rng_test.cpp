#include "util/rng.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace crowddb {
namespace {

// Rng::direction: unit length, uniform on the circle (sixteen equal sectors each get their
// share within a few standard deviations), the same numbers from the same stream.
TEST(Rng, DirectionsAreUnitAndUniform) {
  Rng rng(42);
  constexpr int kDraws = 160000, kSectors = 16;
  int sector[kSectors] = {};
  double sx = 0, sy = 0;
  for (int k = 0; k < kDraws; ++k) {
    double x = 0, y = 0;
    rng.direction(x, y);
    ASSERT_NEAR(x * x + y * y, 1.0, 1e-15);
    sx += x;
    sy += y;
    const double a = std::atan2(y, x) + std::numbers::pi;  // [0, 2 pi]
    ++sector[std::min(kSectors - 1, static_cast<int>(a / (2 * std::numbers::pi) * kSectors))];
  }
  // Each sector: 10,000 expected, standard deviation ~97.
  for (int c = 0; c < kSectors; ++c) EXPECT_NEAR(sector[c], kDraws / kSectors, 500) << c;
  EXPECT_NEAR(sx / kDraws, 0, 0.01);
  EXPECT_NEAR(sy / kDraws, 0, 0.01);
  Rng a = Rng::stream(7, 3), b = Rng::stream(7, 3);
  for (int k = 0; k < 100; ++k) {
    double ax, ay, bx, by;
    a.direction(ax, ay);
    b.direction(bx, by);
    EXPECT_EQ(ax, bx);
    EXPECT_EQ(ay, by);
  }
}

}  // namespace
}  // namespace crowddb
