#include "scenario/builders.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "util/rng.hpp"

namespace crowddb::build {
namespace {

void velocity_in_disc(Rng& rng, double vmax, double& vx, double& vy) {
  do {
    vx = rng.uniform(-1, 1);
    vy = rng.uniform(-1, 1);
  } while (vx * vx + vy * vy > 1);
  vx *= vmax;
  vy *= vmax;
}

}  // namespace

DiscTable uniform(std::size_t n, Box box, double vmax, double rmin, double rmax, uint64_t seed) {
  Rng rng(seed);
  DiscTable t;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = rng.uniform(box.xmin, box.xmax), y = rng.uniform(box.ymin, box.ymax);
    double vx, vy;
    velocity_in_disc(rng, vmax, vx, vy);
    t.push_back(i, x, y, vx, vy, rng.uniform(rmin, rmax));
  }
  return t;
}

DiscTable clustered(std::size_t n, Box box, std::size_t clusters, double spread, double vmax,
                    double rmin, double rmax, uint64_t seed) {
  Rng rng(seed);
  clusters = std::max<std::size_t>(clusters, 1);
  std::vector<double> cx(clusters), cy(clusters);
  for (std::size_t c = 0; c < clusters; ++c) {
    cx[c] = rng.uniform(box.xmin, box.xmax);
    cy[c] = rng.uniform(box.ymin, box.ymax);
  }
  DiscTable t;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t c = rng.below(clusters);
    // Sum of three uniforms: a cheap bell shape that stays reproducible.
    const double ox = (rng.uniform(-1, 1) + rng.uniform(-1, 1) + rng.uniform(-1, 1)) / 3 * spread;
    const double oy = (rng.uniform(-1, 1) + rng.uniform(-1, 1) + rng.uniform(-1, 1)) / 3 * spread;
    double vx, vy;
    velocity_in_disc(rng, vmax, vx, vy);
    t.push_back(i, cx[c] + ox, cy[c] + oy, vx, vy, rng.uniform(rmin, rmax));
  }
  return t;
}

DiscTable lattice(std::size_t n, double spacing, double v, double radius, uint64_t seed) {
  Rng rng(seed);
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  DiscTable t;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(i % side) * spacing,
                 y = static_cast<double>(i / side) * spacing;
    const double vx = (static_cast<double>(rng.below(3)) - 1) * v;
    const double vy = (static_cast<double>(rng.below(3)) - 1) * v;
    t.push_back(i, x, y, vx, vy, radius);
  }
  return t;
}

DiscTable big_crunch(std::size_t n, Box box, double arrival, double rmin, double rmax,
                     double perturb, uint64_t seed) {
  Rng rng(seed);
  const double cx = (box.xmin + box.xmax) / 2, cy = (box.ymin + box.ymax) / 2;
  DiscTable t;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = rng.uniform(box.xmin, box.xmax), y = rng.uniform(box.ymin, box.ymax);
    double vx = (cx - x) / arrival, vy = (cy - y) / arrival;
    if (perturb > 0) {
      vx += rng.uniform(-perturb, perturb);
      vy += rng.uniform(-perturb, perturb);
    }
    t.push_back(i, x, y, vx, vy, rng.uniform(rmin, rmax));
  }
  return t;
}

DiscTable duplicates(std::size_t n, std::size_t distinct, Box box, double vmax, double radius,
                     uint64_t seed) {
  DiscTable base = uniform(std::max<std::size_t>(distinct, 1), box, vmax, radius, radius, seed);
  DiscTable t;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = i % base.size();
    t.push_back(i, base.x[j], base.y[j], base.vx[j], base.vy[j], base.radius[j], base.charge[j]);
  }
  return t;
}

void offset(DiscTable& t, double dx, double dy) {
  for (auto& x : t.x) x += dx;
  for (auto& y : t.y) y += dy;
}

void shuffle_ids(DiscTable& t, uint64_t seed) {
  Rng rng(seed);
  std::vector<uint64_t> ids(t.size());
  std::iota(ids.begin(), ids.end(), uint64_t{1000});
  for (std::size_t i = ids.size(); i > 1; --i) std::swap(ids[i - 1], ids[rng.below(i)]);
  t.id = ids;
}

}  // namespace crowddb::build
