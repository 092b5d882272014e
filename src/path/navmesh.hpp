// A navigation mesh for one agent-radius class (DESIGN.md §6), built with Recast and queried
// with Detour.
//
// Build: the world's bounds are the floor; every cell whose square touches an obstacle (circle
// or polygon, exact geometry; `touch`) is marked unwalkable; Recast erodes the walkable cells by
// the class radius plus a safety margin (its distance transform overestimates diagonal distances by
// up to 12% and contour simplification moves edges by up to a cell), then partitions the rest into
// regions, contours and convex polygons. Large worlds are split into square tiles built
// independently (in parallel when an executor is given) and joined by Detour.
//
// Queries: PathFinder (A* over polygons, then the funnel algorithm for the corner points) and
// NavMesh::visible (Detour raycast: is the straight segment inside the eroded walkable area,
// i.e. can a disc of the class radius walk it?).
//
// Coordinates: Recast works in floats; the mesh stores positions relative to the bounds'
// minimum corner so that large world coordinates keep their precision.
//
// Thread-safety: a built NavMesh is immutable. visible() and nearest() may be called from many
// threads at once (they use only Detour's read-only queries). A PathFinder owns Detour's search
// state: one per thread.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "crowddb/world.hpp"

class dtNavMesh;
class dtNavMeshQuery;
class dtQueryFilter;

namespace crowddb {
class Executor;
}

namespace crowddb::path {

// The static geometry a mesh is built from: the floor (bounds) and the obstacles.
struct NavGeometry {
  Bounds bounds;
  std::vector<CircleObstacle> circles;
  std::vector<PolygonObstacle> polygons;  // simple, counter-clockwise (as World stores them)

  static NavGeometry of(const World& world);
};

struct NavMeshParams {
  double radius = 1;            // clearance kept from obstacles and bounds [length] (> 0)
  double cell_size = 0.25;      // Recast cell side [length] (> 0)
  int tile_size = 256;          // cells per tile side (16..4096)
  double max_edge_error = 1.0;  // contour simplification tolerance [cells]
  // [cells] a cell is unwalkable when its centre lies within this of an obstacle (0..1); half a
  // diagonal marks every cell whose square touches one. 0.5 opens passages about half a cell
  // narrower and still keeps `radius` from every obstacle (tests/path/navmesh_test.cpp).
  double touch = 0.7071067811865476;  // sqrt(0.5)
  // [length] PathFinder keeps a path's corners this far inside the mesh's edges where there is
  // room (the funnel over portals shrunk by it; through the middle of a narrower gap); 0:
  // corners on the mesh's edges (Detour's straight path). On a mesh eroded by less than the
  // agent's radius, to keep its disc off the walls; on one eroded by the radius, to keep the
  // corners off a door's posts (NavigationParams::corner_push).
  double corner_push = 0;
  // The most `corner_push` moves either end of a portal, as a share of its length: 0.5 lets a
  // gap narrower than twice the push be crossed at its middle; less keeps a strip of it in use
  // (one point for everyone slows a crowd through a narrow exit).
  double push_share = 0.5;
};

struct NavMeshStats {
  int tiles = 0;  // tiles holding polygons
  int tiles_x = 0, tiles_y = 0;
  int polygons = 0;
  int vertices = 0;
  int erode_cells = 0;  // erosion radius [cells]
  double seconds = 0;   // build wall time
};

enum class PathStatus : uint8_t {
  ok,        // a path to the goal
  partial,   // the goal is unreachable (or the search ran out of nodes): a path towards it
  no_start,  // no mesh polygon near the start
  no_goal,   // no mesh polygon near the goal
};

const char* to_string(PathStatus s);

struct PathResult {
  PathStatus status = PathStatus::no_start;
  std::vector<Vec2> corners;  // intermediate corners, start and end excluded
  Vec2 start{}, end{};        // the start and end points on the mesh
  double length = 0;          // start -> corners -> end
  // How far the start or the goal (the larger) had to move onto the mesh: within the mesh's
  // clearance for a point a disc of its radius can stand on; farther for one in a pocket or a
  // passage too narrow for the mesh, whose nearest polygon may lie across a wall.
  double snap = 0;
  std::vector<uint32_t> corridor;  // the polygons walked through, start to end (mesh refs)
  // With polygon costs: the search's cost (length through the portals' midpoints plus the costs
  // of the polygons entered); 0 when Detour's corridor stands (no costs given, or none on it).
  double cost = 0;
};

// A segment across a narrow place of the mesh, from a wall to a wall (NavMesh::door_at), and
// what crossing it costs [m].
struct DoorCut {
  Vec2 a{}, b{};
  double cost = 0;
};

// Does the step from p to q cross the cut from a to b? A point on the cut's line counts as lying
// on its left (half-open sides), so a path through a point of the cut crosses it once.
bool cut_crossed(Vec2 a, Vec2 b, Vec2 p, Vec2 q);

// Extra costs [m] for a search that should avoid some places (congestion-aware re-planning and
// queues at doors, src/path/navigation.hpp): of entering mesh polygons (`entries`, sorted by
// polygon ref, each ref once) and of crossing door cuts (`cuts`: a step of the search that
// crosses one pays its cost). Costs finite and >= 0.
struct PolygonCosts {
  std::vector<std::pair<uint32_t, double>> entries;
  std::vector<DoorCut> cuts;
  double of(uint32_t ref) const;
  bool empty() const { return entries.empty() && cuts.empty(); }
};

// The shared edge between two adjacent mesh polygons, as the search sees it.
struct MeshPortal {
  uint32_t from = 0, to = 0;
  Vec2 left{}, right{};  // as seen walking from `from` to `to`
};

class NavMesh {
 public:
  // Throws Error(input) when the parameters are out of range or Recast fails (out of memory, a
  // world too large for the cell size).
  static std::unique_ptr<NavMesh> build(const NavGeometry& geometry, const NavMeshParams& params,
                                        Executor* ex = nullptr);
  ~NavMesh();
  NavMesh(const NavMesh&) = delete;
  NavMesh& operator=(const NavMesh&) = delete;

  const NavMeshParams& params() const { return params_; }
  const NavMeshStats& stats() const { return stats_; }
  // The eroded clearance [length]: erode_cells * cell_size.
  double clearance() const;

  // The closest point on the mesh within `reach` of p (searching a square of half-side reach).
  std::optional<Vec2> nearest(Vec2 p, double reach) const;
  // The first narrow place along a path (`path`: points, the first where the walker stands),
  // within `look` of its start: sampled every cell (at least 0.2 apart), the way across the mesh
  // at a sample is the shorter of two: across the path's direction from edge to edge, and from
  // the nearest wall (Detour's distance to wall) straight away from it to the wall beyond
  // (raycasts); a place is narrow where that way, plus the clearance on either side, is at most
  // `max_width`. Of the first run of narrow samples, the narrowest way: a door's
  // cut from post to post. None when no sample is narrow. DoorCut::cost is 0.
  // `ctx`: a context of the caller's own (one per thread: distance to walls uses Detour's
  // node pool); none: the mesh's own, for one thread at a time. A sample near an open one (whose
  // nearest wall lies farther than max_width / 2 minus the clearance) is skipped when no wall can
  // be near enough there to make it narrow; `every_sample`: none is (the twin the tests compare
  // with). `trace`: what became of each sample, in order (for tests).
  class Context;
  enum class Sample : uint8_t { skipped, open, other, narrow };
  std::optional<DoorCut> first_narrows(const std::vector<Vec2>& path, double look, double max_width,
                                       Context* ctx = nullptr, bool every_sample = false,
                                       std::vector<Sample>* trace = nullptr) const;
  // Line of sight for a disc of the mesh's radius: from the mesh point nearest `from` to `to`
  // without leaving the walkable polygons. False when `from` is off the mesh.
  bool visible(Vec2 from, Vec2 to) const;

  // Every mesh polygon as world-coordinate vertices (for tests and debugging).
  std::vector<std::vector<Vec2>> polygons() const;
  // The polygon (ref) under or nearest to p within `reach`; 0 when none.
  uint32_t polygon_at(Vec2 p, double reach) const;
  // The polygon under or nearest to p within `reach` (a square of that half-side) and its point
  // nearest p: Detour's findNearestPoly, bit for bit. A point well inside a polygon is answered
  // from a grid of the polygons' boxes; `naive`: always Detour's search (the twin the tests
  // compare with). ref 0 when none.
  struct Located {
    uint32_t ref = 0;
    Vec2 at{};
  };
  Located locate_point(Vec2 p, double reach, bool naive = false) const;
  // The grid's answer alone: the polygon p lies well inside, or ref 0 when that is not certain.
  Located locate_inside(Vec2 p) const;
  bool valid_polygon(uint32_t ref) const;
  // Every link between adjacent polygons, each direction once, in mesh order (for tests: the
  // naive twin of the search with polygon costs).
  std::vector<MeshPortal> portals() const;

 private:
  friend class PathFinder;
  NavMesh() = default;
  float lx(double x) const { return static_cast<float>(x - origin_.x); }
  float ly(double y) const { return static_cast<float>(y - origin_.y); }
  Vec2 world(const float* p) const { return {origin_.x + p[0], origin_.y + p[2]}; }
  // Nearest polygon to a local point, searching squares of growing half-side.
  unsigned int locate(const dtNavMeshQuery& q, const float* p, float* snapped) const;
  // Detour's findNearestPoly (local point, half-extents): the grid's answer when p lies well
  // inside a polygon (see navmesh.cpp), else Detour's search. 0 when none.
  unsigned int nearest_poly(const dtNavMeshQuery& q, const float* p, const float* ext,
                            float* snapped) const;
  unsigned int inside_poly(const dtNavMeshQuery& q, const float* p, const float* ext,
                           float* snapped) const;
  void build_poly_grid();

  NavMeshParams params_;
  NavMeshStats stats_;
  Vec2 origin_{};
  float reach_ = 1;  // first search half-side for locate()
  dtNavMesh* mesh_ = nullptr;
  dtNavMeshQuery* shared_query_ = nullptr;  // read-only queries only
  std::unique_ptr<dtQueryFilter> filter_;
  // The ground polygons whose bounding boxes meet each cell of a uniform grid (local x, z):
  // refs of cell c in refs[start[c], start[c + 1]).
  struct PolyGrid {
    float x0 = 0, z0 = 0, cell = 1, inv_cell = 1;
    int w = 0, h = 0;
    std::vector<uint32_t> start, polys;  // cell c lists polys[start[c], start[c + 1])
    // Per polygon its ref and edges; per edge (mesh-local x, z) its start and its direction
    // times the winding's sign (+-1: the inside is on the left either way), and its length.
    struct Edge {
      double ax, az, ex, ez, len;
    };
    struct Poly {
      uint32_t ref, first, count;  // count 0: no area (nothing lies inside it)
    };
    std::vector<Poly> poly;
    std::vector<Edge> edges;
  };
  PolyGrid grid_;
  // Is (x, z) inside the polygon of edges e[0, count) by at least `margin`?
  static bool inside_by(const PolyGrid::Edge* e, uint32_t count, double x, double z, double margin);
};

// A query context over one mesh for first_narrows on several threads (one each): the same
// node pool size as the mesh's own, so the same answers.
class NavMesh::Context {
 public:
  explicit Context(const NavMesh& mesh);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

 private:
  friend class NavMesh;
  dtNavMeshQuery* query_ = nullptr;
};

// A path search context over one mesh (Detour's node pool and open list). One per thread.
class PathFinder {
 public:
  explicit PathFinder(const NavMesh& mesh, int max_nodes = 16384);
  ~PathFinder();
  PathFinder(const PathFinder&) = delete;
  PathFinder& operator=(const PathFinder&) = delete;

  // The shortest corridor of polygons from start to goal, and its corner points (Detour's
  // findPath + findStraightPath). Deterministic: the same mesh and inputs give the same result.
  // With `costs` (not empty), when Detour's corridor enters a polygon with a cost: the corridor
  // of least cost instead, where a step from one portal to the next (or from the start, or to
  // the goal) costs its length, plus the cost of the polygon it enters and of the door cuts it
  // crosses; the corners then come
  // from Detour's funnel over that corridor as usual. When that search cannot reach the goal
  // within the node budget, Detour's corridor stays.
  PathResult find(Vec2 start, Vec2 goal, const PolygonCosts* costs = nullptr);

 private:
  bool portal(unsigned int from, unsigned int to, float* left, float* right) const;
  void funnel(PathResult& r, const float* start, const float* end, int npolys, double push) const;
  // A* over the portals' midpoints with polygon costs; fills polys_ and returns their number,
  // or 0 when the goal is not reached within max_nodes_ expansions.
  int costed_corridor(unsigned int sref, unsigned int gref, const float* s, const float* g,
                      const PolygonCosts& costs, double& cost);
  const NavMesh& mesh_;
  int max_nodes_ = 16384;
  dtNavMeshQuery* query_ = nullptr;
  std::vector<unsigned int> polys_;
  // costed_corridor's scratch, kept from search to search.
  struct CostNode {
    double g;        // cost so far
    double x, z;     // position (local mesh coordinates)
    uint32_t poly;   // the polygon this node is in (entered)
    int32_t parent;  // node index, -1 for the start
    bool closed;
  };
  std::vector<CostNode> cost_nodes_;
  std::unordered_map<uint64_t, int32_t> cost_index_;
  std::vector<std::pair<double, int32_t>> cost_open_;
};

}  // namespace crowddb::path
