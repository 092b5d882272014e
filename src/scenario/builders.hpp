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

// `count` circle obstacles, centres uniform in the box, radius uniform in [rmin, rmax], charge
// `charge` (the "large static obstacles" of the potential-field experiments).
std::vector<CircleObstacle> circles(std::size_t count, Box box, double rmin, double rmax,
                                    double charge, uint64_t seed);

// The E5 potential-field table (thesis §4.2, DESIGN.md §7): density x n = 1, i.e. n agents
// uniform on an n x n board, radius in [1, 3], speed in [0, 5]; and round(3 n / 125) obstacles
// of radius in [5, 15] (125 agents : 3 obstacles).
struct FieldWorld {
  DiscTable agents;
  std::vector<CircleObstacle> obstacles;
};
FieldWorld e5_world(std::size_t n, uint64_t seed);

// Pairs of discs that touch exactly in double arithmetic (centre distance == sum of radii, no
// overlap by the strict test) along 3-4-5 and 5-12-13 directions, half of them nudged one ulp
// closer so that they overlap by a hair: the adversarial boundary of every collision filter.
// 2 * pairs rows, pairs scattered uniformly in the box.
DiscTable touching(std::size_t pairs, Box box, uint64_t seed);

// Appends `count` giant discs (radius uniform in [rmin, rmax]) at uniform positions in the box.
void add_giants(DiscTable& t, std::size_t count, Box box, double rmin, double rmax, uint64_t seed);

// Shifts every position by (dx, dy): the far-offset variants (e.g. 1e6).
void offset(DiscTable& t, double dx, double dy);

// Reverses/permutes row order and assigns ids not in row order, so tie-breaks by id are tested.
void shuffle_ids(DiscTable& t, uint64_t seed);

}  // namespace crowddb::build
