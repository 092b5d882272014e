// The triangulation heuristic for collision sets (thesis §3.3.2, DESIGN.md §3.2): triangulate
// the centres (CGAL's Delaunay triangulation), add for every pair of adjacent triangles the
// missing diagonal (so each quadrilateral becomes a 4-clique), and test only those edges.
//
// NOT exact: it never reports a pair that does not overlap (every candidate goes through the
// oracle's discs_overlap), but it misses a pair whose centres are not joined by a Delaunay edge
// or such a diagonal: a large disc whose overlapping neighbours' centres are screened from its
// centre by two layers of other centres (tests/index/collisions_delaunay_test.cpp builds one;
// the thesis's Figure 3.2). A plain ring around one disc is a Delaunay fan and is found.
// Registered with exact = false, so the planner never chooses it; it is usable by name.
//
// Coincident centres share one triangulation vertex; all their pairs are tested (they always
// overlap), and an edge of that vertex stands for every member. CGAL lives in this translation
// unit only (built with the -frounding-math CGAL needs, apart from the rest of the library).
// Cost: O(n log n) expected for the triangulation, O(n) candidate edges.
#pragma once

#include "plan/access_path.hpp"

namespace crowddb::index {

class CollisionDelaunay final : public CollisionPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, CollisionPairs& out, Executor& ex,
           QueryStats& stats) override;
};

}  // namespace crowddb::index
