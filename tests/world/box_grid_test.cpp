// BoxGrid (world/box_grid.hpp) against a scan of every box: a window of cells lists every box
// that meets the part of the plane those cells cover, sorted and each once (and visit() calls
// for the same boxes, each once), on random boxes of
// mixed sizes (some long enough to be scanned by every question), points outside the grid, and
// degenerate inputs.
#include "world/box_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "util/rng.hpp"

namespace crowddb {
namespace {

bool meets(const BoxBounds& a, const BoxBounds& b) {
  return a.x0 <= b.x1 && b.x0 <= a.x1 && a.y0 <= b.y1 && b.y0 <= a.y1;
}

TEST(BoxGrid, AWindowListsEveryBoxMeetingItOnRandomBoxes) {
  Rng rng(20261206);
  std::size_t scanned_somewhere = 0;
  for (int scene = 0; scene < 40; ++scene) {
    const double span = scene % 3 == 0 ? 1e6 : 100;
    std::vector<BoxBounds> boxes;
    const std::size_t n = 1 + rng.below(scene % 2 == 0 ? 20 : 800);
    for (std::size_t k = 0; k < n; ++k) {
      const double x = rng.uniform(-span, span), y = rng.uniform(-span, span);
      double w = rng.uniform(0, span / 50), h = rng.below(3) == 0 ? 0 : rng.uniform(0, span / 50);
      if (rng.below(40) == 0)  // a long wall, spanning many cells
        w = rng.uniform(span, 3 * span), h = rng.uniform(span / 2, 2 * span);
      boxes.push_back({x, y, x + w, y + h});
    }
    const BoxGrid grid(boxes, scene % 5 == 0 ? 1 + static_cast<int64_t>(rng.below(8)) : 2048);
    ASSERT_TRUE(grid.gridded());
    scanned_somewhere += grid.scanned();
    std::vector<uint32_t> got;
    for (int q = 0; q < 300; ++q) {
      const double x = rng.uniform(-1.2 * span, 1.2 * span),
                   y = rng.uniform(-1.2 * span, 1.2 * span);
      const double r = rng.below(4) == 0 ? 0 : rng.uniform(0, span / 10);
      const BoxBounds window{x - r, y - r, x + r, y + r};
      grid.collect(grid.cell_x(window.x0), grid.cell_x(window.x1), grid.cell_y(window.y0),
                   grid.cell_y(window.y1), got);
      ASSERT_TRUE(std::is_sorted(got.begin(), got.end()));
      ASSERT_EQ(std::adjacent_find(got.begin(), got.end()), got.end());
      // visit() calls for exactly the boxes collect() lists, each once; also on windows of
      // cells reaching past the grid's edges, wholly right of it, or turned inside out.
      const int64_t cx0 = q % 11 == 0 ? grid.nx() + static_cast<int64_t>(rng.below(2))
                                      : grid.cell_x(window.x0) - static_cast<int64_t>(rng.below(3)),
                    cy0 = grid.cell_y(window.y0) - static_cast<int64_t>(rng.below(3));
      const int64_t cx1 = q % 7 == 0 ? cx0 - 1 - int64_t(rng.below(3))
                                     : grid.cell_x(window.x1) + int64_t(rng.below(3)),
                    cy1 = q % 13 == 0 ? cy0 - 1 - int64_t(rng.below(3))
                                      : grid.cell_y(window.y1) + int64_t(rng.below(3));
      std::vector<uint32_t> listed, visited;
      grid.collect(cx0, cx1, cy0, cy1, listed);
      const std::size_t read =
          grid.visit(cx0, cx1, cy0, cy1, [&](uint32_t k) { visited.push_back(k); });
      std::sort(visited.begin(), visited.end());
      ASSERT_EQ(visited, listed) << "scene " << scene << " query " << q;
      EXPECT_EQ(read, grid.collect(cx0, cx1, cy0, cy1, listed));
      for (std::size_t k = 0; k < n; ++k)
        if (meets(boxes[k], window)) {
          ASSERT_TRUE(std::binary_search(got.begin(), got.end(), static_cast<uint32_t>(k)))
              << "scene " << scene << " box " << k << " missing from the window at " << x << ", "
              << y << " reach " << r;
        }
    }
  }
  EXPECT_GT(scanned_somewhere, 0u);  // the long boxes' list was exercised
}

TEST(BoxGrid, NoBoxesOrUnboundedBoxesListEverything) {
  std::vector<uint32_t> got{7};
  const BoxGrid none(std::vector<BoxBounds>{}, 16);
  EXPECT_FALSE(none.gridded());
  none.collect(0, 0, 0, 0, got);
  EXPECT_TRUE(got.empty());

  const std::vector<BoxBounds> wild{{0, 0, 1, 1}, {-INFINITY, 0, 2, 2}, {3, 3, 4, 4}};
  const BoxGrid unbounded(wild, 16);
  EXPECT_FALSE(unbounded.gridded());
  unbounded.collect(unbounded.cell_x(0.5), unbounded.cell_x(0.5), 0, 0, got);
  EXPECT_EQ(got, (std::vector<uint32_t>{0, 1, 2}));

  // visit() on grids that list everything: every box once.
  for (const BoxGrid* g : {&none, &unbounded}) {
    std::vector<uint32_t> visited;
    g->visit(0, 0, 0, 0, [&](uint32_t k) { visited.push_back(k); });
    g->collect(0, 0, 0, 0, got);
    EXPECT_EQ(visited, got);
  }

  const std::vector<BoxBounds> point{{5, 5, 5, 5}};  // zero extent: one cell
  const BoxGrid one(point, 16);
  ASSERT_TRUE(one.gridded());
  one.collect(one.cell_x(NAN), one.cell_x(1e300), one.cell_y(-1e300), one.cell_y(5), got);
  EXPECT_EQ(got, (std::vector<uint32_t>{0}));
}

TEST(BoxGrid, AWindowOfMoreCellsThanBoxesListsThemAll) {
  std::vector<BoxBounds> boxes;
  for (int k = 0; k < 100; ++k) boxes.push_back({double(k), double(k), k + 0.5, k + 0.5});
  const BoxGrid grid(boxes, 1024);
  std::vector<uint32_t> got;
  grid.collect(-5, 20, -5, 20, got);  // 26 x 26 cells > 100 boxes
  EXPECT_EQ(got.size(), 100u);
  grid.collect(grid.cell_x(10.2), grid.cell_x(10.2), grid.cell_y(10.2), grid.cell_y(10.2), got);
  EXPECT_LT(got.size(), 100u);
  EXPECT_TRUE(std::binary_search(got.begin(), got.end(), 10u));
}

}  // namespace
}  // namespace crowddb
