// Random and adversarial disc tables shared by tests, benchmarks and experiments. Every builder
// is a pure function of its arguments and seed (our own generator: same tables everywhere).
// Ids are 0..n-1 in row order unless stated.
#pragma once

#include <cstdint>

#include "crowddb/query.hpp"

namespace crowddb::build {

struct Box {
  double xmin = 0, ymin = 0, xmax = 640, ymax = 480;
};

// Positions uniform in the box; velocity uniform in the disc |v| <= vmax; radius uniform in
// [rmin, rmax]. Overlaps allowed (the E1 setup).
DiscTable uniform(std::size_t n, Box box, double vmax, double rmin, double rmax, uint64_t seed);

// Gaussian-ish clusters: `clusters` centres uniform in the box, members within `spread` of them.
DiscTable clustered(std::size_t n, Box box, std::size_t clusters, double spread, double vmax,
                    double rmin, double rmax, uint64_t seed);

// A square lattice of side ceil(sqrt(n)) with the given spacing: exact ties in x, y and in
// pair distances. Velocities drawn from {-v, 0, v}^2 so first-to-collide times tie too.
DiscTable lattice(std::size_t n, double spacing, double v, double radius, uint64_t seed);

// The Big Crunch (thesis §2.1): agents uniform in the box, each moving towards the centre so that
// all arrive at time `arrival`. perturb > 0 adds uniform noise in [-perturb, perturb] to each
// velocity component (the thesis's perturbed version uses 1).
DiscTable big_crunch(std::size_t n, Box box, double arrival, double rmin, double rmax,
                     double perturb, uint64_t seed);

// Copies of `distinct` positions repeated until n rows: duplicate positions (and velocities).
DiscTable duplicates(std::size_t n, std::size_t distinct, Box box, double vmax, double radius,
                     uint64_t seed);

// Shifts every position by (dx, dy): the far-offset variants (e.g. 1e6).
void offset(DiscTable& t, double dx, double dy);

// Reverses/permutes row order and assigns ids not in row order, so tie-breaks by id are tested.
void shuffle_ids(DiscTable& t, uint64_t seed);

}  // namespace crowddb::build
