// The potential-field aggregate index against the naive nested loop (DESIGN.md §4 tolerance):
// |S_idx - S_naive| <= 1e-9 S_abs + 1e-12 A c_max^2 per potential, times k per gradient
// component, on uniform, clustered, lattice (ties), duplicate, far-offset and 10^6 x 10^6
// tables, tiny and empty tables, with obstacle charged points, across seeds.
#include "index/field_index.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "crowddb/query.hpp"
#include "plan/access_path.hpp"
#include "query/field_kernels.hpp"
#include "scenario/builders.hpp"
#include "util/rng.hpp"

namespace crowddb {
namespace {

PotentialSpec exp_spec(Metric metric, double k = 0.272194, int frames = 2) {
  PotentialSpec s;
  s.kernel = Kernel::exp;
  s.metric = metric;
  s.k = k;
  s.radial_frames = frames;
  return s;
}

const char* metric_name(const PotentialSpec& s) {
  return s.metric == Metric::l1 ? "l1" : (s.radial_frames == 1 ? "radial1" : "radial2");
}

// Sum of |A c_p c_q K(d)| over the terms of each probe: the S_abs of the tolerance.
std::vector<double> abs_sums(const DiscView& d, const StaticScene& scene, const PotentialSpec& spec,
                             std::span<const Vec2> probes = {}) {
  const PairKernel kernel(spec);
  const bool at_probes = !probes.empty();
  const std::size_t n = at_probes ? probes.size() : d.n;
  std::vector<double> out(n);
  for (std::size_t p = 0; p < n; ++p) {
    const double px = at_probes ? probes[p].x : d.x[p], py = at_probes ? probes[p].y : d.y[p];
    const double cp = at_probes ? 1.0 : std::abs(d.charge[p]);
    double pot = 0, gx = 0, gy = 0;
    for (std::size_t q = 0; q < d.n; ++q)
      if (at_probes || q != p)
        kernel.add(px - d.x[q], py - d.y[q], std::abs(spec.A * cp * d.charge[q]), pot, gx, gy);
    const auto sx = scene.point_x(), sy = scene.point_y(), sc = scene.point_charge();
    for (std::size_t q = 0; q < sx.size(); ++q)
      kernel.add(px - sx[q], py - sy[q], std::abs(spec.A * cp * sc[q]), pot, gx, gy);
    out[p] = pot;
  }
  return out;
}

double max_charge(const DiscView& d, const StaticScene& scene, bool unit_probe) {
  double c = unit_probe ? 1.0 : 0.0;
  for (std::size_t i = 0; i < d.n; ++i) c = std::max(c, std::abs(d.charge[i]));
  for (double q : scene.point_charge()) c = std::max(c, std::abs(q));
  return c;
}

// Compares two field columns under the DESIGN.md tolerance; returns the number of violations and
// reports the first few. `grad_scale` multiplies the gradient tolerance (1 for analytic
// gradients, 1/h for finite differences).
int compare(const FieldColumns& idx, const FieldColumns& naive, const std::vector<double>& sabs,
            double A, double cmax, double k, const std::string& what, double grad_scale = 1.0) {
  int bad = 0;
  for (std::size_t i = 0; i < naive.potential.size(); ++i) {
    const double tol = 1e-9 * sabs[i] + 1e-12 * std::abs(A) * cmax * cmax;
    const double gtol = std::max(k, 1e-300) * tol * grad_scale;
    const double ep = std::abs(idx.potential[i] - naive.potential[i]);
    const double ex = std::abs(idx.grad_x[i] - naive.grad_x[i]);
    const double ey = std::abs(idx.grad_y[i] - naive.grad_y[i]);
    if (!(ep <= tol) || !(ex <= gtol) || !(ey <= gtol)) {
      if (++bad <= 3)
        ADD_FAILURE() << what << " row " << i << ": potential " << idx.potential[i] << " vs "
                      << naive.potential[i] << ", grad (" << idx.grad_x[i] << ", " << idx.grad_y[i]
                      << ") vs (" << naive.grad_x[i] << ", " << naive.grad_y[i] << "), S_abs "
                      << sabs[i] << ", tol " << tol;
    }
  }
  return bad;
}

void check_table(const DiscTable& t, const StaticScene& scene, const PotentialSpec& spec,
                 const std::string& what) {
  const DiscView d = t.view();
  const FieldColumns naive = potential_field(d, scene, spec, "naive");
  const FieldColumns idx = potential_field(d, scene, spec, "index");
  ASSERT_EQ(idx.potential.size(), d.n);
  const auto sabs = abs_sums(d, scene, spec);
  EXPECT_EQ(compare(idx, naive, sabs, spec.A, max_charge(d, scene, false), spec.k,
                    what + " " + metric_name(spec)),
            0);
}

void check_all_metrics(const DiscTable& t, const StaticScene& scene, const std::string& what,
                       double k = 0.272194) {
  for (const PotentialSpec& s :
       {exp_spec(Metric::l1, k), exp_spec(Metric::radial, k, 2), exp_spec(Metric::radial, k, 1)})
    check_table(t, scene, s, what);
}

void random_charges(DiscTable& t, uint64_t seed, bool mixed_sign = false) {
  Rng rng(seed);
  for (double& c : t.charge)
    c = rng.uniform() < 0.1 ? 0.0 : rng.uniform(mixed_sign ? -2.0 : 0.0, 3.0);
}

StaticScene obstacles(uint64_t seed, build::Box box, int circles, int polygons,
                      double spacing = 1.0) {
  Rng rng(seed);
  std::vector<CircleObstacle> cs;
  for (int i = 0; i < circles; ++i)
    cs.push_back({rng.uniform(box.xmin, box.xmax), rng.uniform(box.ymin, box.ymax),
                  rng.uniform(2, 8), rng.uniform(0.5, 2)});
  std::vector<PolygonObstacle> ps;
  for (int i = 0; i < polygons; ++i) {
    const double x = rng.uniform(box.xmin, box.xmax), y = rng.uniform(box.ymin, box.ymax);
    const double w = rng.uniform(3, 12), h = rng.uniform(3, 12);
    ps.push_back({{{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, rng.uniform(0.5, 2)});
  }
  return StaticScene(std::move(cs), std::move(ps), spacing);
}

TEST(FieldIndex, SupportsOnlySeparableExponentials) {
  EXPECT_TRUE(field_index_supports(exp_spec(Metric::l1)));
  EXPECT_TRUE(field_index_supports(exp_spec(Metric::radial, 0.3, 1)));
  EXPECT_TRUE(field_index_supports(exp_spec(Metric::radial, 0.3, 2)));
  EXPECT_FALSE(field_index_supports(exp_spec(Metric::radial, 0.3, 3)));
  EXPECT_FALSE(field_index_supports(exp_spec(Metric::l2)));
  PotentialSpec inv = exp_spec(Metric::l1);
  inv.kernel = Kernel::inv;
  EXPECT_FALSE(field_index_supports(inv));
  EXPECT_FALSE(field_index_supports(exp_spec(Metric::l1, -0.1)));
  EXPECT_FALSE(field_index_supports(exp_spec(Metric::l1, INFINITY)));
  EXPECT_THROW(potential_field(DiscView{}, StaticScene{}, exp_spec(Metric::l2), "index"), Error);
}

TEST(FieldIndex, TwoAgentsByHand) {
  DiscTable t;
  t.push_back(1, 0, 0, 0, 0, 1);
  t.push_back(2, 3, 4, 0, 0, 1);
  PotentialSpec s = exp_spec(Metric::l1, 1.0);
  s.A = 1;
  const FieldColumns f = potential_field(t.view(), StaticScene{}, s, "index");
  const double e = std::exp(-7.0);
  EXPECT_NEAR(f.potential[0], e, 1e-15);
  EXPECT_NEAR(f.grad_x[0], e, 1e-15);  // d/dx_p of e^{-(|0-3| + |0-4|)} = +e
  EXPECT_NEAR(f.grad_y[0], e, 1e-15);
  EXPECT_NEAR(f.potential[1], e, 1e-15);
  EXPECT_NEAR(f.grad_x[1], -e, 1e-15);
  EXPECT_NEAR(f.grad_y[1], -e, 1e-15);
}

TEST(FieldIndex, EmptyAndTinyTables) {
  for (const PotentialSpec& s : {exp_spec(Metric::l1), exp_spec(Metric::radial)}) {
    EXPECT_TRUE(potential_field(DiscView{}, StaticScene{}, s, "index").potential.empty());
    DiscTable one;
    one.push_back(0, 5, 5, 0, 0, 1);
    const FieldColumns f1 = potential_field(one.view(), StaticScene{}, s, "index");
    EXPECT_EQ(f1.potential, std::vector<double>{0.0});  // alone: nothing but itself, excluded
    check_table(one, obstacles(3, {0, 0, 10, 10}, 2, 1), s, "one agent with obstacles");
    DiscTable two;  // coincident distinct agents: each sees the other's e^0, gradient 0
    two.push_back(0, 5, 5, 0, 0, 1, 2.0);
    two.push_back(1, 5, 5, 0, 0, 1, 3.0);
    const FieldColumns f2 = potential_field(two.view(), StaticScene{}, s, "index");
    EXPECT_DOUBLE_EQ(f2.potential[0], s.A * 6.0);
    EXPECT_DOUBLE_EQ(f2.potential[1], s.A * 6.0);
    EXPECT_EQ(f2.grad_x[0], 0.0);
    EXPECT_EQ(f2.grad_y[1], 0.0);
    check_table(two, StaticScene{}, s, "two coincident");
    DiscTable pile;  // 40 agents on one spot plus one next to it
    for (int i = 0; i < 40; ++i) pile.push_back(i, 1e6, -1e6, 0, 0, 1, 1 + i % 3);
    pile.push_back(40, 1e6 + 1, -1e6, 0, 0, 1);
    check_table(pile, StaticScene{}, s, "pile");
  }
}

TEST(FieldIndex, UniformAcrossSeeds) {
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    DiscTable t = build::uniform(300 + 37 * seed, {0, 0, 200, 150}, 5, 1, 3, seed);
    if (seed % 2) random_charges(t, seed);
    const StaticScene scene = obstacles(seed, {0, 0, 200, 150}, 3, 2);
    check_all_metrics(t, scene, "uniform seed " + std::to_string(seed));
  }
}

TEST(FieldIndex, MixedSignCharges) {
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    DiscTable t = build::uniform(400, {0, 0, 60, 60}, 5, 1, 3, seed);
    random_charges(t, seed, true);
    check_all_metrics(t, StaticScene{}, "mixed signs seed " + std::to_string(seed));
  }
}

TEST(FieldIndex, ClusteredAcrossSeeds) {
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    DiscTable t = build::clustered(600, {0, 0, 640, 480}, 5, 8, 5, 1, 3, seed);
    const StaticScene scene = obstacles(seed + 100, {0, 0, 640, 480}, 4, 0);
    check_all_metrics(t, scene, "clustered seed " + std::to_string(seed));
  }
}

TEST(FieldIndex, LatticeTiesOnAxesAndDiagonals) {
  for (double spacing : {1.0, 0.5, 2.0, 3.0}) {
    DiscTable t = build::lattice(400, spacing, 1, 0.4, 7);
    random_charges(t, 11);
    check_all_metrics(t, StaticScene{}, "lattice spacing " + std::to_string(spacing), 1.0);
    check_all_metrics(t, StaticScene{}, "lattice spacing " + std::to_string(spacing));
  }
  // Lattice plus obstacle points that sit on lattice nodes and on the diagonals through them.
  DiscTable t = build::lattice(225, 1.0, 1, 0.4, 3);
  std::vector<CircleObstacle> circles = {{3, 3, 0.5, 2}, {7, 1, 0.5, 1}, {2.5, 4.5, 0.5, 1}};
  const StaticScene scene(std::move(circles), {}, 1.0, ObstacleCharges::centres);
  check_all_metrics(t, scene, "lattice + centres", 0.7);
}

TEST(FieldIndex, DuplicatePositions) {
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    DiscTable t = build::duplicates(500, 5 + seed * 7, {0, 0, 50, 50}, 2, 1, seed);
    random_charges(t, seed);
    build::shuffle_ids(t, seed);
    check_all_metrics(t, StaticScene{}, "duplicates seed " + std::to_string(seed));
  }
}

TEST(FieldIndex, FarOffsetCoordinates) {
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    DiscTable u = build::uniform(400, {0, 0, 100, 100}, 5, 1, 3, seed);
    build::offset(u, 1e6, -1e6);
    check_all_metrics(u, StaticScene{}, "uniform offset 1e6 seed " + std::to_string(seed));
    DiscTable l = build::lattice(300, 1.0, 1, 0.4, seed);
    build::offset(l, 1e6 + 0.5, 1e6);
    check_all_metrics(l, StaticScene{}, "lattice offset 1e6 seed " + std::to_string(seed), 1.0);
    DiscTable c = build::clustered(400, {-1e6, -1e6, -1e6 + 300, -1e6 + 300}, 4, 6, 5, 1, 3, seed);
    const StaticScene scene = obstacles(seed, {-1e6, -1e6, -1e6 + 300, -1e6 + 300}, 2, 2);
    check_all_metrics(c, scene, "clustered at -1e6 seed " + std::to_string(seed));
  }
}

// Strips far longer than one tile with dense lattices and random points: strong interactions
// cross every slab and tile boundary of the greedy tiling.
TEST(FieldIndex, TiledStripsAcrossTileBoundaries) {
  // At k = 3 a tile is about 170 units wide: a strip of length 600 spans several slabs/tiles.
  for (double k : {3.0}) {
    DiscTable h, v, diag, rnd;
    for (int i = 0; i < 600; ++i)
      for (int j = 0; j < 2; ++j) h.push_back(h.size(), i * 1.0, j * 1.0, 0, 0, 0.4);
    for (int i = 0; i < 600; ++i)
      for (int j = 0; j < 2; ++j) v.push_back(v.size(), 5e5 + j * 1.0, -3e5 + i * 1.0, 0, 0, 0.4);
    for (int i = 0; i < 600; ++i) {
      diag.push_back(diag.size(), i * 0.5, i * 0.5, 0, 0, 0.4);
      diag.push_back(diag.size(), i * 0.5 + 1, i * 0.5, 0, 0, 0.4);
    }
    Rng rng(static_cast<uint64_t>(k * 10));
    for (int i = 0; i < 1200; ++i)
      rnd.push_back(i, rng.uniform(0, 600), rng.uniform(0, 600), 0, 0, 0.4);
    for (int i = 0; i < 200; ++i)
      rnd.push_back(1200 + i, rng.uniform(0, 600), rng.uniform(0, 2), 0, 0, 0.4);
    random_charges(rnd, 5);
    for (const auto& [t, name] :
         {std::pair{&h, "horizontal"}, {&v, "vertical"}, {&diag, "diagonal"}, {&rnd, "random"}})
      check_all_metrics(*t, StaticScene{}, std::string(name) + " strip k " + std::to_string(k), k);
  }
}

TEST(FieldIndex, WorldOfMillionByMillion) {
  for (uint64_t seed = 1; seed <= 2; ++seed) {
    DiscTable u = build::uniform(600, {0, 0, 1e6, 1e6}, 5, 1, 3, seed);
    // Clusters dense enough to interact, scattered over the whole world.
    DiscTable c = build::clustered(600, {0, 0, 1e6, 1e6}, 8, 25, 5, 1, 3, seed);
    for (std::size_t i = 0; i < c.size(); ++i)
      u.push_back(600 + i, c.x[i], c.y[i], 0, 0, c.radius[i], c.charge[i]);
    const StaticScene scene = obstacles(seed, {0, 0, 1e6, 1e6}, 12, 4);
    check_all_metrics(u, scene, "1e6 world seed " + std::to_string(seed),
                      seed == 1 ? 0.272194 : 0.02);
  }
}

TEST(FieldIndex, KernelRateExtremes) {
  DiscTable t = build::uniform(300, {0, 0, 50, 50}, 5, 1, 3, 9);
  check_all_metrics(t, StaticScene{}, "k = 0", 0.0);
  check_all_metrics(t, StaticScene{}, "k = 1e-9", 1e-9);
  check_all_metrics(t, StaticScene{}, "k = 40", 40.0);
  DiscTable l = build::lattice(200, 1e-3, 1, 1e-4, 2);  // tiles far below one unit
  check_all_metrics(l, StaticScene{}, "tiny lattice k = 1e4", 1e4);
}

TEST(FieldIndex, ThreadCountDoesNotChangeBits) {
  DiscTable t = build::clustered(5000, {0, 0, 2e4, 2e4}, 30, 60, 5, 1, 3, 4);
  const StaticScene scene = obstacles(4, {0, 0, 2e4, 2e4}, 20, 5);
  for (const PotentialSpec& s : {exp_spec(Metric::l1), exp_spec(Metric::radial)}) {
    const FieldColumns a = potential_field(t.view(), scene, s, "index", 1);
    const FieldColumns b = potential_field(t.view(), scene, s, "index", 2);
    const FieldColumns c = potential_field(t.view(), scene, s, "index", 3);
    EXPECT_EQ(a.potential, b.potential);
    EXPECT_EQ(a.grad_x, b.grad_x);
    EXPECT_EQ(a.grad_y, c.grad_y);
    EXPECT_EQ(a.potential, c.potential);
  }
}

// The index keeps its working storage from call to call (FieldSumScratch): one index asked about
// tiled, one-tile and tiny tables in turn, with and without the probes of finite differences,
// answers each with the bits a fresh index gives, on one thread and on two, in both modes.
TEST(FieldIndex, CalledAgainGivesTheBitsOfAFreshIndex) {
  const DiscTable tiled = build::clustered(1500, {0, 0, 2e4, 2e4}, 30, 60, 5, 1, 3, 4);
  DiscTable one = build::uniform(1500, {0, 0, 40, 40}, 1, 0.2, 0.3, 21);
  random_charges(one, 21, true);
  const DiscTable tiny = build::uniform(7, {0, 0, 10, 10}, 1, 0.2, 0.3, 2);
  const StaticScene scene = obstacles(4, {0, 0, 2e4, 2e4}, 20, 5), none;
  for (const FieldIndex::Mode mode : {FieldIndex::Mode::separable, FieldIndex::Mode::cutoff})
    for (int threads : {1, 2}) {
      Executor ex(threads);
      FieldIndex kept(mode);
      for (const DiscTable* t : {&tiled, static_cast<const DiscTable*>(&one), &tiny, &tiled})
        for (const bool fd : {false, true}) {
          PotentialSpec spec = exp_spec(Metric::radial);
          spec.finite_difference = fd;
          spec.fd_step = 1e-3;
          const StaticScene& sc = t == &tiled ? scene : none;
          FieldColumns got, want;
          QueryStats st, fresh;
          kept.run(t->view(), sc, spec, got, ex, st);
          FieldIndex(mode).run(t->view(), sc, spec, want, ex, fresh);
          if (mode == FieldIndex::Mode::separable && !fd) {  // the paths meant: tiles, one tile
            EXPECT_EQ(st.nodes_visited > 1, t == &tiled);
          }
          const std::string what =
              std::string(mode == FieldIndex::Mode::cutoff ? "cutoff" : "index") + " threads " +
              std::to_string(threads) + " rows " + std::to_string(t->size()) + (fd ? " fd" : "");
          EXPECT_EQ(got.potential, want.potential) << what;
          EXPECT_EQ(got.grad_x, want.grad_x) << what;
          EXPECT_EQ(got.grad_y, want.grad_y) << what;
        }
    }
}

// Worlds that fit one tile and are large enough for the tile to run its combos on every thread
// (field_index.cpp, kParallelCombos), and to sort its entries by radix: against the naive loop,
// and the same bits on 1, 2 and 3 threads. A uniform crowd; a lattice (ties in x, in y and on the
// diagonals) with a few duplicate positions and -0 beside +0 (one key for the radix sort, as
// they compare equal); mixed-sign charges.
TEST(FieldIndex, OneLargeTileOnEveryThread) {
  DiscTable uniform = build::uniform(6000, {0, 0, 90, 90}, 1, 0.2, 0.3, 21);
  random_charges(uniform, 21, true);
  DiscTable lattice = build::lattice(4900, 1.0, 1, 0.4, 5);
  random_charges(lattice, 5);
  for (std::size_t i = 97; i < lattice.size(); i += 97) {  // duplicates of the row before
    lattice.x[i] = lattice.x[i - 1];
    lattice.y[i] = lattice.y[i - 1];
  }
  std::size_t zeros = 0;  // every other coordinate of 0 made -0, in x and in y
  for (std::size_t i = 0; i < lattice.size(); ++i) {
    if (lattice.x[i] == 0 && zeros++ % 2) lattice.x[i] = -0.0;
    if (lattice.y[i] == 0 && zeros++ % 2) lattice.y[i] = -0.0;
  }
  ASSERT_GT(zeros, 40u);
  DiscTable negative = uniform;  // the same crowd in negative coordinates
  for (double& x : negative.x) x -= 1e3;
  for (double& y : negative.y) y = -y;
  for (const DiscTable* t : {&uniform, &lattice, &negative}) {
    const std::string what = t == &uniform   ? "one tile, uniform"
                             : t == &lattice ? "one tile, lattice"
                                             : "one tile, negative";
    check_all_metrics(*t, StaticScene{}, what);
    for (const PotentialSpec& s : {exp_spec(Metric::l1), exp_spec(Metric::radial)}) {
      QueryStats stats;
      const FieldColumns a = potential_field(t->view(), StaticScene{}, s, "index", 1, &stats);
      EXPECT_EQ(stats.nodes_visited, 1u) << what << ": not one tile";
      for (int threads : {2, 3}) {
        const FieldColumns b = potential_field(t->view(), StaticScene{}, s, "index", threads);
        EXPECT_EQ(a.potential, b.potential) << what << " " << metric_name(s) << " " << threads;
        EXPECT_EQ(a.grad_x, b.grad_x) << what << " " << metric_name(s) << " " << threads;
        EXPECT_EQ(a.grad_y, b.grad_y) << what << " " << metric_name(s) << " " << threads;
      }
    }
  }
}

TEST(FieldIndex, FiniteDifferenceModeMatchesNaive) {
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    DiscTable t = build::uniform(300, {0, 0, 80, 80}, 5, 1, 3, seed);
    build::offset(t, seed == 3 ? 1e6 : 0, 0);
    for (PotentialSpec s : {exp_spec(Metric::l1), exp_spec(Metric::radial)}) {
      s.finite_difference = true;
      s.fd_step = 1e-3;
      const FieldColumns naive = potential_field(t.view(), StaticScene{}, s, "naive");
      const FieldColumns idx = potential_field(t.view(), StaticScene{}, s, "index");
      // A difference quotient turns potential errors e into gradient errors 2e/h.
      EXPECT_EQ(compare(idx, naive, abs_sums(t.view(), StaticScene{}, s), s.A, 1.0, 1.0, "fd",
                        2 / s.fd_step),
                0);
      // And it approximates the analytic gradient to O(h k^2 P), except for probes with a
      // source within 2h of one of their kink lines (there the difference quotient straddles it).
      PotentialSpec a = s;
      a.finite_difference = false;
      const FieldColumns exact = potential_field(t.view(), StaticScene{}, a, "index");
      int compared = 0;
      for (std::size_t i = 0; i < t.size(); ++i) {
        bool near_kink = false;
        for (std::size_t q = 0; q < t.size(); ++q) {
          const double dx = t.x[i] - t.x[q], dy = t.y[i] - t.y[q];
          if (q != i && std::min({std::abs(dx), std::abs(dy), std::abs(dx - dy),
                                  std::abs(dx + dy)}) < 4 * s.fd_step)
            near_kink = true;
        }
        if (near_kink) continue;
        ++compared;
        EXPECT_NEAR(idx.grad_x[i], exact.grad_x[i], 1e-3 * exact.potential[i] + 1e-9) << i;
        EXPECT_NEAR(idx.grad_y[i], exact.grad_y[i], 1e-3 * exact.potential[i] + 1e-9) << i;
      }
      EXPECT_GT(compared, 200);
    }
  }
}

TEST(FieldIndex, ProbeAtArbitraryPointsMatchesNaive) {
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    DiscTable t = seed % 2 ? build::uniform(400, {0, 0, 100, 100}, 5, 1, 3, seed)
                           : build::lattice(400, 1.0, 1, 0.4, seed);
    if (seed == 4) build::offset(t, 1e6, 1e6);
    random_charges(t, seed);
    const StaticScene scene = obstacles(seed, {t.x[0], t.y[0], t.x[0] + 100, t.y[0] + 100}, 3, 1);
    std::vector<Vec2> probes;
    Rng rng(seed);
    for (int i = 0; i < 200; ++i)
      probes.push_back({t.x[0] + rng.uniform(-5, 105), t.y[0] + rng.uniform(-5, 105)});
    for (std::size_t i = 0; i < 50; ++i) probes.push_back({t.x[i * 7], t.y[i * 7]});  // on sources
    for (std::size_t i = 0; i < 20; ++i)
      probes.push_back({t.x[i] + 0.5, t.y[i] + 0.5});  // on diagonals
    for (PotentialSpec s : {exp_spec(Metric::l1), exp_spec(Metric::radial, 0.5, 2),
                            exp_spec(Metric::radial, 0.5, 1)}) {
      const FieldColumns naive = field_at(probes, t.view(), scene, s, "naive");
      const FieldColumns idx = field_at(probes, t.view(), scene, s, "index");
      const auto sabs = abs_sums(t.view(), scene, s, probes);
      EXPECT_EQ(compare(idx, naive, sabs, s.A, max_charge(t.view(), scene, true), s.k,
                        std::string("probe ") + metric_name(s)),
                0);
    }
  }
  // A probe on a lone source sees its e^0 term; with no sources everything is 0.
  DiscTable one;
  one.push_back(0, 2, 3, 0, 0, 1, 2.0);
  const std::vector<Vec2> at = {{2, 3}};
  EXPECT_DOUBLE_EQ(
      field_at(at, one.view(), StaticScene{}, exp_spec(Metric::l1), "index").potential[0],
      0.929328 * 2);
  EXPECT_EQ(field_at(at, DiscView{}, StaticScene{}, exp_spec(Metric::l1), "index").potential[0],
            0.0);
  const std::vector<Vec2> nan = {{NAN, 0}};
  EXPECT_THROW(field_at(nan, one.view(), StaticScene{}, exp_spec(Metric::l1), "index"), Error);
}

TEST(FieldIndex, PlannerPicksTheExactMethodsOnlyWhereTheyApply) {
  EXPECT_EQ(choose_field_method(5000, exp_spec(Metric::l1)).info.name, "index");
  EXPECT_EQ(choose_field_method(5000, exp_spec(Metric::radial, 0.3, 2)).info.name, "index");
  EXPECT_EQ(choose_field_method(5000, exp_spec(Metric::l2)).info.name, "cutoff");
  EXPECT_EQ(choose_field_method(5000, exp_spec(Metric::radial, 0.3, 4)).info.name, "cutoff");
  PotentialSpec inv = exp_spec(Metric::l2);
  inv.kernel = Kernel::inv;
  EXPECT_EQ(choose_field_method(5000, inv).info.name, "naive");
  EXPECT_EQ(choose_field_method(3, exp_spec(Metric::l1)).info.name, "naive");
}

// The cut-off path: every exp metric, exact within tolerance, on the tables that tile.
TEST(FieldCutoff, MatchesNaiveForEveryExpMetric) {
  std::vector<std::pair<DiscTable, std::string>> tables;
  tables.push_back({build::uniform(500, {0, 0, 300, 300}, 5, 1, 3, 1), "uniform"});
  tables.push_back({build::lattice(400, 1.0, 1, 0.4, 2), "lattice"});
  tables.push_back({build::duplicates(300, 9, {0, 0, 40, 40}, 2, 1, 3), "duplicates"});
  DiscTable far = build::clustered(800, {0, 0, 1e6, 1e6}, 10, 30, 5, 1, 3, 4);
  tables.push_back({far, "1e6 world"});
  DiscTable strip;
  for (int i = 0; i < 700; ++i) strip.push_back(i, 1e6 + i * 0.5, -1e6 + (i % 3), 0, 0, 0.4);
  tables.push_back({strip, "offset strip"});
  for (auto& [t, name] : tables) {
    random_charges(t, 7);
    const StaticScene scene = obstacles(5, {t.x[0], t.y[0], t.x[0] + 50, t.y[0] + 50}, 2, 1);
    for (PotentialSpec s :
         {exp_spec(Metric::l2, 0.272194), exp_spec(Metric::l2, 2.0), exp_spec(Metric::l1, 2.0),
          exp_spec(Metric::radial, 2.0, 3), exp_spec(Metric::radial, 0.5, 2)}) {
      const FieldColumns naive = potential_field(t.view(), scene, s, "naive");
      QueryStats st;
      const FieldColumns cut = potential_field(t.view(), scene, s, "cutoff", 1, &st);
      EXPECT_GT(st.nodes_visited, 0u);
      EXPECT_EQ(
          compare(cut, naive, abs_sums(t.view(), scene, s), s.A, max_charge(t.view(), scene, false),
                  s.k, "cutoff " + name + " k " + std::to_string(s.k)),
          0);
    }
  }
}

TEST(FieldCutoff, ProbesMatchNaive) {
  DiscTable t = build::uniform(300, {0, 0, 400, 400}, 5, 1, 3, 8);
  std::vector<Vec2> probes;
  Rng rng(3);
  for (int i = 0; i < 100; ++i) probes.push_back({rng.uniform(-10, 410), rng.uniform(-10, 410)});
  probes.push_back({t.x[5], t.y[5]});
  for (PotentialSpec s : {exp_spec(Metric::l2, 1.0), exp_spec(Metric::radial, 1.0, 5)}) {
    const FieldColumns naive = field_at(probes, t.view(), StaticScene{}, s, "naive");
    const FieldColumns cut = field_at(probes, t.view(), StaticScene{}, s, "cutoff");
    EXPECT_EQ(compare(cut, naive, abs_sums(t.view(), StaticScene{}, s, probes), s.A, 1.0, s.k,
                      "cutoff probe"),
              0);
  }
}

}  // namespace
}  // namespace crowddb
