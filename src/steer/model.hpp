// Steering models (DESIGN.md §3.0): how agents choose their next velocity. Each model is a small
// plan of queries over the agent table and the static scene (neighbours, obstacle features,
// first-to-collide, potential fields: access paths from src/plan/, each with a naive twin) and a
// per-agent velocity rule. The tick's stages stay a fixed list:
//
//   apply batch -> goal stage (preferred velocities) -> model.velocities() -> integrate
//   -> backoff (the zero-overlap safety net, under every model) -> commit
//
// A model reads the current columns and the preferred velocities and writes one velocity per
// row; it keeps its access-path objects (index storage) from tick to tick. New models register
// in registry.cpp only.
#pragma once

#include <functional>
#include <memory>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "crowddb/simulation.hpp"
#include "plan/access_path.hpp"
#include "sim/oplog.hpp"
#include "util/executor.hpp"
#include "util/pick.hpp"

namespace crowddb::steer {

// Rows per parallel chunk of orca's and cfsm's per-agent loops.
inline constexpr std::size_t kGrain = 128;
// [m] Contact planes and headways keep this much more than touching distance, so that rounding of
// the new positions cannot turn an exact touch into an overlap the backoff would freeze.
inline constexpr double kSkin = 1e-6;

// The squared distance of rows i and j as the neighbour lists compute it (same operands, same
// order: the same double), so that a model's lists need not store it (NeighbourLists::with_dist2:
// 80 MB at 10^6 agents with 10 neighbours each).
inline double dist2_of(const AgentTable& t, std::size_t i, std::size_t j) {
  const double dx = t.x[j] - t.x[i], dy = t.y[j] - t.y[i];
  return dx * dx + dy * dy;
}

// A parameter as EXPLAIN prints it (ostream's default formatting, as every model printed it).
std::string explain_number(double v);

// What a model reads in one tick.
struct TickInput {
  const AgentTable& agents;
  std::span<const Goal> goals;
  const StaticScene& scene;
  const SimConfig& cfg;
  std::span<const double> pref_vx, pref_vy;  // [m/s] from the goal stage (idle agents: 0, or
                                             // stepping off a goal area others need)
  std::span<const double> path_left;         // [m] sim::path_left per row (goal stage); infinite
                                             // for those standing
  uint64_t tick;                             // the tick being computed
  // No two agents overlap at the tick's start: the last tick's backoff left no overlapping pair
  // and nothing was inserted since (the engine's own knowledge; false when unknown).
  bool no_overlaps = false;
};

class Model {
 public:
  virtual ~Model() = default;
  // The new velocity of every row [m/s], written to vx and vy (sized agents.size()). Must not
  // depend on the thread count.
  virtual void velocities(const TickInput& in, std::span<double> vx, std::span<double> vy,
                          Executor& ex, sim::OpLog& log) = 0;
  // EXPLAIN: one line per operator the model runs, numbered from `step` (advanced).
  virtual void explain(std::ostream& os, const TickInput& in, int& step) const = 0;
  // The agents' rows were permuted (order[new row] = old row) since the last tick; passed on to
  // access paths that keep per-row state across ticks (on `ex`'s threads when given). Never
  // changes a result. Runs beside World::permute_rows (Executor::both): reads nothing of the
  // agents' table.
  virtual void rows_permuted(std::span<const uint32_t> /*order*/, Executor* /*ex*/ = nullptr) {}
  // The neighbour lists of the last velocities() call, over every row of its table, for the
  // backoff to rule overlaps out with (sim::lists_rule_out_overlaps); none by default.
  virtual NearLists near_lists() const { return {}; }
};

struct ModelInfo {
  std::string name;
  std::string description;  // one line, shown by EXPLAIN and `--model` errors
  std::function<std::unique_ptr<Model>()> make;
};

const std::vector<ModelInfo>& model_registry();
// Throws Error(usage) naming the registered models when `name` is unknown.
const ModelInfo& find_model(std::string_view name);

}  // namespace crowddb::steer
