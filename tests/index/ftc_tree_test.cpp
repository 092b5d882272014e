// The first-to-collide index against the naive oracle: same collider and bit-identical time for
// every disc, on random and adversarial tables, with every index option.
#include "index/ftc_tree.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "crowddb/error.hpp"
#include "index/ftc_pair_lanes.hpp"
#include "query/ftc_geometry.hpp"
#include "query/naive_paths.hpp"
#include "scenario/builders.hpp"
#include "support/polygons.hpp"
#include "support/random_tables.hpp"
#include "util/rng.hpp"

namespace crowddb {
namespace {

using Opt = FtcIndexOptions;

std::vector<FtcHit> naive(const DiscView& d, const StaticScene& s, double horizon) {
  FtcNaive path;
  Executor ex(1);
  QueryStats st;
  std::vector<FtcHit> out(d.n);
  path.run(d, s, horizon, out, ex, st);
  return out;
}

// The oracle's answer for the last input seen: the option sweeps below ask for it many times.
const std::vector<FtcHit>& naive_cached(const DiscView& d, const StaticScene& s, double horizon) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* p, std::size_t bytes) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ c[i]) * 1099511628211ull;
  };
  for (const double* col : {d.x, d.y, d.vx, d.vy, d.radius}) mix(col, d.n * sizeof(double));
  mix(d.id, d.n * sizeof(uint64_t));
  mix(&horizon, sizeof horizon);
  for (const auto& c : s.circles()) mix(&c, sizeof c);
  for (const auto& p : s.polygons()) mix(p.vertices.data(), p.vertices.size() * sizeof(Vec2));
  static uint64_t key = 0;
  static std::size_t rows = 0;
  static std::vector<FtcHit> answer;
  if (key != h || rows != d.n || answer.size() != d.n) {
    answer = naive(d, s, horizon);
    key = h;
    rows = d.n;
  }
  return answer;
}

std::string describe(const FtcHit& h) {
  return "kind " + std::to_string(static_cast<int>(h.with.kind)) + " row " +
         std::to_string(h.with.row) + " t " + std::to_string(h.time);
}

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// Index (with `opt`, on `threads` threads, told `no_overlaps`) == naive for every row; returns
// how many rows differ.
int compare(const DiscTable& t, const StaticScene& s, double horizon, Opt opt = {}, int threads = 1,
            QueryStats* stats_out = nullptr, bool no_overlaps = false) {
  const DiscView d = t.view();
  const auto& want = naive_cached(d, s, horizon);
  FtcIndex index(opt);
  index.assume_no_overlaps(no_overlaps);
  Executor ex(threads);
  QueryStats st;
  std::vector<FtcHit> got(d.n);
  index.run(d, s, horizon, got, ex, st);
  EXPECT_EQ(index.validate(), "");
  EXPECT_EQ(st.rows, d.n);
  int bad = 0;
  for (std::size_t i = 0; i < d.n; ++i) {
    if (got[i].with == want[i].with && same_bits(got[i].time, want[i].time)) continue;
    if (++bad <= 5)
      ADD_FAILURE() << "row " << i << " (id " << d.id[i] << "): index " << describe(got[i])
                    << ", naive " << describe(want[i]);
  }
  if (stats_out) *stats_out = st;
  return bad;
}

// Every option combination the index offers.
std::vector<Opt> all_options() {
  std::vector<Opt> v;
  for (auto bound : {Opt::Bound::chord, Opt::Bound::frustum})
    for (auto order : {Opt::Order::bottom_up, Opt::Order::leaf_queue, Opt::Order::nearer_first,
                       Opt::Order::best_first})
      for (int slices : {1, 3})
        for (std::size_t leaf : {1, 8})
          for (bool seed : {true, false}) {
            if (bound == Opt::Bound::frustum && slices != 1) continue;
            if ((order == Opt::Order::bottom_up || order == Opt::Order::leaf_queue) && !seed)
              continue;  // start at the leaf
            Opt o;
            o.bound = bound;
            o.order = order;
            o.slices = slices;
            o.leaf_size = leaf;
            o.seed_own_leaf = seed;
            v.push_back(o);
            if (slices == 1) {  // the overlap phase by the tree search, and none at all
              o.overlap_join = false;
              v.push_back(o);
              o.overlaps_first = false;
              v.push_back(o);
            }
          }
  return v;
}

// A few contrasting option sets, for the larger tables.
std::vector<Opt> some_options() {
  Opt thesis;  // the thesis's search: frustum, best-first from the root, one agent per leaf
  thesis.bound = Opt::Bound::frustum;
  thesis.order = Opt::Order::best_first;
  thesis.leaf_size = 1;
  thesis.seed_own_leaf = false;
  thesis.overlaps_first = false;
  return {Opt{},
          Opt{.bound = Opt::Bound::frustum},
          Opt{.slices = 1, .order = Opt::Order::bottom_up},
          Opt{.leaf_size = 3, .slices = 7, .order = Opt::Order::nearer_first},
          Opt{.slices = 2, .overlap_join = false},
          Opt{.lanes = false},
          thesis};
}

const StaticScene kNoScene;

TEST(FtcIndex, EmptyAndTinyTables) {
  DiscTable t;
  EXPECT_EQ(compare(t, kNoScene, 30), 0);
  t.push_back(7, 0, 0, 1, 0, 1);
  EXPECT_EQ(compare(t, kNoScene, 30), 0);
  t.push_back(3, 10, 0, -1, 0, 1);  // head-on: gap 8, closing speed 2 -> t = 4
  EXPECT_EQ(compare(t, kNoScene, 30), 0);
  FtcIndex index;
  index.build(t.view(), kNoScene, 30);
  const FtcHit h = index.query(0);
  EXPECT_EQ(h.with, (Collider{Collider::Kind::agent, 1}));
  EXPECT_EQ(h.time, 4.0);
  for (const Opt& o : all_options()) EXPECT_EQ(compare(t, kNoScene, 30, o), 0);
}

// Everyone within reach of everyone: the overlap join gives up (its cap) and the tree search
// answers; both must agree with the naive loop, with and without the join.
TEST(FtcIndex, CrowdFallsBackFromTheJoin) {
  const DiscTable t = build::uniform(1500, {0, 0, 4, 4}, 5, 1, 3, 7);
  for (bool join : {true, false}) {
    QueryStats st;
    EXPECT_EQ(compare(t, kNoScene, 30, {.overlap_join = join}, 1, &st), 0) << join;
    // The join would test every pair (n^2 = 2.25e6); the fallback prunes by smallest id.
    EXPECT_LT(st.pair_tests, 1500u * 1499u / 4) << join;
  }
}

// The hint that nothing overlaps (the engine's, after a clean tick) skips the overlaps-first
// pass and builds larger leaves: the naive loop's answers whether it holds or not, and, with the
// leaves kept as they are, less work where it holds.
TEST(FtcIndex, NoOverlapsHintChangesTheCostNotTheAnswers) {
  // Apart: a jittered lattice, 8 m spacing, radii up to 3 m, random velocities.
  Rng rng(5);
  DiscTable apart;
  for (uint64_t i = 0; i < 1600; ++i)
    apart.push_back(i, 8.0 * static_cast<double>(i % 40) + rng.uniform(0, 1),
                    8.0 * static_cast<double>(i / 40) + rng.uniform(0, 1), rng.uniform(-2, 2),
                    rng.uniform(-2, 2), rng.uniform(1, 3));
  const DiscTable dense = build::uniform(2000, {}, 50, 1, 3, 2);  // many overlap
  for (const Opt& o :
       {Opt{}, Opt{.overlap_join = false}, Opt{.lanes = false}, Opt{.leaf_size_apart = 1},
        Opt{.leaf_size_apart = 100}, Opt{.bound = Opt::Bound::frustum, .leaf_size_apart = 7}}) {
    for (const DiscTable* t : std::vector<const DiscTable*>{&apart, &dense}) {
      EXPECT_EQ(compare(*t, kNoScene, 30, o, 1, nullptr, true), 0);
      EXPECT_EQ(compare(*t, kNoScene, 30, o, 2, nullptr, true), 0);
      EXPECT_EQ(compare(*t, kNoScene, 30, o, 1, nullptr, false), 0);
    }
  }
  // Large enough (4,096 members and more) for the tree with the larger leaves to be built on
  // every thread.
  DiscTable many;
  for (uint64_t i = 0; i < 6400; ++i)
    many.push_back(i, 8.0 * static_cast<double>(i % 80) + rng.uniform(0, 1),
                   8.0 * static_cast<double>(i / 80) + rng.uniform(0, 1), rng.uniform(-2, 2),
                   rng.uniform(-2, 2), rng.uniform(1, 3));
  EXPECT_EQ(compare(many, kNoScene, 30, {}, 2, nullptr, true), 0);
  QueryStats told, not_told;
  const Opt same_leaves{.leaf_size_apart = Opt{}.leaf_size};
  EXPECT_EQ(compare(apart, kNoScene, 30, same_leaves, 1, &told, true), 0);
  EXPECT_EQ(compare(apart, kNoScene, 30, same_leaves, 1, &not_told, false), 0);
  EXPECT_LT(told.pair_tests + told.nodes_visited, not_told.pair_tests + not_told.nodes_visited);
  // And the leaves do grow: 1,600 members in leaves of at most 48 rather than 16 (median splits).
  FtcIndex larger, usual;
  larger.assume_no_overlaps(true);
  larger.build(apart.view(), kNoScene, 30);
  usual.build(apart.view(), kNoScene, 30);
  EXPECT_EQ(larger.validate(), "");
  EXPECT_EQ(larger.node_count(), 127u);  // 1,600 halved 6 times: 64 leaves of 25
  EXPECT_EQ(usual.node_count(), 255u);   // 7 times: 128 leaves of 12 or 13
}

TEST(FtcIndex, UniformE1Setup) {
  for (uint64_t seed : {1, 2, 3}) {
    const DiscTable t = build::uniform(2000, {}, 50, 1, 3, seed);
    QueryStats st;
    EXPECT_EQ(compare(t, kNoScene, 30, {}, 1, &st), 0) << "seed " << seed;
    // The index must actually prune: far fewer pair tests than the nested loop's n(n-1).
    EXPECT_LT(st.pair_tests, 2000u * 1999u / 20);
  }
}

TEST(FtcIndex, SparseUniformAndManyOptions) {
  const DiscTable t = build::uniform(600, {0, 0, 3000, 3000}, 5, 0.5, 2, 11);
  for (const Opt& o : all_options()) EXPECT_EQ(compare(t, kNoScene, 40, o), 0);
}

TEST(FtcIndex, Clustered) {
  const DiscTable t = build::clustered(1500, {}, 6, 30, 20, 1, 3, 5);
  for (const Opt& o : all_options()) EXPECT_EQ(compare(t, kNoScene, 30, o), 0);
}

TEST(FtcIndex, LatticeWithExactTies) {
  // Spacing 4, radius 1: neighbours approaching at closing speed 2 meet at exactly t = 1, and
  // many pairs tie in time: the smaller id must win.
  for (uint64_t seed : {1, 2}) {
    DiscTable t = build::lattice(400, 4, 1, 1, seed);
    for (const Opt& o : all_options()) EXPECT_EQ(compare(t, kNoScene, 30, o), 0);
    build::shuffle_ids(t, seed + 10);
    for (const Opt& o : all_options()) EXPECT_EQ(compare(t, kNoScene, 30, o), 0);
  }
  // Touching lattice (spacing = 2 radii): grazing contact is no collision, overlaps are.
  DiscTable touching = build::lattice(400, 2, 0, 1, 3);
  EXPECT_EQ(compare(touching, kNoScene, 30), 0);
  DiscTable overlapping = build::lattice(400, 1.5, 0.5, 1, 3);
  build::shuffle_ids(overlapping, 4);
  for (const Opt& o : all_options()) EXPECT_EQ(compare(overlapping, kNoScene, 30, o), 0);
}

TEST(FtcIndex, DuplicatePositionsAndZeroVelocities) {
  DiscTable t = build::duplicates(500, 37, {}, 10, 1.5, 9);
  build::shuffle_ids(t, 2);
  for (const Opt& o : all_options()) EXPECT_EQ(compare(t, kNoScene, 30, o), 0);
  DiscTable still = build::uniform(800, {}, 0, 1, 3, 4);  // vmax 0: only overlaps at t = 0 count
  for (const Opt& o : all_options()) EXPECT_EQ(compare(still, kNoScene, 30, o), 0);
  // Every disc at one point.
  DiscTable same;
  for (uint64_t i = 0; i < 50; ++i) same.push_back(100 - i, 5, 5, 0, 0, 1);
  EXPECT_EQ(compare(same, kNoScene, 30), 0);
}

TEST(FtcIndex, CoordinatesOffsetByAMillion) {
  for (double off : {1e6, -1e6, 3e7}) {
    DiscTable t = build::uniform(1500, {}, 50, 1, 3, 8);
    build::offset(t, off, -off / 2);
    EXPECT_EQ(compare(t, kNoScene, 30), 0) << off;
    DiscTable l = build::lattice(400, 4, 1, 1, 6);
    build::offset(l, off, off);
    for (const Opt& o : all_options()) EXPECT_EQ(compare(l, kNoScene, 30, o), 0) << off;
  }
}

TEST(FtcIndex, BigCrunchAndPerturbed) {
  for (double perturb : {0.0, 1.0}) {
    for (double arrival : {10.0, 30.0, 45.0}) {
      DiscTable t = build::big_crunch(1200, {}, arrival, 1, 3, perturb, 21);
      build::shuffle_ids(t, 3);
      EXPECT_EQ(compare(t, kNoScene, 30), 0) << perturb << " " << arrival;
      EXPECT_EQ(compare(t, kNoScene, 30, {.bound = Opt::Bound::frustum}), 0)
          << perturb << " " << arrival;
    }
    // Sparse: small discs far apart, so the collision times crowd just before the arrival.
    const DiscTable sparse = build::big_crunch(500, {0, 0, 3000, 2000}, 20, 0.1, 0.3, perturb, 4);
    for (const Opt& o : some_options()) EXPECT_EQ(compare(sparse, kNoScene, 30, o), 0) << perturb;
  }
}

TEST(FtcIndex, HorizonZeroAndInfinite) {
  const DiscTable t = build::uniform(400, {0, 0, 800, 800}, 10, 1, 3, 12);
  for (double h : {-1.0, 0.0, 1e-9, 0.5, 1e6, double{INFINITY}}) {
    FtcIndex probe;
    probe.build(t.view(), kNoScene, h);
    EXPECT_EQ(probe.uses_chord_bound(), h > 0 && std::isfinite(h)) << h;
    for (const Opt& o : all_options()) EXPECT_EQ(compare(t, kNoScene, h, o), 0) << h;
  }
}

StaticScene obstacle_scene(uint64_t seed, std::size_t circles, std::size_t polygons) {
  Rng rng(seed);
  std::vector<CircleObstacle> cs;
  for (std::size_t i = 0; i < circles; ++i)
    cs.push_back({rng.uniform(0, 640), rng.uniform(0, 480), rng.uniform(2, 25), 1});
  std::vector<PolygonObstacle> ps;
  for (std::size_t i = 0; i < polygons; ++i) {
    const double x = rng.uniform(0, 600), y = rng.uniform(0, 440), w = rng.uniform(2, 60),
                 h = rng.uniform(2, 60);
    if (i % 3 == 2)  // a triangle
      ps.push_back({{{x, y}, {x + w, y}, {x + w / 2, y + h}}, 1});
    else
      ps.push_back({{{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, 1});
  }
  return StaticScene(std::move(cs), std::move(ps), 1.0);
}

TEST(FtcIndex, StaticObstacles) {
  for (uint64_t seed : {1, 2, 3}) {
    const StaticScene scene = obstacle_scene(seed, 40, 12);
    const DiscTable t = build::uniform(300, {}, 20, 1, 3, seed);
    for (const Opt& o : all_options()) EXPECT_EQ(compare(t, scene, 30, o), 0) << seed;
    const DiscTable sparse = build::uniform(60, {}, 20, 1, 3, seed + 7);
    EXPECT_EQ(compare(sparse, scene, 30), 0);
  }
  // Obstacles only, no agents.
  EXPECT_EQ(compare(DiscTable{}, obstacle_scene(4, 5, 5), 30), 0);
  // Exact three-way tie at t = 8: an agent, a circle and a polygon. The agent wins; without it the
  // circle wins; without both the polygon.
  const StaticScene both({{10, 0, 1, 1}}, {{{{9, -0.5}, {11, -0.5}, {11, 0.5}, {9, 0.5}}, 1}}, 1.0);
  const StaticScene square({}, {{{{9, -0.5}, {11, -0.5}, {11, 0.5}, {9, 0.5}}, 1}}, 1.0);
  DiscTable t;
  t.push_back(1, 0, 0, 1, 0, 1);
  DiscTable t2 = t;
  t2.push_back(2, 18, 0, -1, 0, 1);
  for (const Opt& o : all_options()) {
    EXPECT_EQ(compare(t, both, 30, o), 0);
    EXPECT_EQ(compare(t2, both, 30, o), 0);
    EXPECT_EQ(compare(t, square, 30, o), 0);
  }
  FtcIndex index;
  index.build(t2.view(), both, 30);
  EXPECT_EQ(index.query(0), (FtcHit{{Collider::Kind::agent, 1}, 8.0}));
  index.build(t.view(), both, 30);
  EXPECT_EQ(index.query(0), (FtcHit{{Collider::Kind::circle, 0}, 8.0}));
  index.build(t.view(), square, 30);
  EXPECT_EQ(index.query(0), (FtcHit{{Collider::Kind::polygon, 0}, 8.0}));
}

// Polygons of many edges (a hall's blocked piece, stars), answered through their edge grids:
// the naive loop's answers under every option set.
TEST(FtcIndex, PolygonsOfManyEdges) {
  Rng rng(5);
  std::vector<PolygonObstacle> polys = {{test::hall_piece(3000, 0, 0, 120), 1}};
  for (int k = 0; k < 4; ++k)
    polys.push_back({test::star(rng, 64 + rng.below(1500), rng.uniform(-60, 60),
                                rng.uniform(-60, 60), 2, rng.uniform(5, 20)),
                     1});
  const StaticScene few({}, polys, 1.0);
  // Many polygons: their boxes in a grid, each query reading those its sweep meets. Boxes of
  // every size, some long enough to be read by every query, inside and beyond the crowd.
  for (int k = 0; k < 400; ++k) {
    const double x = rng.uniform(-200, 200), y = rng.uniform(-200, 200);
    const double w = rng.below(40) == 0 ? rng.uniform(50, 300) : rng.uniform(0.5, 4);
    const double h = rng.below(40) == 0 ? rng.uniform(50, 300) : rng.uniform(0.5, 4);
    polys.push_back({{{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, 1});
  }
  const Bounds bounds{-210, -210, 210, 210};
  const StaticScene many({}, polys, 1.0, ObstacleCharges::boundary, &bounds);
  for (const StaticScene* scene : {&few, &many})
    for (uint64_t seed : {1, 2}) {
      const DiscTable t = build::uniform(400, build::Box{-130, -130, 130, 130}, 3, 0.5, 2, seed);
      for (const Opt& o : some_options()) EXPECT_EQ(compare(t, *scene, 30, o), 0) << seed;
      EXPECT_EQ(compare(t, *scene, INFINITY), 0) << seed;
      EXPECT_EQ(compare(t, *scene, 1), 0) << seed;
      EXPECT_EQ(compare(t, *scene, 0), 0) << seed;
    }
}

// One index over scenes of many polygons in turn: the grid over their boxes is the scene's, not
// the last one's.
TEST(FtcIndex, PolygonGridFollowsTheScene) {
  Rng rng(8);
  auto boxes = [&](int n, double size) {
    std::vector<PolygonObstacle> polys;
    for (int k = 0; k < n; ++k) {
      const double x = rng.uniform(-100, 100), y = rng.uniform(-100, 100);
      polys.push_back({{{x, y}, {x + size, y}, {x + size, y + size}, {x, y + size}}, 1});
    }
    return polys;
  };
  const StaticScene a({}, boxes(300, 2), 1.0), b({}, boxes(40, 8), 1.0);
  const DiscTable t = build::uniform(500, build::Box{-100, -100, 100, 100}, 3, 0.3, 1, 4);
  const DiscView d = t.view();
  FtcIndex index;
  Executor ex(1);
  for (const StaticScene* s : {&a, &b, &a, &b}) {
    QueryStats st;
    std::vector<FtcHit> got(d.n);
    index.run(d, *s, 30, got, ex, st);
    EXPECT_EQ(got, naive(d, *s, 30));
  }
}

// Exactly grazing and nearly grazing pairs, where the pair time is most sensitive to rounding.
TEST(FtcIndex, GrazingPairs) {
  Rng rng(77);
  for (double off : {0.0, 1e6}) {
    DiscTable t;
    for (uint64_t i = 0; i < 400; ++i) {
      const double x = off + rng.uniform(0, 200), y = off + rng.uniform(0, 200);
      // A partner passing at closest distance R (1 + e) with e tiny, either side.
      const double e = (rng.uniform() - 0.5) * 1e-12 * static_cast<double>(i % 7);
      const double r = rng.uniform(0.5, 2);
      t.push_back(2 * i, x, y, 1, 0, r);
      t.push_back(2 * i + 1, x + 20, y + 2 * r * (1 + e), -1, 0, r);
    }
    EXPECT_EQ(compare(t, kNoScene, 30), 0);
    EXPECT_EQ(compare(t, kNoScene, 30, {.bound = Opt::Bound::frustum}), 0);
  }
}

TEST(FtcIndex, SameAnswerOnAnyThreadCount) {
  const DiscTable t = build::uniform(3000, {}, 50, 1, 3, 31);
  QueryStats s1, s3;
  EXPECT_EQ(compare(t, kNoScene, 30, {}, 1, &s1), 0);
  EXPECT_EQ(compare(t, kNoScene, 30, {}, 3, &s3), 0);
  EXPECT_EQ(s1.nodes_visited, s3.nodes_visited);
  EXPECT_EQ(s1.queue_pops, s3.queue_pops);
}

// From 4,096 members the tree's subtrees are built on every thread below its top levels, into
// node numbers fixed in advance: the tree must be the one a single thread builds, node for node.
// So every query visits the same nodes and tests the same pairs, and the answers are the naive
// loop's. Uniform and lattice (ties in x and y at every median) tables, of sizes whose two
// halves hold different numbers of nodes (16 * 2^k members and one more: 17 members make 5
// nodes where 16 make 3). The index is then rebuilt, serially, over another table and horizon:
// what it keeps from build to build must not leak into the next tree.
TEST(FtcIndex, TreeBuiltOnThreadsIsTheSame) {
  const DiscTable uniform = build::uniform(16'385, {}, 50, 1, 3, 8);
  const DiscTable lattice = build::lattice(8'193, 2.0, 1, 0.5, 3);
  for (const DiscTable* t : {&uniform, &lattice}) {
    FtcIndex one;
    one.build(t->view(), kNoScene, 30);
    for (int threads : {2, 3, 4}) {
      Executor ex(threads);
      FtcIndex many;
      many.build(t->view(), kNoScene, 30, &ex);
      ASSERT_EQ(many.validate(), "");
      int differ = 0;
      for (std::size_t i = 0; i < t->size(); ++i) {
        QueryStats a, b;
        const FtcHit ha = one.query(i, &a), hb = many.query(i, &b);
        differ += !(ha.with == hb.with && same_bits(ha.time, hb.time) &&
                    a.nodes_visited == b.nodes_visited && a.pair_tests == b.pair_tests &&
                    a.queue_pushes == b.queue_pushes);
      }
      EXPECT_EQ(differ, 0) << t->size() << " members, " << threads << " threads";
      if (threads == 4) {
        const DiscTable other = build::uniform(5'000, {}, 50, 1, 3, 10);
        FtcIndex fresh;
        fresh.build(other.view(), kNoScene, 12);
        many.build(other.view(), kNoScene, 12);
        ASSERT_EQ(many.validate(), "");
        for (std::size_t i = 0; i < other.size(); i += 7) {
          QueryStats a, b;
          const FtcHit ha = fresh.query(i, &a), hb = many.query(i, &b);
          ASSERT_TRUE(ha.with == hb.with && same_bits(ha.time, hb.time) &&
                      a.nodes_visited == b.nodes_visited)
              << "rebuilt, row " << i;
        }
      }
    }
  }
  EXPECT_EQ(compare(build::uniform(5'000, {}, 50, 1, 3, 9), kNoScene, 30, {}, 2), 0);
}

TEST(FtcIndex, StatisticsAddUp) {
  const DiscTable t = build::uniform(1000, {}, 50, 1, 3, 2);
  FtcIndex index;
  index.build(t.view(), kNoScene, 30);
  QueryStats one;
  for (std::size_t i = 0; i < t.size(); ++i) index.query(i, &one);
  QueryStats all;
  Executor ex(1);
  std::vector<FtcHit> out(t.size());
  index.query_all(out, ex, all);
  EXPECT_EQ(one.rows, all.rows);
  EXPECT_EQ(one.nodes_visited, all.nodes_visited);
  EXPECT_EQ(one.queue_pushes, all.queue_pushes);
  EXPECT_EQ(one.queue_pops, all.queue_pops);
  EXPECT_EQ(one.pair_tests, all.pair_tests);
  EXPECT_GT(all.nodes_visited, 0u);
  EXPECT_LE(all.queue_pops, all.queue_pushes);
  // Best-first sends every visited node through the queue (the join's walk does not use it).
  FtcIndex bf({.order = Opt::Order::best_first, .overlap_join = false});
  bf.build(t.view(), kNoScene, 30);
  QueryStats b;
  bf.query_all(out, ex, b);
  EXPECT_GE(b.queue_pops, b.nodes_visited - b.rows);  // minus the seeded own leaves
}

TEST(FtcIndex, RejectsNonFiniteRows) {
  DiscTable t = build::uniform(10, {}, 5, 1, 2, 1);
  t.vy[4] = NAN;
  FtcIndex index;
  try {
    index.build(t.view(), kNoScene, 30);
    ADD_FAILURE() << "no error";
  } catch (const InvalidRow& e) {
    EXPECT_EQ(e.field(), "vy");
    EXPECT_NE(std::string(e.what()).find("row 4"), std::string::npos) << e.what();
  }
}

// The bounds computed two edges at a time and the leaves' pair times computed several at a time
// are the scalar ones bit for bit: the same answers and the same search (every counter equal), on
// tables that reach every branch of the bound (near, far, approaching, leaving, static boxes) and
// of the pair time (overlapping, receding, missing, hitting, beyond the horizon), with both bound
// kinds, several slice counts and leaves of 1-64 members.
TEST(FtcIndex, LanesAreTheScalarReferenceBitForBit) {
  std::vector<std::pair<DiscTable, StaticScene>> cases;
  cases.emplace_back(build::uniform(3000, {}, 50, 1, 3, 5), StaticScene{});
  cases.emplace_back(build::uniform(2000, {0, 0, 4000, 3000}, 20, 0.2, 0.5, 6), StaticScene{});
  cases.emplace_back(build::big_crunch(1500, {}, 30, 1, 3, 1, 7), StaticScene{});
  cases.emplace_back(build::uniform(1500, {}, 50, 1, 3, 8), obstacle_scene(8, 30, 10));
  Rng rng(4242);
  cases.emplace_back(test::random_shape_table(rng, 800, 300, 9), obstacle_scene(9, 5, 3));
  // Points among discs: a row of radius 0 never collides with itself, so its own leaf may be
  // passed over by the leaf scan's shortcut like any other (the counts must still agree).
  DiscTable points = build::uniform(1200, {0, 0, 300, 300}, 20, 0.5, 2, 10);
  for (std::size_t i = 0; i < points.size(); i += 3) points.radius[i] = 0;
  cases.emplace_back(std::move(points), StaticScene{});
  int compared = 0;
  for (const auto& [t, scene] : cases)
    for (const double horizon : {0.5, 30.0, double{INFINITY}})
      for (Opt o : {Opt{}, Opt{.slices = 1}, Opt{.leaf_size = 3, .slices = 7},
                    Opt{.leaf_size = 64, .bound = Opt::Bound::frustum},
                    Opt{.order = Opt::Order::best_first, .overlaps_first = false}}) {
        const bool hint = compared % 2 == 1;  // told that nothing overlaps, every other time
        QueryStats lanes, scalar;
        EXPECT_EQ(compare(t, scene, horizon, o, 1, &lanes, hint), 0);
        o.lanes = false;
        EXPECT_EQ(compare(t, scene, horizon, o, 1, &scalar, hint), 0);
        EXPECT_EQ(lanes.nodes_visited, scalar.nodes_visited) << compared;
        EXPECT_EQ(lanes.queue_pushes, scalar.queue_pushes) << compared;
        EXPECT_EQ(lanes.queue_pops, scalar.queue_pops) << compared;
        EXPECT_EQ(lanes.pair_tests, scalar.pair_tests) << compared;
        ++compared;
      }
  EXPECT_EQ(compared, 90);
}

// The pair times in lanes, the widest (AVX2 where the CPU has it) and the build's own, are
// ray_disc_time's bit for bit: overlapping, approaching, receding, grazing and resting pairs,
// near the origin and 10^6 m from it, leaves of 0 to 70 members (whole vectors and tails).
TEST(FtcIndex, PairTimesInLanesAreRayDiscTimeBitForBit) {
#if CROWDDB_TEST_AVX2_DISPATCH && !defined(__AVX2__)
  // The AVX2 copy is in the build (whose own lanes are narrower): it must be the one taken
  // where the CPU has AVX2.
  EXPECT_EQ(ftc::pair_times_avx2(), __builtin_cpu_supports("avx2") != 0);
#endif
  Rng rng(2024);
  if (!ftc::pair_times_avx2()) GTEST_LOG_(INFO) << "no AVX2 lanes here: both are the build's";
  for (int round = 0; round < 400; ++round) {
    const double off = round % 2 ? 1e6 : 0;
    const ftc::Query q{off + rng.uniform(-5, 5), off + rng.uniform(-5, 5), rng.uniform(-3, 3),
                       rng.uniform(-3, 3), rng.uniform(0.2, 2)};
    const auto n = static_cast<uint32_t>(rng.below(71));
    std::vector<ftc::Member> m(n);
    for (uint32_t k = 0; k < n; ++k) {
      ftc::Member& u = m[k];
      u = {off + rng.uniform(-20, 20),
           off + rng.uniform(-20, 20),
           rng.uniform(-3, 3),
           rng.uniform(-3, 3),
           rng.uniform(0.2, 2),
           k,
           k};
      switch (rng.below(5)) {
        case 0:  // resting relative to the query
          u.vx = q.vx;
          u.vy = q.vy;
          break;
        case 1:  // grazing: passing at exactly the radii's sum, head-on along x
          u.y = q.y + (q.r + u.r);
          u.vy = q.vy;
          break;
        case 2:  // on the query's centre
          u.x = q.x;
          u.y = q.y;
          break;
        default:
          break;
      }
    }
    // Column by column, as a tree keeps them (each column a vector of its own, so reading past
    // the n-th value is the sanitizers' to catch).
    std::vector<double> xs(n), ys(n), vxs(n), vys(n), rs(n);
    for (uint32_t k = 0; k < n; ++k) {
      xs[k] = m[k].x;
      ys[k] = m[k].y;
      vxs[k] = m[k].vx;
      vys[k] = m[k].vy;
      rs[k] = m[k].r;
    }
    const ftc::Columns columns{xs.data(), ys.data(), vxs.data(), vys.data(), rs.data()};
    const double horizon = round % 3 ? 30 : INFINITY;
    for (ftc::Lanes lanes : {ftc::Lanes::widest, ftc::Lanes::build}) {
      std::vector<double> got(n);
      const double earliest = ftc::pair_times(columns, n, q, horizon, got.data(), lanes);
      double want_earliest = INFINITY;
      for (uint32_t k = 0; k < n; ++k) {
        const ftc::Member& u = m[k];
        const double want =
            ray_disc_time(u.x - q.x, u.y - q.y, u.vx - q.vx, u.vy - q.vy, q.r + u.r, horizon);
        ASSERT_TRUE(same_bits(got[k], want))
            << "round " << round << " member " << k << " lanes " << static_cast<int>(lanes) << ": "
            << got[k] << " against " << want;
        want_earliest = std::min(want_earliest, want);
      }
      EXPECT_EQ(earliest, want_earliest) << "round " << round;
    }
  }
}

// One step of the refit tests' crowd: everyone walks a tenth of a tick, a fifth turn, one in a
// hundred jumps across the 160 x 160 world.
void walk(DiscTable& t, Rng& rng) {
  for (std::size_t i = 0; i < t.size(); ++i) {
    t.x[i] += 0.1 * t.vx[i];
    t.y[i] += 0.1 * t.vy[i];
    if (rng.below(5) == 0) {
      t.vx[i] = rng.uniform(-3, 3);
      t.vy[i] = rng.uniform(-3, 3);
    }
    if (rng.below(100) == 0) {
      t.x[i] = rng.uniform(0, 160);
      t.y[i] = rng.uniform(0, 160);
    }
  }
}

// Answers that must agree row for row, bit for bit: the first five differences are reported
// (`a` and `b` name the two sides).
void expect_same_hits(const std::vector<FtcHit>& got, const std::vector<FtcHit>& want,
                      const char* a, const char* b) {
  int bad = 0;
  for (std::size_t i = 0; i < got.size(); ++i)
    if (!(got[i].with == want[i].with && same_bits(got[i].time, want[i].time)) && ++bad <= 5)
      ADD_FAILURE() << "row " << i << ": " << a << " " << describe(got[i]) << ", " << b << " "
                    << describe(want[i]);
}

// One index run tick after tick over a table that changes in between: its discs walk and turn,
// some jump far (off their cells: the walk's stop allows for the drift), all of them shift by a
// kilometre (the build's origin is kept), a row is replaced by another id or removed (a build
// then), the no-overlap hint comes and goes (another leaf size: a build). Refitted or built, on
// one thread or two (the refit in chunks of leaves from 4,096 members), every run answers as the
// naive loop, and the refitted tree validates.
TEST(FtcIndex, RefittedTreeAnswersAsTheNaiveLoop) {
  const StaticScene scene = obstacle_scene(9, 30, 8);
  for (int threads : {1, 2}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    Rng rng(40 + static_cast<uint64_t>(threads));
    DiscTable t = build::uniform(threads == 1 ? 900 : 4200, {0, 0, 160, 160}, 3, 0.2, 0.6,
                                 static_cast<uint64_t>(threads));
    FtcIndex index({.rebuild_every = 7});
    Executor ex(threads);
    int refits = 0;
    for (int step = 0; step < 30; ++step) {
      SCOPED_TRACE("step " + std::to_string(step));
      walk(t, rng);
      if (step == 11)
        for (std::size_t i = 0; i < t.size(); ++i) {
          t.x[i] += 1000;
          t.y[i] -= 700;
        }
      if (step == 17) t.id[t.size() / 2] = 1'000'000;  // another row in that place
      if (step == 23) {                                // one row fewer
        for (auto* col : {&t.x, &t.y, &t.vx, &t.vy, &t.radius, &t.charge}) col->pop_back();
        t.id.pop_back();
      }
      index.assume_no_overlaps(step >= 5 && step < 20);
      const DiscView d = t.view();
      std::vector<FtcHit> got(d.n);
      QueryStats st;
      index.run(d, scene, 30, got, ex, st);
      refits += index.refitted();
      if (step == 0 || step == 5 || step == 17 || step == 20 || step == 23) {
        EXPECT_FALSE(index.refitted());
      }
      EXPECT_EQ(index.validate(), "");
      // (The naive loop over 4,200 discs is the test's cost: every third step, and the steps
      // that change the table, on two threads.)
      if (threads == 2 && step % 3 != 0 && step != 12 && step != 17 && step != 23) continue;
      expect_same_hits(got, naive(d, scene, 30), "index", "naive");
    }
    EXPECT_GE(refits, 15);
  }
}

// The refit under the other bounds and search orders, and under a new horizon: with as many
// knots the tree is refitted (its bounds recomputed for the new times), and answers as the naive
// loop; the thesis's frustum bound, bottom-up search and single-member leaves included.
TEST(FtcIndex, RefitKeepsEveryBoundAndOrderExactAcrossHorizons) {
  const StaticScene scene = obstacle_scene(3, 12, 4);
  Opt frustum{.leaf_size = 8,
              .bound = Opt::Bound::frustum,
              .slices = 1,
              .order = Opt::Order::best_first,
              .seed_own_leaf = false};
  Opt sliced{
      .leaf_size = 8, .bound = Opt::Bound::chord, .slices = 3, .order = Opt::Order::bottom_up};
  Opt single{
      .leaf_size = 1, .bound = Opt::Bound::chord, .slices = 1, .order = Opt::Order::nearer_first};
  for (Opt o : {frustum, sliced, single}) {
    SCOPED_TRACE("bound " + std::to_string(static_cast<int>(o.bound)) + " order " +
                 std::to_string(static_cast<int>(o.order)) + " leaf " +
                 std::to_string(o.leaf_size));
    o.rebuild_every = 6;
    Rng rng(77);
    DiscTable t = build::uniform(600, {0, 0, 160, 160}, 3, 0.2, 0.6, 9);
    FtcIndex index(o);
    Executor ex(1);
    int refits = 0;
    for (int step = 0; step < 14; ++step) {
      SCOPED_TRACE("step " + std::to_string(step));
      walk(t, rng);
      // A shorter horizon at step 3, the first one back at step 4, an unbounded one at 9-10.
      const double horizon = step == 3 ? 12.5 : step == 9 || step == 10 ? INFINITY : 30;
      const DiscView d = t.view();
      std::vector<FtcHit> got(d.n);
      QueryStats st;
      index.run(d, scene, horizon, got, ex, st);
      refits += index.refitted();
      if (step == 3 || step == 4) {
        EXPECT_TRUE(index.refitted());  // a new horizon, as many knots
      }
      EXPECT_EQ(index.validate(), "");
      expect_same_hits(got, naive(d, scene, horizon), "index", "naive");
    }
    EXPECT_GE(refits, 8);
  }
}

// The refit in parallel chunks of leaves makes the tree one thread makes: two indices over the
// same moving crowd, one on one thread and one on two, give the same answers bit for bit and
// the same search counters (nodes opened, pair tests, queue traffic) at every step.
TEST(FtcIndex, ParallelRefitBuildsTheTreeOfOneThread) {
  const StaticScene scene = obstacle_scene(5, 20, 6);
  Rng rng(91);
  DiscTable t = build::uniform(6000, {0, 0, 160, 160}, 3, 0.2, 0.6, 12);
  FtcIndex one({.rebuild_every = 8}), two({.rebuild_every = 8});
  Executor ex1(1), ex2(2);
  int refits = 0;
  for (int step = 0; step < 20; ++step) {
    SCOPED_TRACE("step " + std::to_string(step));
    walk(t, rng);
    one.assume_no_overlaps(step >= 10);
    two.assume_no_overlaps(step >= 10);
    const DiscView d = t.view();
    std::vector<FtcHit> a(d.n), b(d.n);
    QueryStats sa, sb;
    one.run(d, scene, 30, a, ex1, sa);
    two.run(d, scene, 30, b, ex2, sb);
    ASSERT_EQ(one.refitted(), two.refitted());
    refits += two.refitted();
    EXPECT_EQ(sa.nodes_visited, sb.nodes_visited);
    EXPECT_EQ(sa.pair_tests, sb.pair_tests);
    EXPECT_EQ(sa.queue_pushes, sb.queue_pushes);
    EXPECT_EQ(sa.queue_pops, sb.queue_pops);
    expect_same_hits(a, b, "one thread", "two");
  }
  EXPECT_GE(refits, 12);
}

// Random tables of every shape, random options, told or not that nothing overlaps (a hint that
// may be wrong: it changes the cost only): the property test.
TEST(FtcIndex, PropertyManySeeds) {
  const auto options = all_options();
  int failures = 0;
  for (uint64_t seed = 0; seed < 150 && failures == 0; ++seed) {
    Rng rng(seed * 7919 + 1);
    const std::size_t n = rng.below(300);
    const double side = rng.uniform(5, 1000);
    DiscTable t = test::random_shape_table(rng, n, side, seed);
    if (rng.below(4) == 0) build::offset(t, 1e6, -1e6);
    const double horizon = rng.below(8) == 0 ? INFINITY : rng.uniform(0, 50);
    const StaticScene scene =
        rng.below(3) == 0 ? obstacle_scene(seed, rng.below(10), rng.below(4)) : StaticScene{};
    const Opt& o = options[rng.below(options.size())];
    failures += compare(t, scene, horizon, o, 1 + static_cast<int>(rng.below(2)), nullptr,
                        rng.below(2) == 0);
    if (failures) ADD_FAILURE() << "seed " << seed;
  }
}

}  // namespace
}  // namespace crowddb
