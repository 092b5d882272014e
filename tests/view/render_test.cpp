// Pictures of runs: RunFile reads crowddb's output and plain JuPedSim trajectory files, and
// render_png draws every agent where the file says it is (pixel probes on two frames), walls
// where the geometry is blocked, and refuses bad files with one line.
#include "view/render.hpp"

#include <cairo.h>
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <cmath>

#include "crowddb/error.hpp"
#include "support/cli.hpp"
#include "support/sqlite_query.hpp"
#include "view/runs.hpp"

namespace crowddb::view {
namespace {

using test::TempDir;

// The colour of pixel (x, y) of a PNG file, as 0xRRGGBB.
class Png {
 public:
  explicit Png(const std::string& path) : s_(cairo_image_surface_create_from_png(path.c_str())) {}
  ~Png() { cairo_surface_destroy(s_); }
  bool ok() const { return cairo_surface_status(s_) == CAIRO_STATUS_SUCCESS; }
  int width() const { return cairo_image_surface_get_width(s_); }
  int height() const { return cairo_image_surface_get_height(s_); }
  uint32_t at(double x, double y) const {
    const auto* row =
        cairo_image_surface_get_data(s_) +
        static_cast<std::ptrdiff_t>(std::floor(y)) * cairo_image_surface_get_stride(s_);
    const uint32_t px = reinterpret_cast<const uint32_t*>(row)[static_cast<int>(std::floor(x))];
    return px & 0xffffff;
  }

 private:
  cairo_surface_t* s_;
};

using test::bottleneck_run;

TEST(RunFile, ReadsACrowddbRun) {
  TempDir dir;
  const auto file = bottleneck_run(dir, 20);
  const RunFile run = RunFile::open(file.string());
  EXPECT_TRUE(run.crowddb());
  EXPECT_EQ(run.name(), "bottleneck");
  EXPECT_EQ(run.first_frame(), 0);
  EXPECT_EQ(run.last_frame(), 20);
  EXPECT_DOUBLE_EQ(run.fps(), 10);
  EXPECT_EQ(run.bounds().xmax, 16);
  EXPECT_EQ(run.bounds().ymax, 10);
  ASSERT_EQ(run.goals().size(), 1u);
  EXPECT_EQ(run.goals()[0].name, "out");
  EXPECT_EQ(run.goals()[0].ring.size(), 4u);
  EXPECT_FALSE(run.geometry_wkt().empty());
  for (int64_t k : {0, 20}) {
    const std::vector<FrameAgent> agents = run.frame(k);
    std::vector<double> xs;  // read as doubles: SQLite's text of a REAL keeps 15 digits
    {
      sqlite3* h = nullptr;
      ASSERT_EQ(sqlite3_open_v2(file.c_str(), &h, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
      sqlite3_stmt* st = nullptr;
      ASSERT_EQ(
          sqlite3_prepare_v2(h, "SELECT pos_x FROM trajectory_data WHERE frame = ? ORDER BY id", -1,
                             &st, nullptr),
          SQLITE_OK);
      sqlite3_bind_int64(st, 1, k);
      while (sqlite3_step(st) == SQLITE_ROW) xs.push_back(sqlite3_column_double(st, 0));
      sqlite3_finalize(st);
      sqlite3_close(h);
    }
    ASSERT_EQ(agents.size(), xs.size());
    ASSERT_EQ(agents.size(), 150u);
    for (std::size_t i = 0; i < agents.size(); ++i) {
      EXPECT_EQ(agents[i].x, xs[i]);
      EXPECT_GE(agents[i].radius, 0.2);
      EXPECT_LE(agents[i].radius, 0.25);
      EXPECT_TRUE(agents[i].shade == Shade::active || agents[i].shade == Shade::stalled);
      EXPECT_EQ(agents[i].goal, 0);
    }
  }
  try {
    (void)run.frame(21);
    FAIL() << "frame 21 should not exist";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::usage);
    EXPECT_NE(std::string(e.what()).find("frames 0 to 20"), std::string::npos) << e.what();
  }
}

// Probes: the pixel under every agent's centre has its state's colour, on two frames whose
// agents stand elsewhere; a wall's pixel is the blocked colour; open floor is floor.
TEST(Render, DrawsEveryAgentWhereTheFileSaysOnTwoFrames) {
  TempDir dir;
  const auto file = bottleneck_run(dir, 40);
  const RunFile run = RunFile::open(file.string());
  const Viewport v = viewport_of(run, 1000);
  for (int64_t k : {0, 40}) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const auto png = (dir / ("f" + std::to_string(k) + ".png")).string();
    RenderOptions opt;
    opt.width = 1000;
    render_png(run, k, opt, png);
    const Png pic(png);
    ASSERT_TRUE(pic.ok());
    EXPECT_EQ(pic.width(), v.width);
    EXPECT_EQ(pic.height(), v.height);
    const auto agents = run.frame(k);
    for (const FrameAgent& a : agents)
      EXPECT_EQ(pic.at(v.px(a.x), v.py(a.y)),
                a.shade == Shade::stalled ? colour::kStalled : colour::kActive)
          << "agent " << a.id;
    EXPECT_EQ(pic.at(v.px(10.15), v.py(2.2)), colour::kBlocked);  // the door's lower wall
    // Open floor: the room's corner, where nobody stands at these frames.
    bool clear = true;
    for (const FrameAgent& a : agents) clear = clear && std::hypot(a.x - 12.5, a.y - 9.5) > 0.5;
    if (clear) {
      EXPECT_EQ(pic.at(v.px(12.5), v.py(9.5)), colour::kFloor);
    }
  }
  // The two frames differ: some agent moved by more than its radius.
  const auto a0 = run.frame(0), a40 = run.frame(40);
  bool moved = false;
  for (std::size_t i = 0; i < a0.size(); ++i)
    moved = moved || std::hypot(a0[i].x - a40[i].x, a0[i].y - a40[i].y) > a0[i].radius;
  EXPECT_TRUE(moved);
}

// A JuPedSim trajectory file written by other software (the layout of JuPedSim's writer,
// version 3): positions and a walkable area with a hole, no radii or states (drawn at the
// default radius), the frame rate from its metadata. (PedPy's test files of JuPedSim versions
// 1 and 2 were opened and drawn by hand; they are not in this repository.)
TEST(Render, OpensAJuPedSimFileWithoutCrowddbTables) {
  TempDir dir;
  const auto file = dir / "jps.sqlite";
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &h), SQLITE_OK);
  ASSERT_EQ(
      sqlite3_exec(h,
                   "CREATE TABLE trajectory_data (frame INTEGER, id INTEGER, pos_x REAL, "
                   "pos_y REAL, ori_x REAL, ori_y REAL);"
                   "CREATE TABLE metadata (key TEXT, value TEXT);"
                   "INSERT INTO metadata VALUES ('version', '3'), ('fps', '8'), ('xmin', '2'), "
                   "('xmax', '15'), ('ymin', '2'), ('ymax', '8');"
                   "CREATE TABLE geometry (hash INTEGER, wkt TEXT);"
                   "INSERT INTO geometry VALUES (1, 'POLYGON ((0 0, 20 0, 20 10, 0 10, 0 0), "
                   "(8 3, 12 3, 12 7, 8 7, 8 3))');"
                   "CREATE TABLE frame_data (frame INTEGER, geometry_hash INTEGER);"
                   "INSERT INTO trajectory_data VALUES (0, 1, 2, 2, 1, 0), (0, 2, 15, 8, 1, 0),"
                   " (1, 1, 2.5, 2, 1, 0), (1, 2, 14.5, 8, 1, 0);",
                   nullptr, nullptr, nullptr),
      SQLITE_OK);
  sqlite3_close(h);
  const RunFile run = RunFile::open(file.string());
  EXPECT_FALSE(run.crowddb());
  EXPECT_EQ(run.name(), "jps");
  EXPECT_DOUBLE_EQ(run.fps(), 8);
  // The drawing area is the geometry's envelope: JuPedSim's metadata bounds are the positions'.
  EXPECT_EQ(run.bounds().xmin, 0);
  EXPECT_EQ(run.bounds().xmax, 20);
  EXPECT_EQ(run.bounds().ymax, 10);
  EXPECT_EQ(run.last_frame(), 1);
  const auto agents = run.frame(1);
  ASSERT_EQ(agents.size(), 2u);
  EXPECT_EQ(agents[0].x, 2.5);
  EXPECT_EQ(agents[0].radius, RunFile::kDefaultRadius);
  EXPECT_EQ(agents[0].shade, Shade::unknown);
  const auto png = (dir / "jps.png").string();
  render_png(run, 1, RenderOptions{}, png);
  const Png pic(png);
  ASSERT_TRUE(pic.ok());
  const Viewport v = viewport_of(run, RenderOptions{}.width);
  EXPECT_EQ(pic.at(v.px(2.5), v.py(2)), colour::kActive);
  EXPECT_EQ(pic.at(v.px(14.5), v.py(8)), colour::kActive);
  EXPECT_EQ(pic.at(v.px(10), v.py(5)), colour::kBlocked);  // the hole
  EXPECT_EQ(pic.at(v.px(5), v.py(8)), colour::kFloor);
}

TEST(Render, BadFilesAndArgumentsGiveOneLine) {
  TempDir dir;
  const auto text = dir / "text.sqlite";
  {
    std::FILE* f = std::fopen(text.c_str(), "w");
    std::fputs("not a database, just text long enough to have a header of sorts\n", f);
    std::fclose(f);
  }
  const auto other = dir / "other.sqlite";
  const auto badgeo = dir / "badgeo.sqlite";
  const auto nan = dir / "nan.sqlite";
  for (const auto& [path, sql] : std::vector<std::pair<std::filesystem::path, std::string>>{
           {other, "CREATE TABLE t (x);"},
           {badgeo,
            "CREATE TABLE trajectory_data (frame, id, pos_x, pos_y);"
            "INSERT INTO trajectory_data VALUES (0, 1, 1, 1);"
            "CREATE TABLE geometry (hash, wkt); INSERT INTO geometry VALUES (1, 'POLYGON ((0 0, "
            "1');"},
           {nan,
            "CREATE TABLE trajectory_data (frame, id, pos_x, pos_y);"
            "INSERT INTO trajectory_data VALUES (0, 1, 1, 1), (0, 2, 1e999, 1);"}}) {
    sqlite3* h = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &h), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(h, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sql;
    sqlite3_close(h);
  }
  const auto text_pos = dir / "textpos.sqlite";
  const auto huge_frame = dir / "hugeframe.sqlite";
  const auto a_view = dir / "view.sqlite";
  const auto far = dir / "far.sqlite";
  for (const auto& [path, sql] : std::vector<std::pair<std::filesystem::path, std::string>>{
           {text_pos,
            "CREATE TABLE trajectory_data (frame, id, pos_x, pos_y);"
            "INSERT INTO trajectory_data VALUES (0, 1, 1, 1), (0, 2, 'left', 1);"},
           {huge_frame,
            "CREATE TABLE trajectory_data (frame, id, pos_x, pos_y);"
            "INSERT INTO trajectory_data VALUES (0, 1, 1, 1), (4294967296, 1, 1, 1);"},
           {a_view,
            "CREATE TABLE t (frame, id, pos_x, pos_y);"
            "CREATE VIEW trajectory_data AS SELECT * FROM t;"},
           {far,
            "CREATE TABLE trajectory_data (frame, id, pos_x, pos_y);"
            "INSERT INTO trajectory_data VALUES (0, 1, 1, 1), (0, 2, 1e300, 1);"}}) {
    sqlite3* h = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &h), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(h, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sql;
    sqlite3_close(h);
  }
  const std::pair<std::string, std::string> cases[] = {
      {text_pos.string(), "the row of frame 0, id 2 holds text in pos_x (a number is expected)"},
      {huge_frame.string(), "frame numbers 0 to 4294967296 lie outside 0 to 2147483647"},
      {a_view.string(), "no table trajectory_data"},
      {far.string(), "positions must lie within +-1e9 m"},
      {(dir / "missing.sqlite").string(), "no such file"},
      {dir.path().string(), "not a regular file"},
      {text.string(), "not an SQLite file"},
      {other.string(), "no table trajectory_data"},
      {badgeo.string(), "geometry:"},
      {nan.string(), "positions must lie within +-1e9 m"},
  };
  for (const auto& [file, message] : cases) {
    const test::CliResult r =
        test::run_cli("render " + file + " --out " + (dir / "x.png").string(), dir);
    EXPECT_EQ(r.status, 1) << file;
    EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << file << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
  }
  const auto run = bottleneck_run(dir, 5);
  const std::pair<std::string, std::string> usage[] = {
      {"--frame 6", "no frame 6 (frames 0 to 5)"},
      {"--width 50", "--width: 50 pixels"},
      {"--color pink", "--color"},
      {"--time -1", "--time"},
      {"--time 1000", "--time 1000 s is after the last frame (0.5 s)"},
      {"--frame -3", "no frame -3 (frames 0 to 5)"},
  };
  for (const auto& [args, message] : usage) {
    const test::CliResult r = test::run_cli("render " + run.string() + " " + args, dir);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
  }
  // The default output sits beside the run, named after it; --time picks the nearest frame
  // (frame k at k / fps): the same picture as that frame's.
  const test::CliResult ok = test::run_cli("render " + run.string() + " --time 0.31", dir);
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "bn.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "bn.png.tmp"));
  ASSERT_EQ(
      test::run_cli("render " + run.string() + " --frame 3 --out " + (dir / "f3.png").string(), dir)
          .status,
      0);
  ASSERT_EQ(
      test::run_cli("render " + run.string() + " --frame 2 --out " + (dir / "f2.png").string(), dir)
          .status,
      0);
  EXPECT_EQ(test::slurp(dir / "bn.png"), test::slurp(dir / "f3.png"));
  EXPECT_NE(test::slurp(dir / "f2.png"), test::slurp(dir / "f3.png"));
}

}  // namespace
}  // namespace crowddb::view
