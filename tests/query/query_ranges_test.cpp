// The input ranges of first-to-collide and the collision set (crowddb/query.hpp): at their edges
// every method is still exact; beyond them the call is refused instead of answered wrongly
// (issue 13: agents head-on at +-1e160 m/tick used to "never collide" on every method).
#include <gtest/gtest.h>

#include <cmath>

#include "crowddb/error.hpp"
#include "crowddb/query.hpp"

namespace crowddb {
namespace {

DiscTable head_on(double x, double v, double r) {
  DiscTable t;
  t.push_back(1, -x, 0, v, 0, r);
  t.push_back(2, x, 0, -v, 0, r);
  return t;
}

std::string message_of(const auto& call) {
  try {
    call();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::input);
    return e.what();
  }
  return "(no error)";
}

TEST(QueryRanges, HeadOnAtTheLimitsIsExactOnEveryMethod) {
  // Centres 2e9 apart, closing at 2e9 per tick, radii 1: they touch after (2e9 - 2) / 2e9 ticks.
  const DiscTable t = head_on(kMaxCoordinate, kMaxQuerySpeed, 1);
  const StaticScene none;
  for (const std::string& m : ftc_methods()) {
    const auto hits = first_to_collide(t.view(), none, kMaxQueryHorizon, m);
    ASSERT_EQ(hits.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(hits[i].with.kind, Collider::Kind::agent) << m;
      EXPECT_EQ(hits[i].with.row, 1 - i) << m;
      EXPECT_NEAR(hits[i].time, 1 - 1e-9, 1e-15) << m;
    }
  }
}

TEST(QueryRanges, OverflowingVelocitiesAreRefusedNotMissed) {
  // The reproducer: +-1e160 squared overflows to infinity and the pair was "never".
  const StaticScene none;
  for (double v : {1e160, 1e308, kMaxQuerySpeed * 2}) {
    const DiscTable t = head_on(5, v, 0.5);
    const std::string msg = message_of([&] { first_to_collide(t.view(), none, 30, "naive"); });
    EXPECT_NE(msg.find("agent id 1 vx"), std::string::npos) << msg;
    EXPECT_NE(msg.find("outside [-1e9, 1e9]"), std::string::npos) << msg;
  }
  const DiscTable far = head_on(2e9, 1, 0.5);
  EXPECT_NE(message_of([&] { collision_set(far.view(), none); }).find("agent id 1 x"),
            std::string::npos);
  const DiscTable ok = head_on(5, 1, 0.5);
  for (double h : {-1.0, double(NAN), double(INFINITY), 2e9})
    EXPECT_NE(message_of([&] { first_to_collide(ok.view(), none, h); }).find("horizon"),
              std::string::npos)
        << h;
  const StaticScene far_circle({CircleObstacle{3e9, 0, 1, 1}}, {}, 1);
  EXPECT_NE(message_of([&] { collision_set(ok.view(), far_circle); }).find("obstacle circle 0 x"),
            std::string::npos);
}

}  // namespace
}  // namespace crowddb
