// The Barnes-Hut approximation of the inv kernels against the naive sums, under its stated
// worst-case bound (field_bh.cpp), plus its typical accuracy, on random, clustered, lattice,
// duplicate and far-offset tables with obstacles.
#include "index/field_bh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "crowddb/query.hpp"
#include "query/field_kernels.hpp"
#include "scenario/builders.hpp"
#include "util/rng.hpp"

namespace crowddb {
namespace {

PotentialSpec inv_spec(Metric m, int frames = 2) {
  PotentialSpec s;
  s.kernel = Kernel::inv;
  s.metric = m;
  s.A = 1;
  s.radial_frames = frames;
  s.inv_floor = 0.1;
  return s;
}

struct Abs {
  std::vector<double> pot, grad;  // S_abs and G_abs per probe
};

Abs bh_abs_sums(const DiscView& d, const StaticScene& scene, const PotentialSpec& spec) {
  const PairKernel kernel(spec);
  Abs a;
  for (std::size_t p = 0; p < d.n; ++p) {
    double sp = 0, sg = 0;
    const auto add = [&](double dx, double dy, double c) {
      double pot = 0, gx = 0, gy = 0;
      kernel.add(dx, dy, std::abs(spec.A * d.charge[p] * c), pot, gx, gy);
      sp += pot;
      sg += std::hypot(gx, gy);
    };
    for (std::size_t q = 0; q < d.n; ++q)
      if (q != p) add(d.x[p] - d.x[q], d.y[p] - d.y[q], d.charge[q]);
    for (std::size_t q = 0; q < scene.point_count(); ++q)
      add(d.x[p] - scene.point_x()[q], d.y[p] - scene.point_y()[q], scene.point_charge()[q]);
    a.pot.push_back(sp);
    a.grad.push_back(sg);
  }
  return a;
}

// Checks the bound on every row; returns the median relative potential error.
double check(const DiscTable& t, const StaticScene& scene, const PotentialSpec& s,
             const std::string& what) {
  const FieldColumns naive = potential_field(t.view(), scene, s, "naive");
  QueryStats st;
  const FieldColumns bh = potential_field(t.view(), scene, s, "bh", 1, &st);
  const Abs a = bh_abs_sums(t.view(), scene, s);
  const double gb = bh_gradient_bound(s.metric);
  std::vector<double> rel;
  int bad = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double ep = std::abs(bh.potential[i] - naive.potential[i]);
    const double eg = std::hypot(bh.grad_x[i] - naive.grad_x[i], bh.grad_y[i] - naive.grad_y[i]);
    const double slack = 1e-12 * (a.pot[i] + 1);
    if (!(ep <= kBhPotentialBound * a.pot[i] + slack) || !(eg <= gb * a.grad[i] + slack))
      if (++bad <= 3)
        ADD_FAILURE() << what << " row " << i << ": potential error " << ep << " of " << a.pot[i]
                      << ", gradient error " << eg << " of " << a.grad[i];
    rel.push_back(a.pot[i] > 0 ? ep / a.pot[i] : 0);
  }
  EXPECT_EQ(bad, 0) << what;
  std::nth_element(rel.begin(), rel.begin() + static_cast<std::ptrdiff_t>(rel.size() / 2),
                   rel.end());
  return rel[rel.size() / 2];
}

StaticScene scene_for(const DiscTable& t, uint64_t seed) {
  Rng rng(seed);
  std::vector<CircleObstacle> cs;
  for (int i = 0; i < 4; ++i)
    cs.push_back({t.x[0] + rng.uniform(0, 300), t.y[0] + rng.uniform(0, 300), 6, 2});
  return StaticScene(std::move(cs), {}, 1.0);
}

TEST(FieldBarnesHut, WithinItsStatedBoundOnEveryRow) {
  std::vector<std::pair<DiscTable, std::string>> tables;
  tables.push_back({build::uniform(1500, {0, 0, 400, 400}, 5, 1, 3, 1), "uniform"});
  tables.push_back({build::clustered(1500, {0, 0, 1000, 1000}, 6, 60, 5, 1, 3, 2), "clustered"});
  tables.push_back({build::lattice(900, 2.0, 1, 0.4, 3), "lattice"});
  tables.push_back({build::duplicates(800, 40, {0, 0, 200, 200}, 2, 1, 4), "duplicates"});
  DiscTable off = build::uniform(1000, {0, 0, 300, 300}, 5, 1, 3, 5);
  build::offset(off, 1e6, 1e6);
  tables.push_back({off, "offset"});
  for (auto& [t, name] : tables) {
    Rng rng(9);
    for (double& c : t.charge) c = rng.uniform(0.5, 2);
    const StaticScene scene = scene_for(t, 7);
    for (const PotentialSpec& s :
         {inv_spec(Metric::l2), inv_spec(Metric::l1), inv_spec(Metric::radial, 2)}) {
      const double med = check(t, scene, s, name);
      // The typical error is far below the worst case: medians measured 3e-6 .. 1.6e-4.
      EXPECT_LT(med, 1e-3) << name;
    }
  }
}

TEST(FieldBarnesHut, MixedSignsAndFiniteDifferences) {
  DiscTable t = build::uniform(1000, {0, 0, 300, 300}, 5, 1, 3, 11);
  Rng rng(1);
  for (double& c : t.charge) c = rng.uniform(-1, 2);
  check(t, StaticScene{}, inv_spec(Metric::l2), "mixed signs");
  PotentialSpec fd = inv_spec(Metric::l2);
  fd.finite_difference = true;
  const FieldColumns a = potential_field(t.view(), StaticScene{}, fd, "bh");
  const FieldColumns b = potential_field(t.view(), StaticScene{}, fd, "naive");
  for (std::size_t i = 0; i < t.size(); i += 37)
    EXPECT_NEAR(a.potential[i], b.potential[i], 0.25 * std::abs(b.potential[i]) + 1);
}

TEST(FieldBarnesHut, ProbesAndDeterminism) {
  DiscTable t = build::clustered(2000, {0, 0, 500, 500}, 5, 40, 5, 1, 3, 3);
  std::vector<Vec2> probes;
  Rng rng(2);
  for (int i = 0; i < 300; ++i) probes.push_back({rng.uniform(0, 500), rng.uniform(0, 500)});
  const PotentialSpec s = inv_spec(Metric::radial, 2);
  const FieldColumns n = field_at(probes, t.view(), StaticScene{}, s, "naive");
  const FieldColumns b1 = field_at(probes, t.view(), StaticScene{}, s, "bh", 1);
  const FieldColumns b2 = field_at(probes, t.view(), StaticScene{}, s, "bh", 2);
  EXPECT_EQ(b1.potential, b2.potential);
  EXPECT_EQ(b1.grad_x, b2.grad_x);
  for (std::size_t i = 0; i < probes.size(); ++i)
    EXPECT_NEAR(b1.potential[i], n.potential[i], kBhPotentialBound * n.potential[i]);
  // Never chosen by the planner.
  EXPECT_NE(potential_field(t.view(), StaticScene{}, s, "auto").potential, std::vector<double>{});
  QueryStats st;
  potential_field(t.view(), StaticScene{}, s, "auto", 1, &st);
  EXPECT_EQ(st.nodes_visited, 0u);  // naive
}

}  // namespace
}  // namespace crowddb
