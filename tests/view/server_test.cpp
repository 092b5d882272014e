// The viewer's server: its answers equal what RunFile reads (frames in the binary layout the
// page parses, the run's JSON), reading through the frames' row ranges gives what a scan gives
// (files with and without an index on frame, rows in and out of frame order), and a port in
// use is a one-line error.
#include "view/server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sqlite3.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "crowddb/error.hpp"
#include "support/cli.hpp"
#include "view/runs.hpp"

namespace crowddb::view {
namespace {

using test::TempDir;

using test::bottleneck_run;

template <class T>
T get(const std::string& b, std::size_t& at) {
  T v;
  std::memcpy(&v, b.data() + at, sizeof v);
  at += sizeof v;
  return v;
}

void expect_same(const std::vector<FrameAgent>& a, const std::vector<FrameAgent>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].id, b[i].id);
    EXPECT_EQ(a[i].x, b[i].x);
    EXPECT_EQ(a[i].y, b[i].y);
    EXPECT_EQ(a[i].radius, b[i].radius);
    EXPECT_EQ(a[i].shade, b[i].shade);
    EXPECT_EQ(a[i].goal, b[i].goal);
  }
}

TEST(ViewServer, FramesInTheBinaryLayoutEqualTheFile) {
  TempDir dir;
  RunFile run = RunFile::open(bottleneck_run(dir, 300).string());
  run.index_frames();
  EXPECT_EQ(run.max_agents(), 150u);
  const std::string b = frames_binary(run, 250, 100);  // 250..300: clipped at the last frame
  std::size_t at = 0;
  EXPECT_EQ(get<uint32_t>(b, at), 0x46424443u);
  ASSERT_EQ(get<uint32_t>(b, at), 51u);
  for (int64_t k = 250; k <= 300; ++k) {
    const std::size_t start = at;
    EXPECT_EQ(get<int32_t>(b, at), k);
    const auto n = get<uint32_t>(b, at);
    const std::vector<FrameAgent> want = run.frame(k);
    ASSERT_EQ(n, want.size());
    std::vector<double> id(n);
    std::vector<float> x(n), y(n), r(n), v(n);
    std::vector<int32_t> goal(n);
    for (auto& e : id) e = get<double>(b, at);
    for (auto& e : x) e = get<float>(b, at);
    for (auto& e : y) e = get<float>(b, at);
    for (auto& e : r) e = get<float>(b, at);
    for (auto& e : v) e = get<float>(b, at);
    for (auto& e : goal) e = get<int32_t>(b, at);
    for (uint32_t i = 0; i < n; ++i) {
      EXPECT_EQ(id[i], static_cast<double>(want[i].id));
      EXPECT_EQ(x[i], static_cast<float>(want[i].x));
      EXPECT_EQ(y[i], static_cast<float>(want[i].y));
      EXPECT_EQ(r[i], static_cast<float>(want[i].radius));
      EXPECT_EQ(v[i], static_cast<float>(std::hypot(want[i].vx, want[i].vy)));
      EXPECT_EQ(goal[i], want[i].goal);
      EXPECT_EQ(get<uint8_t>(b, at), static_cast<uint8_t>(want[i].shade));
    }
    while ((at - start) % 8) EXPECT_EQ(get<uint8_t>(b, at), 0) << "padding";
  }
  EXPECT_EQ(at, b.size());
  EXPECT_THROW(frames_binary(run, 0, 0), Error);
  EXPECT_THROW(frames_binary(run, 0, 1001), Error);
  EXPECT_THROW(frames_binary(run, -1, 1), Error);
  EXPECT_THROW(frames_binary(run, 301, 1), Error);
  EXPECT_THROW(frames_binary(run, INT64_MAX, 2), Error);
  const std::string last = frames_binary(run, 300, 1000);  // no overflow past the last frame
  std::size_t at2 = 4;
  EXPECT_EQ(get<uint32_t>(last, at2), 1u);

  const nlohmann::json j = nlohmann::json::parse(run_json(run));
  EXPECT_EQ(j["name"], "bottleneck");
  EXPECT_EQ(j["last_frame"], 300);
  EXPECT_EQ(j["max_agents"], 150);
  EXPECT_EQ(j["goals"].size(), 1u);
  EXPECT_EQ(j["blocked"].size(), 2u);  // the two walls beside the door
  const nlohmann::json m = nlohmann::json::parse(metrics_json(run));
  EXPECT_EQ(m["time"].size(), 300u);
}

// Row ranges must not change what a frame reads: crowddb's file (an index on frame, so the
// ranges are read in id order, not rowid order), files whose frames come in one run with and
// without such an index (ids stored descending), and one whose frames are interleaved (no
// ranges: scans).
TEST(ViewServer, RowRangesReadWhatAScanReads) {
  TempDir dir;
  const auto file = bottleneck_run(dir, 300);  // arrivals reorder the table's rows
  {
    RunFile plain = RunFile::open(file.string()), indexed = RunFile::open(file.string());
    indexed.index_frames();
    EXPECT_TRUE(indexed.indexed());
    for (int64_t k = 0; k <= 300; k += 23) expect_same(indexed.frame(k), plain.frame(k));
  }
  // 0: in order; 1: in order with an index on (frame, id); 2: interleaved; 3: in order, with a
  // column of its own named rowid (holding nonsense) that would shadow SQLite's.
  for (const int variant : {0, 1, 2, 3}) {
    const bool interleaved = variant == 2;
    SCOPED_TRACE(variant);
    const auto other = dir / ("v" + std::to_string(variant) + ".sqlite");
    sqlite3* h = nullptr;
    ASSERT_EQ(sqlite3_open(other.c_str(), &h), SQLITE_OK);
    std::string sql = variant == 3
                          ? "CREATE TABLE trajectory_data (frame, id, pos_x, pos_y, rowid);"
                          : "CREATE TABLE trajectory_data (frame, id, pos_x, pos_y);";
    for (int f = 0; f < 20; ++f)
      for (int id = 30; id > 0; --id) {  // ids descending: the reader sorts
        const int frame = interleaved ? (f * 30 + id) % 20 : f;
        sql += "INSERT INTO trajectory_data (frame, id, pos_x, pos_y) VALUES (" +
               std::to_string(frame) + ", " + std::to_string(id + 100 * f) + ", " +
               std::to_string(id) + ", " + std::to_string(frame) + ");";
      }
    if (variant == 1) sql += "CREATE INDEX by_frame ON trajectory_data(frame, id);";
    ASSERT_EQ(sqlite3_exec(h, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(h);
    RunFile plain = RunFile::open(other.string()), indexed = RunFile::open(other.string());
    indexed.index_frames();
    EXPECT_EQ(indexed.indexed(), variant <= 1);
    EXPECT_EQ(indexed.max_agents(), 30u);
    for (int64_t k = 0; k < 20; ++k) {
      const auto a = indexed.frame(k);
      expect_same(a, plain.frame(k));
      EXPECT_EQ(a.size(), 30u);
      EXPECT_TRUE(std::is_sorted(a.begin(), a.end(), [](const FrameAgent& p, const FrameAgent& q) {
        return p.id < q.id;
      }));
    }
  }
}

// Starts `crowddb view RUN --port 0` in the background (ended by `timeout` after 30 s at the
// latest) and returns the port it listens on, or 0.
int start_view(const std::filesystem::path& run, const TempDir& dir) {
  const auto out = dir / "view.out";
  const std::string cmd = "timeout 30 " + std::string(CROWDDB_CLI) + " view " + run.string() +
                          " --port 0 > " + out.string() + " 2>&1 &";
  if (std::system(cmd.c_str()) != 0) return 0;
  for (int i = 0; i < 200; ++i) {
    std::ifstream f(out);
    std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const auto at = text.find("http://127.0.0.1:");
    if (at != std::string::npos && text.find('/', at + 17) != std::string::npos)
      return std::atoi(text.c_str() + at + 17);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
}

// A second server on the port of a running one fails with one line (the HTTP library's own
// default, SO_REUSEPORT, would let both listen and mix their answers); requests that name
// another host are refused (a page elsewhere rebinding its name to 127.0.0.1); the API's
// parameters are checked.
TEST(ViewServer, OneServerPerPortAndOnlyForThisMachine) {
  TempDir dir;
  const auto run = bottleneck_run(dir, 20);
  const int port = start_view(run, dir);
  ASSERT_GT(port, 0);
  {  // (timeout: should it listen after all, the test fails instead of hanging)
    const auto err = dir / "second.err";
    const int raw = std::system(("timeout 10 " + std::string(CROWDDB_CLI) + " view " +
                                 run.string() + " --port " + std::to_string(port) +
                                 " >/dev/null 2>" + err.string() + " </dev/null")
                                    .c_str());
    EXPECT_EQ(WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, 1);
    const std::string text = test::slurp(err);
    EXPECT_NE(text.find(std::to_string(port) + ": cannot listen"), std::string::npos) << text;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
  }

  httplib::Client c("127.0.0.1", port);
  auto ok = c.Get("/api/run");
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 200);
  EXPECT_EQ(nlohmann::json::parse(ok->body)["last_frame"], 20);
  auto page = c.Get("/");
  ASSERT_TRUE(page);
  EXPECT_NE(page->body.find("<canvas"), std::string::npos);
  auto frames = c.Get("/api/frames?from=0&count=5");
  ASSERT_TRUE(frames);
  EXPECT_EQ(frames->status, 200);
  for (const char* bad :
       {"/api/frames?from=x", "/api/frames?from=99999999999999999999", "/api/frames?from=0&count=0",
        "/api/frames?from=21&count=1", "/api/frames?from=-5&count=1"}) {
    auto r = c.Get(bad);
    ASSERT_TRUE(r) << bad;
    EXPECT_EQ(r->status, 400) << bad;
  }
  auto rebound = c.Get("/api/run", {{"Host", "attacker.example:" + std::to_string(port)}});
  ASSERT_TRUE(rebound);
  EXPECT_EQ(rebound->status, 403);
  EXPECT_EQ(c.Get("/nothing/here")->status, 404);
  std::system(("pkill -f 'view " + run.string() + "' >/dev/null 2>&1").c_str());
}

TEST(ViewServer, ABadFileIsRefusedBeforeAnythingListens) {
  TempDir dir;
  const test::CliResult bad = test::run_cli("view " + (dir / "nothing.sqlite").string(), dir);
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("no such file"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace crowddb::view
