// The indexed obstacle-feature query: the scene's features (circles and polygon edges, walls
// included) registered in a uniform grid once per scene; a query looks only at the cells its
// reach box covers.
//
// Invariant: a feature is registered in every cell it may pass through (circles: the cells of
// their bounding box; edges: the cells of their bounding box whose centre lies within half a
// cell diagonal of the segment), so any feature closer to p than `reach` is registered in a cell
// of p's reach box. Candidates are de-duplicated, then decided by feature_dist2, the primitive
// the naive scan uses: the lists are identical. The grid covers the features' bounding box only
// (query boxes are clamped to it); its cell is the mean reach of the first query, but at most
// 1024 cells per axis. Build O(F + registrations + cells), query O(cells + candidates log
// candidates).
//
// Far from every feature (most of a crowd, most of the time) a query ends after one look-up:
// each cell keeps its Chebyshev distance, in cells, to the nearest cell holding a feature, so a
// query point in a cell at distance m is more than (m - 3) cells from every feature (a cell of
// slack each against rounding where the point and where a feature's box were binned).
#pragma once

#include <cstdint>
#include <vector>

#include "plan/access_path.hpp"

namespace crowddb::index {

class FeatureGrid final : public FeaturePath {
 public:
  void run(const DiscView& points, std::span<const double> reach, const StaticScene& scene,
           FeatureLists& out, Executor& ex, QueryStats& stats) override;

 private:
  void build(const StaticScene& scene, double cell);

  uint64_t generation_ = 0;  // the scene the grid was built for (0: none)
  double x0_ = 0, y0_ = 0, x1_ = 0, y1_ = 0, cell_ = 1, inv_cell_ = 1;
  int64_t W_ = 0, H_ = 0;
  std::vector<uint32_t> start_;  // W * H + 1
  std::vector<uint32_t> items_;  // feature numbers, ascending within a cell
  std::vector<uint16_t> clear_;  // per cell: Chebyshev distance to the nearest non-empty cell
};

}  // namespace crowddb::index
