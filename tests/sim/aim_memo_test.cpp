// The aim-point memo against its naive twin: goal_target asked directly.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <vector>

#include "sim/stages.hpp"
#include "util/rng.hpp"
#include "world/geometry.hpp"

namespace crowddb::sim {
namespace {

bool same_bits(Vec2 a, Vec2 b) {
  return std::bit_cast<uint64_t>(a.x) == std::bit_cast<uint64_t>(b.x) &&
         std::bit_cast<uint64_t>(a.y) == std::bit_cast<uint64_t>(b.y);
}

// Questions that repeat (a row asked twice at one point), that change one part of the key at a
// time (the point by one ulp or its sign of zero, the radius, the goal), and rows that are asked
// in any order: every answer must be goal_target's, bit for bit.
TEST(AimMemo, AnswersAreGoalTargetsBitForBit) {
  World w(Bounds{-20, -20, 20, 20});
  w.add_goal({"box", 0, 0, 1, 1, {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}});
  w.add_goal({"slot", 5, 0.25, 1, 1, {{4, 0}, {6, 0}, {6, 0.5}, {4, 0.5}}});  // thinner than discs
  w.add_goal({"disc", -5, 5, 1, 1, {}});
  w.add_goal({"L", 10, 1, 1, 1, {{9, 0}, {13, 0}, {13, 2}, {11, 2}, {11, 4}, {9, 4}}});
  const auto goals = w.goals();
  AimMemo memo;
  memo.resize(8, goals);
  EXPECT_EQ(memo.rows_kept(), 8u);
  Rng rng(11);
  struct Question {
    uint32_t goal;
    double x, y, r;
  };
  std::vector<Question> last(8, {0, 3, 3, 0.3});
  std::size_t repeats = 0;
  for (int k = 0; k < 20000; ++k) {
    const std::size_t row = rng.below(8);
    Question q = last[row];
    switch (rng.below(6)) {
      case 0:  // the same question again
        ++repeats;
        break;
      case 1:
        q.x = std::nextafter(q.x, rng.below(2) ? 1e9 : -1e9);
        break;
      case 2:
        q.y = q.y == 0 ? -q.y : (rng.below(4) == 0 ? 0.0 : q.y);
        break;
      case 3:
        q.r = rng.uniform(0, 1.2);
        break;
      case 4:
        q.goal = static_cast<uint32_t>(rng.below(goals.size()));
        break;
      default:
        q = {static_cast<uint32_t>(rng.below(goals.size())), rng.uniform(-15, 15),
             rng.uniform(-15, 15), rng.uniform(0, 1)};
    }
    last[row] = q;
    const Vec2 got = memo.target(goals, q.goal, q.x, q.y, q.r, row);
    const Vec2 want = goal_target(goals[q.goal], q.x, q.y, q.r);
    ASSERT_TRUE(same_bits(got, want)) << "question " << k << " row " << row;
  }
  EXPECT_GT(repeats, 2000u);
  // Resizing keeps no stale answer either: rows beyond the old size start empty.
  memo.resize(2, goals);
  memo.resize(16, goals);
  const Vec2 got = memo.target(goals, 0, 3, 3, 0.3, 12);
  EXPECT_TRUE(same_bits(got, goal_target(goals[0], 3, 3, 0.3)));
}

// Goals that are points are their own aims: the memo keeps no entry for any row, and still
// answers goal_target bit for bit (the rows are far beyond what it holds).
TEST(AimMemo, KeepsNothingWhenEveryGoalIsAPoint) {
  World w(Bounds{-20, -20, 20, 20});
  w.add_goal({"disc", -5, 5, 1, 1, {}});
  w.add_goal({"spot", 7.25, -3.5, 0, 1, {}});
  const auto goals = w.goals();
  AimMemo memo;
  memo.resize(1000, goals);
  EXPECT_EQ(memo.rows_kept(), 0u);
  Rng rng(5);
  for (int k = 0; k < 200; ++k) {
    const auto goal = static_cast<uint32_t>(rng.below(goals.size()));
    const double x = rng.uniform(-15, 15), y = rng.uniform(-15, 15), r = rng.uniform(0, 1);
    const std::size_t row = rng.below(1000);
    ASSERT_TRUE(
        same_bits(memo.target(goals, goal, x, y, r, row), goal_target(goals[goal], x, y, r)));
  }
  // An area among the goals: entries for every row again.
  w.add_goal({"box", 0, 0, 1, 1, {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}});
  memo.resize(1000, w.goals());
  EXPECT_EQ(memo.rows_kept(), 1000u);
}

}  // namespace
}  // namespace crowddb::sim
