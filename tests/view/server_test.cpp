// The viewer's server: its answers equal what RunFile reads (frames in the binary layout the
// page parses, the run's JSON), reading through the frames' row ranges gives what a scan gives
// (files with and without an index on frame, rows in and out of frame order), and a port in
// use is a one-line error.
#include "view/server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sqlite3.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <nlohmann/json.hpp>

#include "crowddb/error.hpp"
#include "support/cli.hpp"

namespace crowddb::view {
namespace {

using test::TempDir;

std::filesystem::path bottleneck_run(const TempDir& dir, int ticks) {
  const auto out = dir / "bn.sqlite";
  const test::CliResult r =
      test::run_cli("run " + test::source_path("scenarios/bottleneck.json") + " --ticks " +
                        std::to_string(ticks) + " --quiet --out " + out.string(),
                    dir);
  EXPECT_EQ(r.status, 0) << r.err;
  return out;
}

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
    for (int64_t k = 0; k <= 300; k += 23) expect_same(indexed.frame(k), plain.frame(k));
  }
  for (const int variant : {0, 1, 2}) {
    const bool interleaved = variant == 2;
    SCOPED_TRACE(variant);
    const auto other = dir / ("v" + std::to_string(variant) + ".sqlite");
    sqlite3* h = nullptr;
    ASSERT_EQ(sqlite3_open(other.c_str(), &h), SQLITE_OK);
    std::string sql = "CREATE TABLE trajectory_data (frame, id, pos_x, pos_y);";
    for (int f = 0; f < 20; ++f)
      for (int id = 30; id > 0; --id) {  // ids descending: the reader sorts
        const int frame = interleaved ? (f * 30 + id) % 20 : f;
        sql += "INSERT INTO trajectory_data VALUES (" + std::to_string(frame) + ", " +
               std::to_string(id + 100 * f) + ", " + std::to_string(id) + ", " +
               std::to_string(frame) + ");";
      }
    if (variant == 1) sql += "CREATE INDEX by_frame ON trajectory_data(frame, id);";
    ASSERT_EQ(sqlite3_exec(h, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(h);
    RunFile plain = RunFile::open(other.string()), indexed = RunFile::open(other.string());
    indexed.index_frames();
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

TEST(ViewServer, APortInUseIsAOneLineError) {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(s, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  ASSERT_EQ(bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(listen(s, 1), 0);
  socklen_t len = sizeof a;
  ASSERT_EQ(getsockname(s, reinterpret_cast<sockaddr*>(&a), &len), 0);
  const int port = ntohs(a.sin_port);
  TempDir dir;
  const auto run = bottleneck_run(dir, 5);
  const test::CliResult r =
      test::run_cli("view " + run.string() + " --port " + std::to_string(port), dir);
  close(s);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(std::to_string(port) + ": cannot listen"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  // A bad file is refused before anything listens.
  const test::CliResult bad = test::run_cli("view " + (dir / "nothing.sqlite").string(), dir);
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("no such file"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace crowddb::view
