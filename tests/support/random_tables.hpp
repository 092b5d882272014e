// A random disc table of one of the builders' shapes (uniform, clustered, lattice, Big Crunch,
// duplicates), speeds, radii and shape drawn from `rng`, ids shuffled half the time: the input of
// the property tests that compare an index with its naive oracle.
#pragma once

#include <cstddef>
#include <cstdint>

#include "scenario/builders.hpp"
#include "util/rng.hpp"

namespace crowddb::test {

inline DiscTable random_shape_table(Rng& rng, std::size_t n, double side, uint64_t seed) {
  const double vmax = rng.below(4) == 0 ? 0 : rng.uniform(0.1, 60);
  const double rmin = rng.uniform(0.01, 3), rmax = rmin + rng.uniform(0, 3);
  DiscTable t;
  switch (rng.below(5)) {
    case 0:
      t = build::uniform(n, {0, 0, side, side}, vmax, rmin, rmax, seed);
      break;
    case 1:
      t = build::clustered(n, {0, 0, side, side}, 1 + rng.below(5), side / 20, vmax, rmin, rmax,
                           seed);
      break;
    case 2:
      t = build::lattice(n, rng.uniform(0.5, 5), static_cast<double>(rng.below(3)), rmin, seed);
      break;
    case 3:
      t = build::big_crunch(n, {0, 0, side, side}, rng.uniform(1, 60), rmin, rmax,
                            static_cast<double>(rng.below(2)), seed);
      break;
    default:
      t = build::duplicates(n, 1 + rng.below(20), {0, 0, side, side}, vmax, rmin, seed);
      break;
  }
  if (rng.below(2)) build::shuffle_ids(t, seed);
  return t;
}

}  // namespace crowddb::test
