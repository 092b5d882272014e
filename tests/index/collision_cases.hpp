// Random and adversarial inputs for the collision-set methods, shared by their tests. Each case
// is a disc table plus a scene; the naive oracle gives the expected answer.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "crowddb/query.hpp"
#include "scenario/builders.hpp"

namespace crowddb::test {

struct CollisionCase {
  std::string name;
  DiscTable discs;
  bool equal_radii = false;
};

// Scenes the cases are combined with: none; circles; polygons with walls (the world bounds).
inline std::vector<std::pair<std::string, StaticScene>> collision_scenes(const build::Box& box) {
  std::vector<std::pair<std::string, StaticScene>> scenes;
  scenes.emplace_back("no obstacles", StaticScene());
  const double w = box.xmax - box.xmin, h = box.ymax - box.ymin;
  const double spacing = std::max(w, h) / 64;  // charged points: unused by collision queries
  std::vector<CircleObstacle> circles;
  for (int i = 0; i < 6; ++i)
    circles.push_back({box.xmin + w * (0.1 + 0.15 * i), box.ymin + h * (0.2 + 0.1 * i),
                       0.04 * std::max(w, h) + 1, 1});
  scenes.emplace_back("circles", StaticScene(circles, {}, spacing, ObstacleCharges::centres));
  std::vector<PolygonObstacle> polys;
  polys.push_back({{{box.xmin + 0.3 * w, box.ymin + 0.3 * h},
                    {box.xmin + 0.5 * w, box.ymin + 0.3 * h},
                    {box.xmin + 0.4 * w, box.ymin + 0.6 * h}},
                   1});
  polys.push_back({{{box.xmin + 0.6 * w, box.ymin + 0.6 * h},
                    {box.xmin + 0.9 * w, box.ymin + 0.6 * h},
                    {box.xmin + 0.9 * w, box.ymin + 0.62 * h},
                    {box.xmin + 0.6 * w, box.ymin + 0.62 * h}},
                   1});
  // Walls a little inside the discs' box, so that some discs touch or cross them.
  const Bounds walls{box.xmin + 0.02 * w, box.ymin + 0.02 * h, box.xmax - 0.02 * w,
                     box.ymax - 0.02 * h};
  scenes.emplace_back("polygons+walls",
                      StaticScene({}, polys, spacing, ObstacleCharges::centres, &walls));
  return scenes;
}

inline std::vector<CollisionCase> collision_cases(uint64_t seed) {
  using build::Box;
  std::vector<CollisionCase> cs;
  auto add = [&](std::string name, DiscTable t, bool eq = false) {
    cs.push_back({std::move(name), std::move(t), eq});
  };
  add("empty", DiscTable(), true);
  add("single", build::uniform(1, Box{}, 1, 2, 2, seed), true);
  add("two overlapping", build::uniform(2, Box{0, 0, 3, 3}, 1, 2, 2, seed), true);
  add("uniform radii 1-3 ~10%", build::uniform(1500, Box{0, 0, 700, 700}, 1, 1, 3, seed));
  add("uniform mixed 0.5-50", build::uniform(1200, Box{0, 0, 3000, 3000}, 1, 0.5, 50, seed + 1));
  add("dense mixed 0.5-50", build::uniform(600, Box{0, 0, 400, 400}, 1, 0.5, 50, seed + 2));
  add("equal radii", build::uniform(1500, Box{0, 0, 300, 300}, 1, 1.5, 1.5, seed + 3), true);
  add("clustered", build::clustered(1500, Box{0, 0, 2000, 2000}, 12, 40, 1, 0.5, 3, seed + 4));
  add("lattice touching", build::lattice(900, 2.0, 1, 1.0, seed + 5),
      true);  // spacing == 2R: no pair
  add("lattice overlapping", build::lattice(900, 1.9, 1, 1.0, seed + 6), true);
  add("lattice sparse", build::lattice(900, 2.5, 1, 1.0, seed + 7), true);
  add("duplicates", build::duplicates(800, 50, Box{0, 0, 200, 200}, 1, 1.0, seed + 8), true);
  add("touching pairs", build::touching(400, Box{0, 0, 5000, 5000}, seed + 9));
  {
    DiscTable t = build::touching(400, Box{0, 0, 5000, 5000}, seed + 10);
    build::offset(t, 1e6, -3e6);
    add("touching pairs at 1e6", std::move(t));
  }
  {
    DiscTable t = build::lattice(900, 2.0, 1, 1.0, seed + 11);
    build::offset(t, 1e9, 1e9);
    add("lattice touching at 1e9", std::move(t), true);
  }
  {
    DiscTable t = build::uniform(1200, Box{0, 0, 700, 700}, 1, 1, 3, seed + 12);
    build::offset(t, 1e6, 1e6);
    add("uniform at 1e6", std::move(t));
  }
  {
    DiscTable t = build::uniform(1200, Box{0, 0, 700, 700}, 1, 1, 3, seed + 13);
    build::offset(t, -4e12, 2e12);
    add("uniform at 1e12", std::move(t));
  }
  {  // two clusters 1e9 apart: a huge extent with dense parts
    DiscTable a = build::uniform(600, Box{0, 0, 200, 200}, 1, 1, 3, seed + 14);
    DiscTable b = build::uniform(600, Box{0, 0, 200, 200}, 1, 1, 3, seed + 15);
    build::offset(b, 1e9, -1e9);
    for (std::size_t i = 0; i < b.size(); ++i)
      a.push_back(600 + i, b.x[i], b.y[i], 0, 0, b.radius[i]);
    add("far clusters", std::move(a));
  }
  {
    DiscTable t = build::uniform(1500, Box{0, 0, 700, 700}, 1, 1, 3, seed + 16);
    build::add_giants(t, 4, Box{0, 0, 700, 700}, 50, 400, seed + 17);
    add("a few giants", std::move(t));
  }
  {
    DiscTable t = build::uniform(1000, Box{0, 0, 400, 400}, 1, 1e-3, 2e-3, seed + 18);
    build::add_giants(t, 30, Box{0, 0, 400, 400}, 1, 30, seed + 19);
    add("tiny and large", std::move(t));
  }
  {  // all centres on one vertical line and one horizontal line (sweep degeneracies)
    DiscTable t;
    for (int i = 0; i < 400; ++i) t.push_back(i, 5, 1.7 * i, 0, 0, 0.8 + 0.1 * (i % 3));
    for (int i = 0; i < 400; ++i)
      t.push_back(400 + i, 1.7 * i - 300, 40, 0, 0, 0.8 + 0.1 * (i % 3));
    add("lines", std::move(t));
  }
  {
    DiscTable t = build::uniform(1000, Box{-500, -500, -100, 100}, 1, 0.5, 4, seed + 20);
    build::shuffle_ids(t, seed + 21);
    add("negative coordinates, shuffled ids", std::move(t));
  }
  return cs;
}

// The rows of a CollisionPairs answer, sorted and unique (the collision set).
inline std::vector<uint32_t> rows_of(const CollisionPairs& p) {
  std::vector<uint32_t> rows;
  for (auto [i, j] : p.agents) {
    rows.push_back(i);
    rows.push_back(j);
  }
  for (const auto& h : p.obstacles) rows.push_back(h.first);
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  return rows;
}

}  // namespace crowddb::test
