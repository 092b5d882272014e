// Where streams meet (src/steer/streams.*): the breadth-first marking against its naive twin
// (sweeps until nothing changes) on random and adversarial crowds, on 1 and 2 threads.
#include "steer/streams.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <tuple>

#include "util/executor.hpp"

namespace crowddb::steer {
namespace {

struct StreamCrowd {
  std::vector<double> x, y, radius, wish_x, wish_y;
  std::vector<uint32_t> goal;
  NeighbourLists nb;
  double gap = 1;  // [s]

  std::size_t size() const { return x.size(); }
  void add(double px, double py, double wx, double wy, uint32_t g, double r = 0.25) {
    x.push_back(px);
    y.push_back(py);
    radius.push_back(r);
    wish_x.push_back(wx);
    wish_y.push_back(wy);
    goal.push_back(g);
  }
  // The k nearest others strictly within `range`, nearest first, by brute force.
  void lists(double range, std::size_t k) {
    nb = {};
    nb.offset.push_back(0);
    for (std::size_t i = 0; i < size(); ++i) {
      std::vector<std::pair<double, uint32_t>> c;
      for (std::size_t j = 0; j < size(); ++j) {
        const double d2 = (x[j] - x[i]) * (x[j] - x[i]) + (y[j] - y[i]) * (y[j] - y[i]);
        if (j != i && d2 < range * range) c.push_back({d2, static_cast<uint32_t>(j)});
      }
      std::sort(c.begin(), c.end());
      if (c.size() > k) c.resize(k);
      for (auto [d2, j] : c) {
        nb.row.push_back(j);
        nb.dist2.push_back(d2);
      }
      nb.offset.push_back(static_cast<uint32_t>(nb.row.size()));
    }
  }
  StreamView view() const { return {x, y, radius, goal, wish_x, wish_y, &nb, gap}; }
};

std::size_t streams_count(const std::vector<uint8_t>& m) {
  return static_cast<std::size_t>(std::count(m.begin(), m.end(), 1));
}

// Searches by the table of rows and by binary searches (StreamMarks::by_table) so far.
std::size_t streams_by_table = 0, streams_by_search = 0;

// Marks with both and on 1 and 2 threads; every answer must equal the naive one.
std::vector<uint8_t> streams_checked_marks(const StreamCrowd& c) {
  std::vector<uint8_t> naive;
  mark_meetings_naive(c.view(), naive);
  for (int threads : {1, 2}) {
    Executor ex(threads);
    StreamMarks marks;
    for (int call = 0; call < 2; ++call) {  // the second reuses the vectors
      mark_meetings(c.view(), marks, ex);
      EXPECT_EQ(marks.marked, naive) << threads << " threads, call " << call;
      EXPECT_EQ(marks.count, streams_count(naive));
      if (!marks.edges.empty() && marks.count > 0)
        ++(marks.by_table ? streams_by_table : streams_by_search);
      // The followed entries are the ones within reach that the corridor test names (kept for
      // the rows not at a meeting themselves).
      for (std::size_t i = 0; i < c.size(); ++i) {
        if (at_meeting(c.view(), i)) {
          for (uint32_t a = c.nb.offset[i]; a < c.nb.offset[i + 1]; ++a)
            EXPECT_EQ(marks.follows[a], 0);
          continue;
        }
        const double w = std::sqrt(c.wish_x[i] * c.wish_x[i] + c.wish_y[i] * c.wish_y[i]);
        for (uint32_t a = c.nb.offset[i]; a < c.nb.offset[i + 1]; ++a)
          EXPECT_EQ(marks.follows[a] != 0,
                    w > 0 && follows(c.view(), i, c.nb.row[a], c.wish_x[i] / w, c.wish_y[i] / w));
      }
    }
  }
  return naive;
}

TEST(Streams, RandomCrowdsMarkAsTheNaiveSweeps) {
  std::mt19937_64 rng(11);
  std::size_t marked_total = 0, unmarked_total = 0;
  for (int round = 0; round < 60; ++round) {
    StreamCrowd c;
    // Every tenth crowd large enough for several chunks of the parallel marking.
    const int n = round % 10 == 9 ? 2500 + static_cast<int>(rng() % 2000)
                                  : 20 + static_cast<int>(rng() % 400);
    const double side =
        std::sqrt(n / (0.2 + static_cast<double>(rng() % 30) / 10.0));  // 0.2 to 3.1 per m^2
    const uint32_t goals = 1 + rng() % 4;
    std::uniform_real_distribution<double> pos(0, side), ang(-M_PI, M_PI);
    // Streams: each goal has a heading; wishes scatter around it, some stand.
    std::vector<double> heading(goals);
    for (double& h : heading) h = ang(rng);
    for (int i = 0; i < n; ++i) {
      const auto g = static_cast<uint32_t>(rng() % goals);
      const double a = heading[g] + (rng() % 2 ? 0.0 : ang(rng) / 3);
      const double speed = rng() % 8 == 0 ? 0.0 : 1.3;
      const double px = rng() % 10 == 0 && i > 0 ? c.x.back() : pos(rng);  // some stacked
      c.add(px, pos(rng), speed * std::cos(a), speed * std::sin(a), g,
            0.2 + static_cast<double>(rng() % 6) / 100.0);
    }
    c.lists(1 + static_cast<double>(rng() % 6), 1 + rng() % 12);
    c.gap = 0.25 + static_cast<double>(rng() % 8) / 4;  // 0.25 to 2 s
    const auto m = streams_checked_marks(c);
    marked_total += streams_count(m);
    unmarked_total += m.size() - streams_count(m);
  }
  // Both answers occur often: the comparison is not over trivial inputs.
  EXPECT_GT(marked_total, 2000u);
  EXPECT_GT(unmarked_total, 2000u);
  // And both ways of finding a row's followers were taken, on crowds with few edges and many.
  EXPECT_GT(streams_by_table, 20u);
  EXPECT_GT(streams_by_search, 20u);
}

// A queue of 2,000 in single file whose head meets someone coming the other way: the meeting
// reaches the last in the queue through 1,999 followers, one neighbour list at a time.
TEST(Streams, AMeetingReachesTheEndOfALongQueue) {
  StreamCrowd c;
  for (int i = 0; i < 2000; ++i) c.add(0.6 * i, 0, 1.3, 0, 0);
  c.add(0.6 * 2000, 0, -1.3, 0, 1);  // oncoming, other goal
  c.lists(1.0, 2);                   // each sees only the ones next to it
  const auto m = streams_checked_marks(c);
  EXPECT_EQ(streams_count(m), c.size());
  // The same queue with the one ahead bound for the same goal, or for another but the same
  // way, or standing: no meeting anywhere.
  for (auto [wx, g] : {std::pair{-1.3, 0u}, std::pair{1.3, 1u}, std::pair{0.0, 1u}}) {
    c.wish_x.back() = wx;
    c.goal.back() = g;
    EXPECT_EQ(streams_count(streams_checked_marks(c)), 0u) << wx << " " << g;
  }
}

// Who follows whom: ahead along the wish, within the combined width, going the same way (within
// 60 degrees) or standing. The meeting at the head passes back only through those.
TEST(Streams, TheMeetingPassesOnlyToFollowers) {
  StreamCrowd c;
  c.add(0, 0, 1.3, 0, 0);        // 0: head, meets 1
  c.add(0.7, 0, -1.3, 0, 1);     // 1: oncoming
  c.add(-0.8, 0.49, 1.3, 0, 0);  // 2: behind 0, 0.49 m off its line (inside 0.5: follows)
  c.add(-0.8, 0.51, 1.3, 0, 0);  // 3: 0.51 m off (outside): does not follow 0
  c.add(-0.8, -0.3, 0, 1.3, 0);  // 4: behind 0 but walking north (90 degrees): follows no one
  c.add(-1.6, 0, 1.3, 0.7,
        0);              // 5: behind 2, wish 28 degrees off: follows 2 (2 is in its corridor)
  c.add(5, 5, 0, 0, 1);  // 6: far away, standing
  c.lists(10, 3);
  const auto m = streams_checked_marks(c);
  EXPECT_EQ(m, (std::vector<uint8_t>{1, 1, 1, 0, 0, 1, 0}));
}

// A queue is one queue across its gaps: with 3 m between them (beyond any gap's cap, which
// follows_within_gap checks) the meeting still reaches the last. The cap itself looks only as
// far as the gap matters: spacing below |wish| x gap (1.3 m at 1 s).
TEST(Streams, AQueueIsOneQueueAcrossItsGapsButTheCapLooksOnlyAsFarAsTheGap) {
  StreamCrowd c;
  for (int i = 0; i < 50; ++i) c.add(3.5 * i, 0, 1.3, 0, 0);
  c.add(3.5 * 50, 0, -1.3, 0, 1);
  c.lists(4, 2);
  EXPECT_EQ(streams_count(streams_checked_marks(c)), c.size());
  for (auto [spacing, gap, within] : {std::tuple{1.29, 1.0, true}, std::tuple{1.31, 1.0, false},
                                      std::tuple{1.31, 2.0, true}, std::tuple{2.61, 2.0, false}}) {
    StreamCrowd q;
    q.gap = gap;
    q.add(0, 0, 1.3, 0, 0);
    q.add(-(0.5 + spacing), 0, 1.3, 0, 0);
    q.lists(5, 1);
    EXPECT_EQ(follows_within_gap(q.view(), 1, q.nb.offset[1], 1, 0, 1.3), within)
        << spacing << " m, " << gap << " s";
  }
}

// Followers in a ring follow each other for ever: with no meeting nobody is marked (the sweep
// and the search both end), with one everyone is.
TEST(Streams, ACircleOfFollowersEnds) {
  StreamCrowd c;
  const int n = 40;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    c.add(5 * std::cos(a), 5 * std::sin(a), -1.3 * std::sin(a), 1.3 * std::cos(a), 0);
  }
  c.lists(1.0, 2);
  EXPECT_EQ(streams_count(streams_checked_marks(c)), 0u);
  c.add(5.3, 0.2, 0, -1.3, 1);  // someone crossing against the ring's flow
  c.lists(1.0, 2);
  EXPECT_EQ(streams_count(streams_checked_marks(c)), c.size());
}

}  // namespace
}  // namespace crowddb::steer
