#include "io/write_behind.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <stdexcept>
#include <vector>

namespace crowddb::io {
namespace {

TEST(WriteBehind, RunsTheJobsInOrderOnItsOwnThread) {
  std::vector<int> done;
  std::atomic<int> elsewhere{0};
  const auto caller = std::this_thread::get_id();
  {
    WriteBehind behind(2);
    for (int i = 0; i < 1000; ++i)
      behind.post([&, i] {
        done.push_back(i);
        if (std::this_thread::get_id() != caller) ++elsewhere;
      });
    behind.drain();
    ASSERT_EQ(done.size(), 1000u);
    for (int i = 0; i < 1000; ++i) ASSERT_EQ(done[i], i);
    EXPECT_EQ(elsewhere.load(), 1000);
  }
}

// The destructor runs the jobs still waiting when it is called, then stops the thread.
TEST(WriteBehind, TheDestructorRunsWhatIsStillWaiting) {
  std::vector<int> done;
  std::promise<void> gate;
  std::shared_future<void> open = gate.get_future().share();
  std::future<void> opener;  // outlives `behind`: the gate opens while its destructor waits
  {
    WriteBehind behind(2);
    behind.post([open] { open.wait(); });
    behind.post([&] { done.push_back(1); });
    opener = std::async(std::launch::async, [&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      gate.set_value();
    });
  }
  EXPECT_EQ(done, std::vector<int>{1});
}

// The first failure comes back from drain() and every later post(); the jobs after it never run.
TEST(WriteBehind, AFailedJobsErrorComesBackAndTheRestAreDropped) {
  WriteBehind behind(4);
  std::atomic<int> ran{0};
  std::promise<void> go;
  std::shared_future<void> go_f = go.get_future().share();
  behind.post([&] { ++ran; });
  behind.post([go_f] {
    go_f.wait();  // fails once the next job is queued behind it
    throw std::runtime_error("disk full");
  });
  behind.post([&] { ran += 100; });
  go.set_value();
  EXPECT_THROW(
      {
        try {
          behind.drain();
        } catch (const std::runtime_error& e) {
          EXPECT_STREQ(e.what(), "disk full");
          throw;
        }
      },
      std::runtime_error);
  EXPECT_THROW(behind.post([&] { ran += 1000; }), std::runtime_error);
  behind.wait_idle();  // returns, without the error
  EXPECT_EQ(ran.load(), 1);
}

// post() waits while max_waiting jobs wait, so what they hold stays bounded.
TEST(WriteBehind, PostWaitsWhileTheQueueIsFull) {
  WriteBehind behind(1);
  std::promise<void> started, go;
  std::shared_future<void> go_f = go.get_future().share();
  std::vector<char> order;
  behind.post([&] {
    started.set_value();
    go_f.wait();
    order.push_back('a');
  });
  started.get_future().wait();
  behind.post([&] { order.push_back('b'); });  // waits in the queue: it is full now
  auto third = std::async(std::launch::async, [&] { behind.post([&] { order.push_back('c'); }); });
  EXPECT_EQ(third.wait_for(std::chrono::milliseconds(100)), std::future_status::timeout)
      << "post() returned with the queue full";
  go.set_value();
  third.get();
  behind.drain();
  EXPECT_EQ(std::string(order.begin(), order.end()), "abc");
}

}  // namespace
}  // namespace crowddb::io
