// DocBuilder::free, the importers' placement test: through an obstacle lookup rebuilt as
// obstacles are added, against the scan of every obstacle (free_by_scan), query for query.
#include "io/import/builder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "util/rng.hpp"

namespace crowddb::io {
namespace {

// Obstacles added in bursts between queries, as the importers do (SteerSuite's obstacle
// regions place each box with free() against the ones before it): boxes, rotated boxes,
// triangles, circles, a few huge ones that span the scene, and discs placed to touch an
// obstacle exactly or to miss it by a rounding's width.
TEST(DocBuilder, FreeThroughTheLookupIsTheScan) {
  for (const uint64_t seed : {1u, 2u, 3u}) {
    Rng rng(seed);
    DocBuilder b;
    std::size_t queries = 0, blocked = 0, agents = 0;
    for (int burst = 0; burst < 40; ++burst) {
      const int adds = burst < 5 ? 3 : static_cast<int>(rng.below(60)) + 1;
      for (int a = 0; a < adds; ++a) {
        const double x = rng.uniform(-100, 100), y = rng.uniform(-100, 100);
        switch (rng.below(6)) {
          case 0:
          case 1: {
            const double w = rng.uniform(0.2, 4), h = rng.uniform(0.2, 4);
            b.polygon({{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, "test");
            break;
          }
          case 2: {
            const double t = rng.uniform(0, std::numbers::pi), c = std::cos(t), s = std::sin(t);
            b.polygon(
                {{x, y}, {x + 3 * c, y + 3 * s}, {x + 3 * c - s, y + 3 * s + c}, {x - s, y + c}},
                "test");
            break;
          }
          case 3:
            b.polygon({{x, y}, {x + 2, y + 0.5}, {x + 0.5, y + 2}}, "test");
            break;
          case 4:
            b.circle({x, y}, rng.uniform(0.1, 3), "test");
            break;
          default:
            if (rng.below(8) == 0)  // a long wall across the scene
              b.polygon({{-120, y}, {120, y}, {120, y + 0.3}, {-120, y + 0.3}}, "test");
            else
              b.circle({x, y}, rng.uniform(0.1, 0.5), "test");
        }
      }
      for (int q = 0; q < 300; ++q) {
        double x = rng.uniform(-130, 130), y = rng.uniform(-130, 130);
        const double r = rng.below(10) == 0 ? 0 : rng.uniform(0.1, 1.5);
        if (q % 5 == 0) {  // exactly beside a box's right edge, touching or a hair apart
          x = std::round(x) + r;
          y = std::round(y);
          if (q % 10 == 0) x = std::nextafter(x, INFINITY);
        }
        const bool with_agents = q % 3 != 0;
        const bool got = b.free(x, y, r, with_agents);
        ASSERT_EQ(got, b.free_by_scan(x, y, r, with_agents))
            << "seed " << seed << " burst " << burst << " query " << q << " at (" << x << ", " << y
            << ") r " << r;
        ++queries;
        blocked += !got;
        if (got && q % 7 == 0) {
          b.occupy(x, y, r);
          ++agents;
        }
      }
    }
    // Both answers occur, so the comparison says something.
    EXPECT_GT(blocked, queries / 20) << "seed " << seed;
    EXPECT_LT(blocked, queries - queries / 20) << "seed " << seed;
    EXPECT_GT(agents, 100u);
  }
}

// Queries far outside the obstacles and with a disc wider than the scene: the lookup's border
// cells and its "scan them all" cases.
TEST(DocBuilder, FreeFarAwayAndWideIsTheScan) {
  DocBuilder b;
  for (int k = 0; k < 200; ++k)
    b.circle({static_cast<double>(k % 20), static_cast<double>(k / 20)}, 0.3, "test");
  for (const double r : {0.0, 0.2, 0.7, 5.0, 1e4})
    for (const double x : {-1e6, -0.5, 0.0, 0.7, 0.5, 19.3, 1e6})
      for (const double y : {-1e6, 0.0, 4.5, 9.0, 1e6})
        ASSERT_EQ(b.free(x, y, r, false), b.free_by_scan(x, y, r, false))
            << "(" << x << ", " << y << ") r " << r;
  EXPECT_FALSE(b.free(0.5, 0, 0.2001, false));  // touches circles 0 and 1
  EXPECT_TRUE(b.free(0.5, 0, 0.19, false));
  EXPECT_FALSE(b.free(100, 100, 1e4, false));
}

}  // namespace
}  // namespace crowddb::io
