// The asynchronous path service: results arrive exactly at their due tick, in submission order,
// identical to a direct search, whatever the worker's timing.
#include "path/path_service.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include "util/rng.hpp"

namespace crowddb::path {
namespace {

std::unique_ptr<NavMesh> maze() {
  NavGeometry g{{0, 0, 60, 40}, {{45, 20, 4, 1}}, {}};
  g.polygons.push_back({{{15, 0}, {17, 0}, {17, 30}, {15, 30}}, 1});
  g.polygons.push_back({{{30, 10}, {32, 10}, {32, 40}, {30, 40}}, 1});
  return NavMesh::build(g, {1.0, 0.25});
}

std::vector<PathJob> random_jobs(const NavMesh& mesh, uint64_t first_ticket, int n, uint64_t seed) {
  Rng rng(seed);
  std::vector<PathJob> jobs;
  for (int i = 0; i < n; ++i)
    jobs.push_back({first_ticket + static_cast<uint64_t>(i),
                    static_cast<uint64_t>(100 + i),
                    &mesh,
                    {rng.uniform(2, 58), rng.uniform(2, 38)},
                    {rng.uniform(2, 58), rng.uniform(2, 38)},
                    nullptr});
  return jobs;
}

void expect_same(const PathResult& a, const PathResult& b) {
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.length, b.length);  // bit-identical
  ASSERT_EQ(a.corners.size(), b.corners.size());
  for (std::size_t i = 0; i < a.corners.size(); ++i) {
    EXPECT_EQ(a.corners[i].x, b.corners[i].x);
    EXPECT_EQ(a.corners[i].y, b.corners[i].y);
  }
}

TEST(PathService, RepliesComeAtTheirDueTickInSubmissionOrder) {
  auto mesh = maze();
  PathService service;
  service.submit(3, random_jobs(*mesh, 1, 5, 1));
  service.submit(3, random_jobs(*mesh, 6, 2, 2));
  service.submit(5, random_jobs(*mesh, 8, 4, 3));
  EXPECT_TRUE(service.collect(1).empty());
  EXPECT_TRUE(service.collect(2).empty());
  const auto at3 = service.collect(3);
  ASSERT_EQ(at3.size(), 7u);
  for (std::size_t i = 0; i < at3.size(); ++i) EXPECT_EQ(at3[i].ticket, i + 1);
  EXPECT_TRUE(service.collect(4).empty());
  const auto at5 = service.collect(5);
  ASSERT_EQ(at5.size(), 4u);
  EXPECT_EQ(at5.front().ticket, 8u);
  EXPECT_EQ(service.pending_batches(), 0u);
  EXPECT_EQ(service.stats().jobs_done, 11u);
}

TEST(PathService, ResultsEqualADirectSearch) {
  auto mesh = maze();
  PathService service;
  const auto jobs = random_jobs(*mesh, 1, 40, 7);
  service.submit(1, jobs);
  const auto replies = service.collect(1);
  ASSERT_EQ(replies.size(), jobs.size());
  PathFinder direct(*mesh);
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    EXPECT_EQ(replies[i].agent, jobs[i].agent);
    expect_same(replies[i].result, direct.find(jobs[i].start, jobs[i].goal));
  }
}

// A worker that stalls at random (as on a machine whose other core is busy) changes how long the
// tick waits, never what it gets or when.
TEST(PathService, RandomWorkerDelaysChangeNothing) {
  auto mesh = maze();
  std::vector<std::vector<PathReply>> runs;
  for (int run = 0; run < 2; ++run) {
    PathService::Options opt;
    std::mutex mu;
    Rng jitter(run + 1);
    if (run == 1)
      opt.before_job = [&](const PathJob&) {
        std::chrono::microseconds pause;
        {
          std::lock_guard lock(mu);
          pause = std::chrono::microseconds(jitter.below(3000));
        }
        std::this_thread::sleep_for(pause);
      };
    PathService service(opt);
    std::vector<PathReply> all;
    for (uint64_t tick = 0; tick < 12; ++tick) {
      for (PathReply& r : service.collect(tick)) all.push_back(std::move(r));
      service.submit(tick + 2, random_jobs(*mesh, tick * 10, 3, tick));
    }
    for (PathReply& r : service.collect(100)) all.push_back(std::move(r));
    if (run == 1) {
      EXPECT_GT(service.stats().waits, 0u);  // the delays did make the tick wait
    }
    runs.push_back(std::move(all));
  }
  ASSERT_EQ(runs[0].size(), runs[1].size());
  for (std::size_t i = 0; i < runs[0].size(); ++i) {
    EXPECT_EQ(runs[0][i].ticket, runs[1][i].ticket);
    expect_same(runs[0][i].result, runs[1][i].result);
  }
}

TEST(PathService, DueTicksMustNotDecrease) {
  auto mesh = maze();
  PathService service;
  service.submit(5, random_jobs(*mesh, 1, 1, 1));
  EXPECT_THROW(service.submit(4, random_jobs(*mesh, 2, 1, 1)), std::logic_error);
}

TEST(PathService, JobErrorsReachTheCollector) {
  auto mesh = maze();
  PathService::Options opt;
  opt.before_job = [](const PathJob& j) {
    if (j.ticket == 2) throw std::runtime_error("boom");
  };
  PathService service(opt);
  service.submit(1, random_jobs(*mesh, 1, 3, 1));
  EXPECT_THROW(service.collect(1), std::runtime_error);
  service.submit(2, random_jobs(*mesh, 10, 1, 1));  // the service goes on
  EXPECT_EQ(service.collect(2).size(), 1u);
}

// Destroying the service with batches queued stops the worker after its current batch (the
// test fails by hanging, or under the sanitizers by touching freed batches).
TEST(PathService, StopsWithWorkPending) {
  auto mesh = maze();
  std::atomic<int> started{0};
  {
    PathService::Options opt;
    opt.before_job = [&](const PathJob&) {
      ++started;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    };
    PathService service(opt);
    for (uint64_t t = 0; t < 50; ++t) service.submit(t, random_jobs(*mesh, t * 10, 5, t));
  }
  EXPECT_LE(started.load(), 250);
}

}  // namespace
}  // namespace crowddb::path
