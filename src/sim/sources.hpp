// Sources (World::sources): agents entering over time. Agent k of a source is due at
// start + k / rate (for k < count and start + k / rate < end) and enters at the first tick whose
// start time is at or after that, at a free spot of the source's area: uniform in the area
// (rejection in its bounding box, seeded), its disc overlapping no agent (those already in and
// those entering this tick) and no obstacle or wall. When no free spot turns up in `kTries`
// draws the agent waits for the next tick, before any later agent of that source; none is
// dropped. Goals go round robin over the source's list.
//
// Deterministic: each source draws from its own stream (seed, source row), in emission order.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "crowddb/query.hpp"
#include "crowddb/simulation.hpp"
#include "util/rng.hpp"
#include "world/obstacle_lookup.hpp"

namespace crowddb::sim {

class SourceEmitter {
 public:
  // How a drawn spot is tested against the agents and obstacles: through a placement grid and an
  // obstacle lookup, or (the tests' oracle) against every agent near the area, every one entering
  // this tick and every obstacle, one by one.
  enum class FreeSpots { grid, naive };
  SourceEmitter(const World& world, uint64_t seed, FreeSpots free_spots = FreeSpots::grid);
  // Inserts (as pending changes) the agents that enter at the start of tick `tick` (time
  // (tick - 1) dt). Returns how many.
  std::size_t emit(World& world, const SimConfig& cfg, const StaticScene& scene, uint64_t tick);
  // How many times a free-spot grid was built (the tests check that the grid answered).
  uint64_t grids_built() const { return grids_built_; }
  // Agents still to enter (due or not).
  std::size_t waiting(const World& world) const;
  // Checkpoints: per source, the agents let in and the random stream.
  void save(ByteWriter& out) const;
  void restore(ByteReader& in, const World& world);

 private:
  static constexpr int kTries = 20;
  // Free-spot tests one by one, in passes over the discs they look at, before a grid is built
  // over those discs: building it costs some 50-100 tests a disc (a hash table's cache misses).
  static constexpr uint64_t kScansBeforeGrid = 64;
  struct State {
    uint64_t entered = 0;
    Rng rng;
  };
  // Does the disc of `a` touch an obstacle or a wall of the scene?
  bool touches_an_obstacle(const StaticScene& scene, const AgentSpec& a);
  // Obstacles (walls included) beyond which a spot is tested against those near it only.
  static constexpr std::size_t kObstaclesForALookup = 16;
  std::vector<State> state_;
  bool naive_;
  uint64_t grids_built_ = 0;
  std::optional<ObstacleLookup> lookup_;  // over the scene's obstacles, built at the first need
  std::size_t lookup_obstacles_ = 0;
  std::vector<uint32_t> near_obstacles_;
};

// Agents a source lets in over its whole life: count, or fewer when `end` comes first.
uint64_t source_total(const Source& s);

}  // namespace crowddb::sim
