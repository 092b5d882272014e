// The RVO2-style airport of the speed benchmarks (rvo2_side_by_side, tick_speed): `agents` people
// uniform at `density` per m^2 in a walled square, radius 0.25 m, 1.3 m/s, four goals on the
// walls (round robin), dt 0.1 s, ORCA's neighbour distance 5 m, 10 neighbours, horizons 2 and
// 0.5 s (RVO2's settings in the side-by-side); `model` steers them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

namespace crowddb::bench {

inline double airport_side(std::size_t agents, double density = 0.5) {
  return std::sqrt(static_cast<double>(agents) / density);
}

// `placed`: how many of them the document itself places (all by default; the 10^7 case of
// tick_speed places one and inserts the rest through the API, past the scenario files' cap).
inline std::string airport_scenario(std::size_t agents, const std::string& model, int threads,
                                    double density = 0.5, std::size_t placed = SIZE_MAX) {
  const double side = airport_side(agents, density);
  char doc[2048];
  std::snprintf(doc, sizeof doc, R"({"bounds": [0, 0, %.17g, %.17g], "dt": 0.1, "seed": 3,
    "threads": %d, "steering": {"model": "%s", "orca": {"neighbor_dist": 5, "max_neighbors": 10,
    "time_horizon": 2, "time_horizon_obst": 0.5}},
    "goals": [{"name": "S", "x": %.17g, "y": 1}, {"name": "E", "x": %.17g, "y": %.17g},
              {"name": "W", "x": 1, "y": %.17g}, {"name": "N", "x": %.17g, "y": %.17g}],
    "groups": [{"count": %zu, "placement": {"type": "uniform", "region": [0, 0, %.17g, %.17g],
                "gap": 0.02}, "radius": 0.25, "pref_speed": 1.3, "goals": {"assign": "round_robin"}}]})",
                side, side, threads, model.c_str(), side / 2, side - 1, side / 2, side / 2,
                side / 2, side - 1, std::min(agents, placed), side, side);
  return doc;
}

}  // namespace crowddb::bench
