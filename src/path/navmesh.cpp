#include "path/navmesh.hpp"

#include <DetourCommon.h>
#include <DetourNavMesh.h>
#include <DetourNavMeshBuilder.h>
#include <DetourNavMeshQuery.h>
#include <Recast.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdarg>
#include <cstring>
#include <queue>
#include <string>
#include <unordered_map>

#include "util/executor.hpp"
#include "util/plain_number.hpp"
#include "util/stopwatch.hpp"
#include "world/geometry.hpp"

namespace crowddb::path {
namespace {

// Heights: the floor is the plane y = 0; nothing stands above it, so any positive clearance
// and climb will do. One cell of height is enough.
constexpr float kCellHeight = 0.5f;
constexpr float kFloorBelow = -1.0f, kFloorAbove = 2.0f;
constexpr int kWalkableHeight = 2, kWalkableClimb = 1;  // [cells]
// Extra erosion beyond ceil(radius / cell): the chamfer distance transform and contour
// simplification may each bring the mesh edge up to about a cell closer to an obstacle.
constexpr int kErodeMargin = 1;
constexpr unsigned short kWalkFlag = 1;
constexpr int kMaxPathPolys = 4096;
// Node pool of the mesh's own query context and of NavMesh::Context: the distance to walls
// explores this many polygons at most (the same number everywhere, so the same answers). 16 cut
// short 0.2-1.7 % of the door searches' distances in the shipped airports (a wall missed, a door
// seen wider than it is; no run changed with 256, where none was cut short in any scenario we
// have: docs/bench/journal.md).
constexpr int kSharedNodes = 256;
constexpr int kMaxStraight = 512;
static_assert(sizeof(dtPolyRef) == sizeof(uint32_t), "polygon refs are stored as 32 bits");

// Recast reports failures through its context's log; keep the first error for the message.
class Context : public rcContext {
 public:
  Context() : rcContext(true) {}
  std::string error;

 protected:
  void doLog(const rcLogCategory category, const char* msg, const int len) override {
    if (category == RC_LOG_ERROR && error.empty())
      error.assign(msg, static_cast<std::size_t>(std::max(0, len)));
  }
};

template <class T, void (*Free)(T*)>
struct RcPtr {
  T* p;
  explicit RcPtr(T* q) : p(q) {}
  ~RcPtr() { Free(p); }
  RcPtr(const RcPtr&) = delete;
  RcPtr& operator=(const RcPtr&) = delete;
  T* operator->() const { return p; }
  T& operator*() const { return *p; }
};
using Heightfield = RcPtr<rcHeightfield, rcFreeHeightField>;
using CompactHeightfield = RcPtr<rcCompactHeightfield, rcFreeCompactHeightfield>;
using ContourSet = RcPtr<rcContourSet, rcFreeContourSet>;
using PolyMesh = RcPtr<rcPolyMesh, rcFreePolyMesh>;

struct Box {
  double xmin, ymin, xmax, ymax;
  bool overlaps(const Box& o) const {
    return xmin <= o.xmax && o.xmin <= xmax && ymin <= o.ymax && o.ymin <= ymax;
  }
};

// Obstacles in mesh-local coordinates with their bounding boxes.
struct LocalObstacles {
  std::vector<CircleObstacle> circles;
  std::vector<std::vector<Vec2>> rings;
  std::vector<Box> circle_boxes, ring_boxes;
};

LocalObstacles localise(const NavGeometry& g, Vec2 o) {
  LocalObstacles L;
  for (const CircleObstacle& c : g.circles) {
    CircleObstacle l = c;
    l.x -= o.x;
    l.y -= o.y;
    L.circles.push_back(l);
    L.circle_boxes.push_back({l.x - l.radius, l.y - l.radius, l.x + l.radius, l.y + l.radius});
  }
  for (const PolygonObstacle& p : g.polygons) {
    std::vector<Vec2> ring;
    Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (const Vec2& v : p.vertices) {
      ring.push_back({v.x - o.x, v.y - o.y});
      b = {std::min(b.xmin, ring.back().x), std::min(b.ymin, ring.back().y),
           std::max(b.xmax, ring.back().x), std::max(b.ymax, ring.back().y)};
    }
    L.rings.push_back(std::move(ring));
    L.ring_boxes.push_back(b);
  }
  return L;
}

// Marks every compact-heightfield cell whose centre lies within `touch` cells of an obstacle as
// unwalkable (0.71, half a diagonal: every cell whose square touches it). Exact geometry (no
// triangulation), so non-convex polygons need no decomposition.
void mark_obstacles(rcCompactHeightfield& chf, const LocalObstacles& L, double touch_cells) {
  const double cs = chf.cs, touch = touch_cells * cs, pad = std::max(touch, cs * std::sqrt(0.5));
  const double bx = chf.bmin[0], bz = chf.bmin[2];
  auto block = [&](const Box& box, auto&& touches) {
    const int x0 = std::max(0, static_cast<int>(std::floor((box.xmin - pad - bx) / cs)));
    const int x1 =
        std::min(chf.width - 1, static_cast<int>(std::floor((box.xmax + pad - bx) / cs)));
    const int z0 = std::max(0, static_cast<int>(std::floor((box.ymin - pad - bz) / cs)));
    const int z1 =
        std::min(chf.height - 1, static_cast<int>(std::floor((box.ymax + pad - bz) / cs)));
    for (int z = z0; z <= z1; ++z)
      for (int x = x0; x <= x1; ++x) {
        const rcCompactCell& c = chf.cells[x + z * chf.width];
        if (c.count == 0) continue;
        if (!touches(bx + (x + 0.5) * cs, bz + (z + 0.5) * cs)) continue;
        for (unsigned i = c.index, e = c.index + c.count; i < e; ++i) chf.areas[i] = RC_NULL_AREA;
      }
  };
  const Box tile{bx, bz, bx + chf.width * cs, bz + chf.height * cs};
  for (std::size_t k = 0; k < L.circles.size(); ++k) {
    if (!L.circle_boxes[k].overlaps(
            {tile.xmin - pad, tile.ymin - pad, tile.xmax + pad, tile.ymax + pad}))
      continue;
    const CircleObstacle& c = L.circles[k];
    block(L.circle_boxes[k],
          [&](double x, double y) { return discs_overlap(x - c.x, y - c.y, c.radius + touch); });
  }
  for (std::size_t k = 0; k < L.rings.size(); ++k) {
    if (!L.ring_boxes[k].overlaps(
            {tile.xmin - pad, tile.ymin - pad, tile.xmax + pad, tile.ymax + pad}))
      continue;
    const auto& ring = L.rings[k];
    block(L.ring_boxes[k],
          [&](double x, double y) { return disc_overlaps_polygon(ring, x, y, touch); });
  }
}

struct TileData {
  unsigned char* data = nullptr;
  int size = 0;
  int polygons = 0, vertices = 0;
  std::string error;
};

struct TileJob {
  int tx, ty;
  int tile_cells, border, erode;
  float cs;
  float world_w, world_h;  // local floor extent
  const LocalObstacles* obstacles;
  double touch;  // [cells] see mark_obstacles
};

TileData build_tile(const TileJob& j) {
  TileData out;
  Context ctx;
  auto fail = [&](const char* step) {
    out.error = std::string(step) + (ctx.error.empty() ? "" : ": " + ctx.error);
    return out;
  };
  const float tile_w = static_cast<float>(j.tile_cells) * j.cs;
  const float pad = static_cast<float>(j.border) * j.cs;
  float bmin[3] = {static_cast<float>(j.tx) * tile_w - pad, kFloorBelow,
                   static_cast<float>(j.ty) * tile_w - pad};
  float bmax[3] = {static_cast<float>(j.tx + 1) * tile_w + pad, kFloorAbove,
                   static_cast<float>(j.ty + 1) * tile_w + pad};
  const int side = j.tile_cells + 2 * j.border;

  Heightfield hf(rcAllocHeightfield());
  if (!hf.p || !rcCreateHeightfield(&ctx, *hf, side, side, bmin, bmax, j.cs, kCellHeight))
    return fail("heightfield");
  // The floor: the bounds rectangle as two triangles (Recast clips them to the tile).
  const float verts[12] = {0, 0, 0, j.world_w, 0, 0, j.world_w, 0, j.world_h, 0, 0, j.world_h};
  const int tris[6] = {0, 2, 1, 0, 3, 2};
  const unsigned char areas[2] = {RC_WALKABLE_AREA, RC_WALKABLE_AREA};
  if (!rcRasterizeTriangles(&ctx, verts, 4, tris, areas, 2, *hf, kWalkableClimb))
    return fail("rasterize");

  CompactHeightfield chf(rcAllocCompactHeightfield());
  if (!chf.p || !rcBuildCompactHeightfield(&ctx, kWalkableHeight, kWalkableClimb, *hf, *chf))
    return fail("compact heightfield");
  mark_obstacles(*chf, *j.obstacles, j.touch);
  if (!rcErodeWalkableArea(&ctx, j.erode, *chf)) return fail("erode");
  // Watershed partitioning: the most regular polygons, hence the best A* corridors. Layer and
  // monotone partitioning built the 1 km benchmark world twice as fast but, in a single large
  // tile, led A* into a corridor 10% longer (tests/path/navmesh_test.cpp, TilesJoinSeamlessly).
  if (!rcBuildDistanceField(&ctx, *chf)) return fail("distance field");
  if (!rcBuildRegions(&ctx, *chf, j.border, /*minRegionArea=*/8, /*mergeRegionArea=*/64))
    return fail("regions");
  ContourSet cset(rcAllocContourSet());
  if (!cset.p || !rcBuildContours(&ctx, *chf, /*maxError=*/1.0f, /*maxEdgeLen=*/64, *cset))
    return fail("contours");
  if (cset->nconts == 0) return out;  // nothing walkable in this tile
  PolyMesh pmesh(rcAllocPolyMesh());
  if (!pmesh.p || !rcBuildPolyMesh(&ctx, *cset, DT_VERTS_PER_POLYGON, *pmesh))
    return fail("polygon mesh");
  if (pmesh->npolys == 0) return out;
  for (int i = 0; i < pmesh->npolys; ++i)
    pmesh->flags[i] = pmesh->areas[i] == RC_WALKABLE_AREA ? kWalkFlag : 0;

  dtNavMeshCreateParams p;
  std::memset(&p, 0, sizeof p);
  p.verts = pmesh->verts;
  p.vertCount = pmesh->nverts;
  p.polys = pmesh->polys;
  p.polyAreas = pmesh->areas;
  p.polyFlags = pmesh->flags;
  p.polyCount = pmesh->npolys;
  p.nvp = pmesh->nvp;
  p.walkableHeight = kWalkableHeight * kCellHeight;
  p.walkableRadius = static_cast<float>(j.erode) * j.cs;
  p.walkableClimb = kWalkableClimb * kCellHeight;
  p.tileX = j.tx;
  p.tileY = j.ty;
  p.tileLayer = 0;
  rcVcopy(p.bmin, pmesh->bmin);
  rcVcopy(p.bmax, pmesh->bmax);
  p.cs = j.cs;
  p.ch = kCellHeight;
  p.buildBvTree = true;
  if (!dtCreateNavMeshData(&p, &out.data, &out.size)) return fail("Detour tile data");
  out.polygons = pmesh->npolys;
  out.vertices = pmesh->nverts;
  return out;
}

int bits_for(int n) {
  int b = 0;
  while ((1 << b) < n) ++b;
  return b;
}

[[noreturn]] void bad(const std::string& what) {
  throw Error(Error::Kind::input, "navigation mesh: " + what);
}

// The edge a link of `poly` crosses into its neighbour (a part of it at a tile border), as
// Detour's private getPortalPoints finds it: left and right as seen walking out of `poly`.
void link_portal(const dtMeshTile& tile, const dtPoly& poly, const dtLink& link, float* left,
                 float* right) {
  const float* v0 = &tile.verts[poly.verts[link.edge] * 3];
  const float* v1 = &tile.verts[poly.verts[(link.edge + 1) % poly.vertCount] * 3];
  dtVcopy(left, v0);
  dtVcopy(right, v1);
  if (link.side != 0xff && (link.bmin != 0 || link.bmax != 255)) {
    dtVlerp(left, v0, v1, link.bmin / 255.0f);
    dtVlerp(right, v0, v1, link.bmax / 255.0f);
  }
}

}  // namespace

const char* to_string(PathStatus s) {
  switch (s) {
    case PathStatus::ok:
      return "ok";
    case PathStatus::partial:
      return "partial";
    case PathStatus::no_start:
      return "no_start";
    case PathStatus::no_goal:
    default:
      return "no_goal";
  }
}

NavGeometry NavGeometry::of(const World& w) {
  return {w.bounds(),
          {w.circles().begin(), w.circles().end()},
          {w.polygons().begin(), w.polygons().end()}};
}

NavMesh::~NavMesh() {
  dtFreeNavMeshQuery(shared_query_);
  dtFreeNavMesh(mesh_);
}

double NavMesh::clearance() const {
  return stats_.erode_cells * params_.cell_size;
}

std::unique_ptr<NavMesh> NavMesh::build(const NavGeometry& g, const NavMeshParams& params,
                                        Executor* ex) {
  Stopwatch clock;
  const double cs = params.cell_size;
  if (!(std::isfinite(params.radius) && params.radius > 0)) bad("radius must be > 0");
  if (!(std::isfinite(cs) && cs > 0)) bad("cell_size must be > 0");
  if (params.tile_size < 16 || params.tile_size > 4096) bad("tile_size must be in 16..4096");
  if (!(params.touch >= 0 && params.touch <= 1)) bad("touch must be in [0, 1] cells");
  const Bounds& b = g.bounds;
  if (!(b.width() > 0 && b.height() > 0)) bad("the bounds are empty");
  const double erode_cells = std::ceil(params.radius / cs) + kErodeMargin;  // may be huge
  if (!(erode_cells <= 120))
    throw Error(Error::Kind::input,
                "/navigation/cell_size: " + plain_number(cs) +
                    " is too small for agents of radius " + plain_number(params.radius) +
                    " (the navigation mesh would erode over 120 cells): raise cell_size");
  const int erode = static_cast<int>(erode_cells);
  const double gw = std::ceil(b.width() / cs), gh = std::ceil(b.height() / cs);
  const double tx = std::ceil(gw / params.tile_size), ty = std::ceil(gh / params.tile_size);
  if (!(tx * ty <= 16384))
    throw Error(Error::Kind::input,
                "/navigation: the navigation mesh would need " +
                    (std::isfinite(tx * ty) ? plain_number(tx * ty) : std::string("too many")) +
                    " tiles at cell_size " + plain_number(cs) +
                    " (at most 16384): raise cell_size or tile_size");
  const int tiles_x = static_cast<int>(tx), tiles_y = static_cast<int>(ty);

  auto nm = std::unique_ptr<NavMesh>(new NavMesh());
  nm->params_ = params;
  nm->origin_ = {b.xmin, b.ymin};
  nm->stats_.erode_cells = erode;
  nm->stats_.tiles_x = tiles_x;
  nm->stats_.tiles_y = tiles_y;
  nm->reach_ = static_cast<float>((erode + 1) * cs);
  const LocalObstacles local = localise(g, nm->origin_);

  nm->mesh_ = dtAllocNavMesh();
  if (!nm->mesh_) bad("out of memory");
  dtNavMeshParams np;
  std::memset(&np, 0, sizeof np);
  np.tileWidth = np.tileHeight = static_cast<float>(params.tile_size * cs);
  np.maxTiles = tiles_x * tiles_y;
  const int tile_bits = std::max(1, bits_for(np.maxTiles));
  np.maxPolys = 1 << (22 - tile_bits);
  if (dtStatusFailed(nm->mesh_->init(&np))) bad("Detour could not initialise the mesh");

  const int n = tiles_x * tiles_y;
  std::vector<TileData> tiles(static_cast<std::size_t>(n));
  auto build_range = [&](std::size_t lo, std::size_t hi) {
    for (std::size_t k = lo; k < hi; ++k) {
      TileJob j{static_cast<int>(k) % tiles_x,
                static_cast<int>(k) / tiles_x,
                params.tile_size,
                erode + 3,
                erode,
                static_cast<float>(cs),
                static_cast<float>(b.width()),
                static_cast<float>(b.height()),
                &local,
                params.touch};
      tiles[k] = build_tile(j);
    }
  };
  if (ex)
    ex->for_each_chunk(tiles.size(), 1, build_range);
  else
    build_range(0, tiles.size());
  // Tiles join the mesh in index order, so the mesh (and its polygon refs) never depends on
  // which thread built which tile.
  std::string first_error;
  for (std::size_t k = 0; k < tiles.size(); ++k) {
    TileData& t = tiles[k];
    if (!t.error.empty() && first_error.empty())
      first_error = "tile " + std::to_string(k) + ": " + t.error;
    if (!t.data) continue;
    if (!first_error.empty() || t.polygons > np.maxPolys ||
        dtStatusFailed(nm->mesh_->addTile(t.data, t.size, DT_TILE_FREE_DATA, 0, nullptr))) {
      if (first_error.empty()) first_error = "tile " + std::to_string(k) + " could not be added";
      dtFree(t.data);
      continue;
    }
    ++nm->stats_.tiles;
    nm->stats_.polygons += t.polygons;
    nm->stats_.vertices += t.vertices;
  }
  if (!first_error.empty()) bad("Recast failed: " + first_error);
  nm->shared_query_ = dtAllocNavMeshQuery();
  if (!nm->shared_query_ || dtStatusFailed(nm->shared_query_->init(nm->mesh_, kSharedNodes)))
    bad("out of memory");
  nm->filter_ = std::make_unique<dtQueryFilter>();
  nm->build_poly_grid();
  nm->stats_.seconds = clock.seconds();
  return nm;
}

// ------------------------------------------------------------------------- point location
//
// Detour's findNearestPoly computes, for every polygon whose box meets the search square, its
// point nearest p and a distance, and keeps the first of least distance in its traversal order.
// A point over a polygon and within climb of its floor is at distance 0, the least there is. So
// when p lies inside a polygon P by a margin that no float rounding bridges, P is the only
// polygon at distance 0 (the mesh is one layer: polygons meet only along their edges, and every
// other polygon, its nearest point included, lies at least the margin away), and findNearestPoly
// answers P and closestPointOnPoly(P, p) whatever its order. A grid of the polygons' boxes finds
// P without the search (a few point-in-polygon tests instead of Detour's distance to the edges of
// every polygon near p); anything else (near an edge, off the mesh, above a floor beyond climb)
// goes to Detour. tests/path/navmesh_test.cpp compares the two on random and adversarial points.

namespace {

// Calls fn(tile, polygon, ref) for every ground polygon of the mesh, in mesh order.
template <class F>
void for_each_ground_polygon(const dtNavMesh& m, F&& fn) {
  for (int i = 0; i < m.getMaxTiles(); ++i) {
    const dtMeshTile* t = m.getTile(i);
    if (!t || !t->header) continue;
    const dtPolyRef base = m.getPolyRefBase(t);
    for (int k = 0; k < t->header->polyCount; ++k) {
      const dtPoly& p = t->polys[k];
      if (p.getType() == DT_POLYTYPE_GROUND) fn(*t, p, base | static_cast<dtPolyRef>(k));
    }
  }
}

// [m] How far inside its polygon a point must lie for the grid's answer: the float rounding of
// local coordinates (below 10^-3 m up to 10 km from the mesh's corner) many times over.
double inside_margin(const float* p) {
  return 1e-3 * std::max(1.0, (std::fabs(double{p[0]}) + std::fabs(double{p[2]})) / 1000.0);
}

}  // namespace

// Is (x, z) inside the polygon by at least `margin` from the line of every edge? (Then it lies
// in the polygon's kernel, at least `margin` from its boundary.) Either winding (the edges carry
// its sign); edges of length 0 were left out (their ends are the neighbouring edges' ends).
bool NavMesh::inside_by(const PolyGrid::Edge* e, uint32_t count, double x, double z,
                        double margin) {
  if (count == 0) return false;
  for (uint32_t i = 0; i < count; ++i)
    if (!(e[i].ex * (z - e[i].az) - e[i].ez * (x - e[i].ax) >= margin * e[i].len)) return false;
  return true;
}

void NavMesh::build_poly_grid() {
  struct Box {
    float x0, z0, x1, z1;
    uint32_t poly;  // its index in grid_.poly
  };
  std::vector<Box> boxes;
  float x0 = FLT_MAX, z0 = FLT_MAX, x1 = -FLT_MAX, z1 = -FLT_MAX;
  grid_ = {};
  PolyGrid& g = grid_;
  for_each_ground_polygon(*mesh_, [&](const dtMeshTile& t, const dtPoly& p, dtPolyRef ref) {
    // Its edges for inside_by: the winding's sign (twice the signed area, from the float
    // vertices in double), then each edge's start, direction times that sign, and length.
    const int n = p.vertCount;
    double area2 = 0;
    for (int i = 0, j = n - 1; i < n; j = i++) {
      const float* a = &t.verts[p.verts[j] * 3];
      const float* c = &t.verts[p.verts[i] * 3];
      area2 += double{a[0]} * c[2] - double{c[0]} * a[2];
    }
    const auto first = static_cast<uint32_t>(g.edges.size());
    if (area2 != 0) {
      const double side = area2 > 0 ? 1 : -1;
      for (int i = 0, j = n - 1; i < n; j = i++) {
        const float* a = &t.verts[p.verts[j] * 3];
        const float* c = &t.verts[p.verts[i] * 3];
        const double ex = double{c[0]} - a[0], ez = double{c[2]} - a[2];
        const double len = std::sqrt(ex * ex + ez * ez);
        if (len == 0) continue;
        // (side * (ex * dz - ez * dx) == (side * ex) * dz - (side * ez) * dx bit for bit: the
        // sign changes no rounding.)
        g.edges.push_back({a[0], a[2], side * ex, side * ez, len});
      }
    }
    const auto index = static_cast<uint32_t>(g.poly.size());
    g.poly.push_back({ref, first, static_cast<uint32_t>(g.edges.size()) - first});
    Box b{FLT_MAX, FLT_MAX, -FLT_MAX, -FLT_MAX, index};
    for (int v = 0; v < p.vertCount; ++v) {
      const float* q = &t.verts[p.verts[v] * 3];
      b.x0 = std::min(b.x0, q[0]);
      b.z0 = std::min(b.z0, q[2]);
      b.x1 = std::max(b.x1, q[0]);
      b.z1 = std::max(b.z1, q[2]);
    }
    x0 = std::min(x0, b.x0);
    z0 = std::min(z0, b.z0);
    x1 = std::max(x1, b.x1);
    z1 = std::max(z1, b.z1);
    boxes.push_back(b);
  });
  if (boxes.empty()) return;
  // About one polygon per cell.
  const double w = std::max(double{x1} - x0, 1e-3), h = std::max(double{z1} - z0, 1e-3);
  const double cell = std::sqrt(w * h / static_cast<double>(boxes.size()));
  g.x0 = x0;
  g.z0 = z0;
  g.cell = static_cast<float>(cell);
  g.inv_cell = static_cast<float>(1 / cell);
  g.w = static_cast<int>(std::min(w / cell + 1, 1e6));
  g.h = static_cast<int>(std::min(h / cell + 1, 1e6));
  const auto cx = [&](float v) {
    return std::clamp(static_cast<int>((v - g.x0) * g.inv_cell), 0, g.w - 1);
  };
  const auto cz = [&](float v) {
    return std::clamp(static_cast<int>((v - g.z0) * g.inv_cell), 0, g.h - 1);
  };
  g.start.assign(static_cast<std::size_t>(g.w) * static_cast<std::size_t>(g.h) + 1, 0);
  for (const Box& b : boxes)
    for (int z = cz(b.z0); z <= cz(b.z1); ++z)
      for (int x = cx(b.x0); x <= cx(b.x1); ++x)
        ++g.start[static_cast<std::size_t>(z) * g.w + x + 1];
  for (std::size_t c = 1; c < g.start.size(); ++c) g.start[c] += g.start[c - 1];
  g.polys.resize(g.start.back());
  std::vector<uint32_t> fill(g.start.begin(), g.start.end() - 1);
  for (const Box& b : boxes)
    for (int z = cz(b.z0); z <= cz(b.z1); ++z)
      for (int x = cx(b.x0); x <= cx(b.x1); ++x)
        g.polys[fill[static_cast<std::size_t>(z) * g.w + x]++] = b.poly;
}

unsigned int NavMesh::inside_poly(const dtNavMeshQuery& q, const float* p, const float* ext,
                                  float* snapped) const {
  const PolyGrid& g = grid_;
  // (NaN fails these too.)
  if (!(p[0] >= g.x0 && p[2] >= g.z0)) return 0;
  const float fx = (p[0] - g.x0) * g.inv_cell, fz = (p[2] - g.z0) * g.inv_cell;
  if (!(fx < static_cast<float>(g.w) && fz < static_cast<float>(g.h))) return 0;
  // The same cell arithmetic as the build's (monotone in p), so a box holding p lists its
  // polygon in p's cell.
  const int x = std::clamp(static_cast<int>(fx), 0, g.w - 1);
  const int z = std::clamp(static_cast<int>(fz), 0, g.h - 1);
  const std::size_t c = static_cast<std::size_t>(z) * g.w + x;
  const double margin = inside_margin(p);
  for (uint32_t k = g.start[c]; k < g.start[c + 1]; ++k) {
    const PolyGrid::Poly& candidate = g.poly[g.polys[k]];
    if (!inside_by(g.edges.data() + candidate.first, candidate.count, p[0], p[2], margin)) continue;
    const dtPolyRef ref = candidate.ref;
    const dtMeshTile* tile = nullptr;
    const dtPoly* poly = nullptr;
    mesh_->getTileAndPolyByRefUnsafe(ref, &tile, &poly);
    // Detour's own terms for this polygon: the filter, the point over it and its distance.
    // (dtQueryFilter::passFilter is Detour's inline, not exported: the same test.)
    if (!((poly->flags & filter_->getIncludeFlags()) != 0 &&
          (poly->flags & filter_->getExcludeFlags()) == 0))
      return 0;
    float at[3];
    bool over = false;
    if (dtStatusFailed(q.closestPointOnPoly(ref, p, at, &over)) || !over) return 0;
    float diff[3];
    dtVsub(diff, p, at);
    float d = dtAbs(diff[1]) - tile->header->walkableClimb;
    d = d > 0 ? d * d : 0;
    if (d != 0 || !(dtAbs(diff[1]) <= ext[1])) return 0;
    dtVcopy(snapped, at);
    return ref;
  }
  return 0;
}

unsigned int NavMesh::nearest_poly(const dtNavMeshQuery& q, const float* p, const float* ext,
                                   float* snapped) const {
  if (const unsigned int ref = inside_poly(q, p, ext, snapped)) return ref;
  dtPolyRef ref = 0;
  if (dtStatusFailed(q.findNearestPoly(p, ext, filter_.get(), &ref, snapped))) return 0;
  return ref;
}

NavMesh::Located NavMesh::locate_point(Vec2 p, double reach, bool naive) const {
  const float c[3] = {lx(p.x), 0, ly(p.y)};
  const float ext[3] = {static_cast<float>(reach), 2 * kFloorAbove, static_cast<float>(reach)};
  float s[3];
  dtPolyRef ref = 0;
  if (naive) {
    if (dtStatusFailed(shared_query_->findNearestPoly(c, ext, filter_.get(), &ref, s))) ref = 0;
  } else {
    ref = nearest_poly(*shared_query_, c, ext, s);
  }
  return ref ? Located{ref, world(s)} : Located{};
}

NavMesh::Located NavMesh::locate_inside(Vec2 p) const {
  const float c[3] = {lx(p.x), 0, ly(p.y)};
  const float ext[3] = {0, 2 * kFloorAbove, 0};
  float s[3];
  const unsigned int ref = inside_poly(*shared_query_, c, ext, s);
  return ref ? Located{ref, world(s)} : Located{};
}

unsigned int NavMesh::locate(const dtNavMeshQuery& q, const float* p, float* snapped) const {
  // The grid's answer holds for every square below (they share the vertical extent); Detour's
  // search only if it has none.
  const float column[3] = {0, 2 * kFloorAbove, 0};
  if (const unsigned int ref = inside_poly(q, p, column, snapped)) return ref;
  for (float reach = reach_; reach <= reach_ * 16; reach *= 4) {
    const float ext[3] = {reach, 2 * kFloorAbove, reach};
    dtPolyRef ref = 0;
    if (dtStatusSucceed(q.findNearestPoly(p, ext, filter_.get(), &ref, snapped)) && ref) return ref;
  }
  return 0;
}

std::optional<Vec2> NavMesh::nearest(Vec2 p, double reach) const {
  const Located l = locate_point(p, reach);
  if (!l.ref) return std::nullopt;
  return l.at;
}

bool NavMesh::visible(Vec2 from, Vec2 to) const {
  const float a[3] = {lx(from.x), 0, ly(from.y)};
  float s[3];
  const dtPolyRef ref = locate(*shared_query_, a, s);
  if (!ref) return false;
  const float e[3] = {lx(to.x), s[1], ly(to.y)};
  dtRaycastHit hit;
  std::memset(&hit, 0, sizeof hit);
  if (dtStatusFailed(shared_query_->raycast(ref, s, e, filter_.get(), 0, &hit))) return false;
  return hit.t == FLT_MAX;
}

std::vector<std::vector<Vec2>> NavMesh::polygons() const {
  std::vector<std::vector<Vec2>> out;
  for_each_ground_polygon(*mesh_, [&](const dtMeshTile& t, const dtPoly& p, dtPolyRef) {
    std::vector<Vec2> ring;
    for (int v = 0; v < p.vertCount; ++v) ring.push_back(world(&t.verts[p.verts[v] * 3]));
    out.push_back(std::move(ring));
  });
  return out;
}

uint32_t NavMesh::polygon_at(Vec2 p, double reach) const {
  return locate_point(p, reach).ref;
}

bool NavMesh::valid_polygon(uint32_t ref) const {
  return ref != 0 && mesh_->isValidPolyRef(ref);
}

std::vector<MeshPortal> NavMesh::portals() const {
  std::vector<MeshPortal> out;
  for_each_ground_polygon(*mesh_, [&](const dtMeshTile& t, const dtPoly& p, dtPolyRef ref) {
    for (unsigned int l = p.firstLink; l != DT_NULL_LINK; l = t.links[l].next) {
      const dtLink& link = t.links[l];
      if (!link.ref) continue;
      float a[3], b[3];
      link_portal(t, p, link, a, b);
      out.push_back({ref, link.ref, world(a), world(b)});
    }
  });
  return out;
}

bool cut_crossed(Vec2 a, Vec2 b, Vec2 p, Vec2 q) {
  const auto cross = [](Vec2 o, Vec2 u, Vec2 v) {
    return (u.x - o.x) * (v.y - o.y) - (u.y - o.y) * (v.x - o.x);
  };
  if ((cross(a, b, p) >= 0) == (cross(a, b, q) >= 0)) return false;
  const double oa = cross(p, q, a), ob = cross(p, q, b);
  return (oa <= 0 && ob >= 0) || (oa >= 0 && ob <= 0);
}

NavMesh::Context::Context(const NavMesh& mesh) {
  query_ = dtAllocNavMeshQuery();
  if (!query_ || dtStatusFailed(query_->init(mesh.mesh_, kSharedNodes))) {
    dtFreeNavMeshQuery(query_);
    throw Error(Error::Kind::input, "navigation mesh: out of memory for a query context");
  }
}

NavMesh::Context::~Context() {
  dtFreeNavMeshQuery(query_);
}

std::optional<DoorCut> NavMesh::first_narrows(const std::vector<Vec2>& path, double look,
                                              double max_width, Context* ctx, bool every_sample,
                                              std::vector<Sample>* trace) const {
  const dtNavMeshQuery& query = ctx ? *ctx->query_ : *shared_query_;
  const double reach = max_width - 2 * clearance();
  if (!(reach > 0) || path.size() < 2) return std::nullopt;
  const double step = std::max(params_.cell_size, 0.2);
  std::optional<DoorCut> best;
  double best_width = INFINITY;
  double walked = 0;
  // Samples that cannot be narrow are skipped: the distance to the nearest wall (capped at
  // `reach`) is 1-Lipschitz, so from a sample whose nearest wall lies d > reach / 2 away, every
  // point within d - reach / 2 of it has its nearest wall farther than reach / 2 too. Only a
  // complete search sets this window (one cut short by the node pool may have missed a wall);
  // the margin covers Detour's float arithmetic. A sample inside it is not narrow, as its own
  // search would have said, so the answer is the same.
  Vec2 open_at{};
  double open_for = 0;          // the window's radius around open_at (0: none)
  Sample kind = Sample::other;  // what across() made of the sample (for `trace`)
  // The way across the mesh at p, walking along (dx, dy), when narrow: across the walk's
  // direction (a path along a wall runs on the mesh's edge, where the nearest wall's direction is
  // not known), or straight away from the nearest wall (a path crossing a door at a slant).
  const auto across = [&](Vec2 p, double dx, double dy) -> std::optional<DoorCut> {
    const float a[3] = {lx(p.x), 0, ly(p.y)};
    float s[3];
    const dtPolyRef ref = locate(query, a, s);
    if (!ref) return std::nullopt;
    const Vec2 from = world(s);
    if (std::hypot(from.x - open_at.x, from.y - open_at.y) < open_for) {
      kind = Sample::skipped;
      return std::nullopt;
    }
    // How far from `from` along (ux, uy) the mesh reaches, up to `len`; infinite beyond.
    const auto ray = [&](double ux, double uy, double len) {
      const float e[3] = {lx(from.x + ux * len), s[1], ly(from.y + uy * len)};
      dtRaycastHit h;
      std::memset(&h, 0, sizeof h);
      if (dtStatusFailed(query.raycast(ref, s, e, filter_.get(), 0, &h)) || h.t == FLT_MAX)
        return static_cast<double>(INFINITY);
      return static_cast<double>(h.t) * len;
    };
    float d = 0, hit[3], normal[3];
    const dtStatus found =
        query.findDistanceToWall(ref, s, static_cast<float>(reach), filter_.get(), &d, hit, normal);
    if (dtStatusFailed(found)) return std::nullopt;
    if (!(2 * d <= reach)) {  // every way across is at least twice as long as to the nearest wall
      kind = Sample::open;
      if (!(found & DT_OUT_OF_NODES) && !every_sample) {
        open_at = from;
        open_for = d - reach / 2 - (1e-3 + 4e-7 * (std::abs(s[0]) + std::abs(s[2]) + reach));
      }
      return std::nullopt;
    }
    std::optional<DoorCut> narrow;
    double width = INFINITY;
    const double l1 = ray(-dy, dx, reach), l2 = ray(dy, -dx, reach);
    if (l1 + l2 <= reach) {
      width = l1 + l2;
      narrow =
          DoorCut{{from.x + dy * l2, from.y - dx * l2}, {from.x - dy * l1, from.y + dx * l1}, 0};
    }
    if (d > 0.01) {
      // Away from the wall (Detour's normal points from the wall to the point).
      const double far = ray(normal[0], normal[2], reach - d);
      if (d + far < width) {
        width = d + far;
        narrow = DoorCut{world(hit), {from.x + normal[0] * far, from.y + normal[2] * far}, 0};
      }
    }
    if (!(width > 0.5 * params_.cell_size)) return std::nullopt;  // a corner, not a way across
    return narrow;
  };
  for (std::size_t k = 0; k + 1 < path.size() && walked <= look; ++k) {
    const Vec2 u = path[k], v = path[k + 1];
    const double len = std::hypot(v.x - u.x, v.y - u.y);
    for (double at = step; at < len && walked + at <= look; at += step) {
      const Vec2 p{u.x + (v.x - u.x) * at / len, u.y + (v.y - u.y) * at / len};
      kind = Sample::other;
      const std::optional<DoorCut> cut = across(p, (v.x - u.x) / len, (v.y - u.y) / len);
      if (trace) trace->push_back(cut ? Sample::narrow : kind);
      if (!cut) {
        if (best) return best;  // the end of the first narrow run
        continue;
      }
      const double w = std::hypot(cut->b.x - cut->a.x, cut->b.y - cut->a.y);
      if (w < best_width) {
        best_width = w;
        best = cut;
      }
    }
    walked += len;
  }
  return best;
}

double PolygonCosts::of(uint32_t ref) const {
  const auto it = std::lower_bound(entries.begin(), entries.end(), ref,
                                   [](const auto& e, uint32_t r) { return e.first < r; });
  return it != entries.end() && it->first == ref ? it->second : 0;
}

PathFinder::PathFinder(const NavMesh& mesh, int max_nodes)
    : mesh_(mesh), max_nodes_(std::clamp(max_nodes, 64, 65535)), polys_(kMaxPathPolys) {
  query_ = dtAllocNavMeshQuery();
  if (!query_ || dtStatusFailed(query_->init(mesh.mesh_, max_nodes_)))
    throw Error(Error::Kind::input, "navigation mesh: out of memory for the path search");
}

PathFinder::~PathFinder() {
  dtFreeNavMeshQuery(query_);
}

PathResult PathFinder::find(Vec2 start, Vec2 goal, const PolygonCosts* costs) {
  PathResult r;
  const dtQueryFilter* filter = mesh_.filter_.get();
  const float sp[3] = {mesh_.lx(start.x), 0, mesh_.ly(start.y)};
  const float gp[3] = {mesh_.lx(goal.x), 0, mesh_.ly(goal.y)};
  float s[3], g[3];
  const dtPolyRef sref = mesh_.locate(*query_, sp, s);
  if (!sref) {
    r.status = PathStatus::no_start;
    return r;
  }
  const dtPolyRef gref = mesh_.locate(*query_, gp, g);
  if (!gref) {
    r.status = PathStatus::no_goal;
    return r;
  }
  const Vec2 ws = mesh_.world(s), wg = mesh_.world(g);
  r.snap = std::max(std::hypot(ws.x - start.x, ws.y - start.y),
                    std::hypot(wg.x - goal.x, wg.y - goal.y));
  int npolys = 0;
  const dtStatus st =
      query_->findPath(sref, gref, s, g, filter, polys_.data(), &npolys, kMaxPathPolys);
  if (dtStatusFailed(st) || npolys == 0) {
    r.status = PathStatus::no_goal;
    return r;
  }
  // With costs, search again only when Detour's corridor to the goal enters a polygon that has
  // one: costs only make other corridors dearer, so one that avoids them stays the least (and a
  // search over a 200 m forest of obstacles, SteerSuite's scenarioSpace, is not repeated for
  // every agent while a jam stands somewhere else).
  // (Door cuts: searched again whenever there are some; they come a few a tick.)
  if (costs && !costs->empty() && !dtStatusDetail(st, DT_PARTIAL_RESULT) &&
      polys_[static_cast<std::size_t>(npolys - 1)] == gref &&
      (!costs->cuts.empty() || std::any_of(polys_.begin() + 1, polys_.begin() + npolys,
                                           [&](dtPolyRef p) { return costs->of(p) > 0; })))
    if (const int n = costed_corridor(sref, gref, s, g, *costs, r.cost); n > 0) npolys = n;
  r.status = PathStatus::ok;
  float end[3] = {g[0], g[1], g[2]};
  if (polys_[static_cast<std::size_t>(npolys - 1)] != gref ||
      dtStatusDetail(st, DT_PARTIAL_RESULT)) {
    r.status = PathStatus::partial;
    query_->closestPointOnPoly(polys_[static_cast<std::size_t>(npolys - 1)], g, end, nullptr);
  }
  float straight[kMaxStraight * 3];
  unsigned char flags[kMaxStraight];
  dtPolyRef refs[kMaxStraight];
  int ns = 0;
  if (dtStatusFailed(query_->findStraightPath(s, end, polys_.data(), npolys, straight, flags, refs,
                                              &ns, kMaxStraight)) ||
      ns == 0) {
    r.status = PathStatus::no_goal;
    return r;
  }
  if (!(flags[ns - 1] & DT_STRAIGHTPATH_END)) r.status = PathStatus::partial;  // truncated
  r.corridor.assign(polys_.begin(), polys_.begin() + npolys);
  r.start = mesh_.world(&straight[0]);
  r.end = mesh_.world(&straight[(ns - 1) * 3]);
  if (mesh_.params_.corner_push > 0)
    funnel(r, s, end, npolys, mesh_.params_.corner_push);
  else
    for (int i = 1; i < ns - 1; ++i) r.corners.push_back(mesh_.world(&straight[i * 3]));
  Vec2 prev = r.start;
  for (const Vec2& c : r.corners) {
    r.length += std::hypot(c.x - prev.x, c.y - prev.y);
    prev = c;
  }
  r.length += std::hypot(r.end.x - prev.x, r.end.y - prev.y);
  return r;
}

// Nodes are the portals' midpoints (a portal entered from one side is a node of its own), the
// start and the goal points. A* with the straight-line distance to the goal as the heuristic:
// consistent, since every step costs at least its length, so the first time the goal comes off
// the queue its cost is the least. Ties on the queue go by node number, which follows the
// deterministic expansion order.
int PathFinder::costed_corridor(unsigned int sref, unsigned int gref, const float* s,
                                const float* g, const PolygonCosts& costs, double& cost) {
  const auto dist = [](double ax, double az, double bx, double bz) {
    return std::hypot(bx - ax, bz - az);
  };
  const double gx = g[0], gz = g[2];
  // The door cuts in the search's local coordinates, and what a step from (ax, az) to (bx, bz)
  // pays for those it crosses (cut_crossed).
  std::vector<DoorCut> cuts = costs.cuts;
  for (DoorCut& c : cuts) {
    c.a = {mesh_.lx(c.a.x), mesh_.ly(c.a.y)};
    c.b = {mesh_.lx(c.b.x), mesh_.ly(c.b.y)};
  }
  const auto step_cost = [&](double ax, double az, double bx, double bz) {
    double extra = 0;
    for (const DoorCut& c : cuts)
      if (cut_crossed(c.a, c.b, {ax, az}, {bx, bz})) extra += c.cost;
    return extra;
  };
  std::vector<CostNode>& nodes = cost_nodes_;
  auto& index = cost_index_;  // (from << 32 | to) of a portal -> node
  auto& open = cost_open_;    // (cost + heuristic, node), least first
  nodes.clear();
  index.clear();
  open.clear();
  const auto push = [&](double f, int32_t n) {
    open.emplace_back(f, n);
    std::push_heap(open.begin(), open.end(), std::greater<>());
  };
  nodes.push_back({0, s[0], s[2], sref, -1, false});
  push(dist(s[0], s[2], gx, gz), 0);
  int32_t goal_node = -1;
  double goal_cost = INFINITY;
  int expanded = 0;
  const dtNavMesh& m = *mesh_.mesh_;
  const dtQueryFilter& filter = *mesh_.filter_;
  while (!open.empty()) {
    std::pop_heap(open.begin(), open.end(), std::greater<>());
    const auto [f, n] = open.back();
    open.pop_back();
    if (f >= goal_cost) break;  // the goal, reached at goal_cost, is the least now
    if (nodes[static_cast<std::size_t>(n)].closed) continue;
    nodes[static_cast<std::size_t>(n)].closed = true;
    if (++expanded > max_nodes_) return 0;
    const CostNode here = nodes[static_cast<std::size_t>(n)];  // nodes may grow below
    if (here.poly == gref) {
      const double c = here.g + dist(here.x, here.z, gx, gz) + step_cost(here.x, here.z, gx, gz);
      if (c < goal_cost) {
        goal_cost = c;
        goal_node = n;
      }
    }
    const dtMeshTile* tile = nullptr;
    const dtPoly* poly = nullptr;
    m.getTileAndPolyByRefUnsafe(here.poly, &tile, &poly);
    for (unsigned int k = poly->firstLink; k != DT_NULL_LINK; k = tile->links[k].next) {
      const dtLink& link = tile->links[k];
      const dtPolyRef next = link.ref;
      if (!next) continue;
      const dtMeshTile* ntile = nullptr;
      const dtPoly* npoly = nullptr;
      m.getTileAndPolyByRefUnsafe(next, &ntile, &npoly);
      // Detour's passFilter, which its library does not export (inline in its source).
      if (!(npoly->flags & filter.getIncludeFlags()) || (npoly->flags & filter.getExcludeFlags()))
        continue;
      // The portal's midpoint, from this link (as portal() finds it).
      float l[3], r[3];
      link_portal(*tile, *poly, link, l, r);
      const double mx = 0.5 * (static_cast<double>(l[0]) + r[0]);
      const double mz = 0.5 * (static_cast<double>(l[2]) + r[2]);
      const double c = here.g + dist(here.x, here.z, mx, mz) + costs.of(next) +
                       step_cost(here.x, here.z, mx, mz);
      const uint64_t key = static_cast<uint64_t>(here.poly) << 32 | next;
      const auto [it, fresh] = index.try_emplace(key, static_cast<int32_t>(nodes.size()));
      if (fresh) {
        nodes.push_back({c, mx, mz, next, n, false});
      } else {
        CostNode& o = nodes[static_cast<std::size_t>(it->second)];
        if (o.closed || c >= o.g) continue;
        o.g = c;
        o.parent = n;
      }
      push(c + dist(mx, mz, gx, gz), it->second);
    }
  }
  if (goal_node < 0) return 0;
  int count = 0;
  for (int32_t n = goal_node; n >= 0; n = nodes[static_cast<std::size_t>(n)].parent) ++count;
  if (count > kMaxPathPolys) return 0;
  int k = count;
  for (int32_t n = goal_node; n >= 0; n = nodes[static_cast<std::size_t>(n)].parent)
    polys_[static_cast<std::size_t>(--k)] = nodes[static_cast<std::size_t>(n)].poly;
  cost = goal_cost;
  return count;
}

// The edge shared by adjacent polygons `from` and `to`: left and right as seen walking from
// `from`; false when they are not adjacent.
bool PathFinder::portal(unsigned int from, unsigned int to, float* left, float* right) const {
  const dtMeshTile* tile = nullptr;
  const dtPoly* poly = nullptr;
  mesh_.mesh_->getTileAndPolyByRefUnsafe(from, &tile, &poly);
  for (unsigned int k = poly->firstLink; k != DT_NULL_LINK; k = tile->links[k].next) {
    const dtLink& link = tile->links[k];
    if (link.ref != to) continue;
    link_portal(*tile, *poly, link, left, right);
    return true;
  }
  return false;
}

// The funnel algorithm (Mononen's "simple stupid funnel", as Detour's findStraightPath runs it)
// over the corridor's portals, each shrunk by `push` from both ends (to its midpoint when it is
// narrower than twice that; by at most push_share of its length): the corners keep `push` from
// the corridor's edges where there is room, and pass through the middle of a narrower gap.
void PathFinder::funnel(PathResult& r, const float* start, const float* end, int npolys,
                        double push) const {
  struct Portal {
    float l[3], rt[3];
  };
  const double share = std::clamp(mesh_.params_.push_share, 0.0, 0.5);
  std::vector<Portal> portals;
  portals.reserve(static_cast<std::size_t>(npolys) + 1);
  Portal first;
  dtVcopy(first.l, start);
  dtVcopy(first.rt, start);
  portals.push_back(first);
  for (int i = 0; i + 1 < npolys; ++i) {
    Portal p;
    if (!portal(polys_[static_cast<std::size_t>(i)], polys_[static_cast<std::size_t>(i + 1)], p.l,
                p.rt))
      break;
    const float dx = p.rt[0] - p.l[0], dz = p.rt[2] - p.l[2];
    const double len = std::sqrt(static_cast<double>(dx) * dx + static_cast<double>(dz) * dz);
    const double t = std::min(len > 2 * push ? push / len : 0.5, share);
    const float l0 = p.l[0], l2 = p.l[2];
    p.l[0] = static_cast<float>(l0 + dx * t);
    p.l[2] = static_cast<float>(l2 + dz * t);
    p.rt[0] = static_cast<float>(l0 + dx * (1 - t));
    p.rt[2] = static_cast<float>(l2 + dz * (1 - t));
    portals.push_back(p);
  }
  Portal last;
  dtVcopy(last.l, end);
  dtVcopy(last.rt, end);
  portals.push_back(last);

  float apex[3], left[3], right[3];
  dtVcopy(apex, start);
  dtVcopy(left, start);
  dtVcopy(right, start);
  std::size_t apex_i = 0, left_i = 0, right_i = 0;
  // The funnel's side `side` (index `side_i`) is crossed: its point is a corner (unless it is
  // the end), the funnel restarts there and the scan resumes after its portal.
  std::size_t i = 1;
  const auto restart_at = [&](const float* side, std::size_t side_i) {
    if (!dtVequal(side, end)) r.corners.push_back(mesh_.world(side));
    dtVcopy(apex, side);
    apex_i = side_i;
    dtVcopy(left, apex);
    dtVcopy(right, apex);
    left_i = right_i = apex_i;
    i = apex_i;
  };
  for (; i < portals.size(); ++i) {
    const float* pl = portals[i].l;
    const float* pr = portals[i].rt;
    if (dtTriArea2D(apex, right, pr) <= 0.0f) {  // the right side narrows the funnel
      if (dtVequal(apex, right) || dtTriArea2D(apex, left, pr) > 0.0f) {
        dtVcopy(right, pr);
        right_i = i;
      } else {  // crosses the left side: the left point is a corner
        restart_at(left, left_i);
        continue;
      }
    }
    if (dtTriArea2D(apex, left, pl) >= 0.0f) {  // the left side narrows the funnel
      if (dtVequal(apex, left) || dtTriArea2D(apex, right, pl) < 0.0f) {
        dtVcopy(left, pl);
        left_i = i;
      } else {  // crosses the right side: the right point is a corner
        restart_at(right, right_i);
        continue;
      }
    }
  }
  // Consecutive corners at the same point (a portal shrunk to its midpoint twice) are one.
  r.corners.erase(
      std::unique(r.corners.begin(), r.corners.end(),
                  [](const Vec2& a, const Vec2& b) { return a.x == b.x && a.y == b.y; }),
      r.corners.end());
}

}  // namespace crowddb::path
