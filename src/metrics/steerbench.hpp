// SteerBench's metrics (Singh, Kapadia, Faloutsos, Reinman 2009), computed the way SteerSuite's
// AgentMetricsCollector and CompositeTechnique01/02 compute them, so that scores compare with
// published ones when dt is SteerSuite's 0.05 s:
//
//   per agent, per tick while it is measured (from its first tick in the table to the tick it
//   arrives, which is not counted, or to the end of the run):
//     time          += dt
//     path length   += |p_n - p_{n-1}|
//     energy        += 0.5 |v_n|^2              (mass 1, NOT times dt: SteerBench's sum)
//     acceleration  += |v_n - v_{n-1}| / dt     (from the second measured tick on)
//   with v_n = (p_n - p_{n-1}) / dt (finite differences, as SteerSuite);
//   collisions: episodes of penetration > 1 mm with another agent or an obstacle (walls
//   included), counted once per episode and per agent involved.
//   composite01 = 50 * avg collisions + avg time + avg energy
//   composite02 = composite01 + avg acceleration
// Averages are over every measured agent (SteerSuite measures the agents present at the start;
// agents from sources are measured from their entry).
#pragma once

#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "crowddb/simulation.hpp"
#include "crowddb/world.hpp"
#include "util/flat_map.hpp"

namespace crowddb::metrics {

struct AgentScore {
  uint64_t id = 0;
  std::size_t collisions = 0;  // unique collision episodes
  double time = 0;             // [s] measured
  double path_length = 0;      // [m]
  double energy = 0;           // sum of 0.5 |v|^2 per tick [m^2/s^2]
  double acceleration = 0;     // sum of |dv| / dt per tick [m/s^2]
  bool arrived = false;
  double score01() const { return 50.0 * static_cast<double>(collisions) + time + energy; }
  double score02() const { return score01() + acceleration; }
};

struct SteerBenchTotals {
  std::size_t agents = 0;
  std::size_t collisions = 0;  // sum over agents (an agent-agent episode counts for both)
  double avg_collisions = 0, avg_time = 0, avg_energy = 0, avg_acceleration = 0, avg_path = 0;
  double composite01 = 0, composite02 = 0;
};

class SteerBench {
 public:
  // `walls`: the world's bounds are solid (SimConfig::walls), so touching them is a collision.
  SteerBench(double dt, bool walls) : dt_(dt), walls_(walls) {}
  // The agents at the start (tick 0).
  void start(const World& world);
  // After each tick. `m` tells whether anything overlaps at all (when nothing does, no collision
  // can have started and the per-pair search is skipped). With an executor the rows that only
  // add the tick to their agent's track do so on its threads (the same sums: each track is one
  // row's).
  void tick(const World& world, const TickMetrics& m, Executor* ex = nullptr);
  // In order of first appearance. Made on each call (a live agent's sums are in its track), and
  // held until the next: for_each_score gives the same without holding them all at once.
  const std::vector<AgentScore>& scores() const;
  // f(const AgentScore&) for every agent measured, in order of first appearance.
  template <class F>
  void for_each_score(F&& f) const {
    for (uint32_t where : where_) f(score_at(where));
  }
  SteerBenchTotals totals() const;
  // Checkpoints (a resumed run's scores equal the uninterrupted run's).
  void save(ByteWriter& out) const;
  void restore(ByteReader& in);

 private:
  // 88 bytes: at 10^6 agents every byte a track holds is a megabyte. A live agent's score is its
  // track: AgentScore is made only when it closes (arrives or leaves), or when asked for.
  struct Track {
    double x, y, vx = 0, vy = 0;
    // The running sums. (The tracks are in row order, the scores in order of appearance: a
    // write into the scores per row and tick was a cache miss each.)
    double time = 0, path_length = 0, energy = 0, acceleration = 0;
    uint64_t id = 0;
    uint32_t order = 0;       // its agent's place in the order of first appearance
    uint32_t collisions = 0;  // episodes so far
    uint32_t seen = 0;        // the last tick it was in the table, modulo 2^32
    bool has_v = false;
    bool live = true;  // false: the slot is free
  };
  static_assert(sizeof(Track) == 88);
  static constexpr uint32_t kNoSlot = UINT32_MAX;
  // where_'s entries: a live track's slot, or kClosed | its place in closed_.
  static constexpr uint32_t kClosed = 1u << 31;
  void open_score(uint64_t id);  // a new place in the order of appearance, and the index
  uint32_t open_track(Track tr);
  void close_track(uint32_t slot);
  uint32_t open_agent(uint64_t id, double x, double y);  // its place and track; the slot
  void collisions(const World& world);
  AgentScore score_at(uint32_t where) const;  // the agent's score, where_ giving where it is
  void add_tick(Track& tr, double x, double y) const;  // the tick's step, its agent now at (x, y)
  // Does the slot a row remembers still hold agent id's live track?
  bool holds(uint32_t slot, uint64_t id) const {
    return slot != kNoSlot && tracks_[slot].live && tracks_[slot].id == id;
  }
  // Puts the live tracks in the order of the rows that hold them (slot = place in that order),
  // in place: a copy of them all is 88 MB at 10^6 agents, at the moment the run's memory peaks.
  void lay_out_in_row_order(const AgentTable& t);

  double dt_;
  bool walls_;
  uint64_t tick_ = 0;
  // Per agent measured, in order of first appearance: its live track's slot, or where its
  // closed score is.
  std::vector<uint32_t> where_;
  std::vector<AgentScore> closed_;          // the scores of agents no longer measured
  mutable std::vector<AgentScore> scores_;  // scores()'s answer
  // Every id measured so far -> its place in where_ (never erased: an agent closed on arrival
  // stays known).
  static constexpr uint32_t kUnknown = UINT32_MAX;
  FlatMap<uint32_t, kUnknown> known_;
  // The agents measured now: their tracks in slots (reused once closed). Each tick visits every
  // row, so a row remembers its slot: rows change only when the table reorders them or agents
  // leave or enter (then the slot's track is closed or another agent's), and the id lookup (a
  // cache miss per agent at 10^5 agents and more) is left for those. After a tick in which many
  // rows changed (the table put its rows in curve order), the tracks are laid out again in row
  // order, so that the next ticks walk them in memory order.
  std::vector<Track> tracks_;
  std::vector<uint32_t> free_slots_;
  std::vector<uint32_t> row_slot_;
  std::vector<uint8_t> pending_;  // per row, scratch of tick(): left for its one-thread pass
  static constexpr std::size_t kTickGrain = 8192;          // rows per chunk of tick()
  std::set<std::pair<uint64_t, uint64_t>> open_pairs_;     // agent ids, smaller first
  std::set<std::pair<uint64_t, int64_t>> open_obstacles_;  // id, obstacle (-1..-4: walls)
};

}  // namespace crowddb::metrics
