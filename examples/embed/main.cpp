// Embedding crowddb: a corridor with two goals, agents walking between them; mid-run one agent
// is added, one removed and one sent to the other goal, and every agent's position is read back
// from the agents table. Prints one line per second of simulated time; exits 1 if anything is
// off (so CI can run it).
#include <crowddb/simulation.hpp>
#include <crowddb/world.hpp>
#include <cstdio>
#include <vector>

int main() try {
  using namespace crowddb;

  // A 20 m x 6 m corridor (its bounds are walls), a goal at each end.
  World world(Bounds{0, 0, 20, 6});
  const uint32_t east =
      world.add_goal(Goal{.name = "east", .x = 19, .y = 3, .arrival_radius = 0.5});
  const uint32_t west = world.add_goal(Goal{.name = "west", .x = 1, .y = 3, .arrival_radius = 0.5});

  // Ten agents each way. Inserts are validated now and applied when the simulation starts.
  std::vector<AgentId> ids;
  for (int i = 0; i < 10; ++i) {
    const double y = 0.6 + 0.5 * i;
    ids.push_back(world.insert(AgentSpec{.x = 2, .y = y, .radius = 0.2, .goal = east}));
    ids.push_back(world.insert(AgentSpec{.x = 18, .y = y, .radius = 0.2, .goal = west}));
  }

  SimConfig config;  // the defaults: ORCA steering, dt 0.1 s, agents leave when they arrive
  config.threads = 2;
  Simulation sim(std::move(world), config);

  AgentId late{};
  for (int tick = 1; tick <= 400 && sim.world().agents().size() > 0; ++tick) {
    if (tick == 20) {
      // Changes go through world(): they are buffered and applied at the start of the next step.
      late = sim.world().insert(AgentSpec{.x = 10, .y = 5.5, .radius = 0.2, .goal = west});
      sim.world().erase(ids[0]);           // the first eastbound agent leaves
      sim.world().retarget(ids[1], east);  // the first westbound agent turns round
    }
    const TickMetrics& m = sim.step();
    if (m.overlapping_pairs != 0) {
      std::fprintf(stderr, "tick %llu: %zu overlapping pairs\n",
                   static_cast<unsigned long long>(m.tick), m.overlapping_pairs);
      return 1;
    }
    if (tick % 10 == 0) {
      // The agents table is columns: x[i], y[i] ... of the agent in row i (id[i] says which).
      const AgentTable& a = sim.world().agents();
      double mean_x = 0;
      for (std::size_t i = 0; i < a.size(); ++i) mean_x += a.x[i];
      std::printf("t = %4.1f s: %2zu agents walking, %2zu arrived, mean x %.2f m\n", sim.time(),
                  a.size(), sim.arrived_total(), a.size() ? mean_x / double(a.size()) : 0.0);
    }
    if (tick == 21 && (sim.world().contains(ids[0]) || !sim.world().contains(late))) {
      std::fprintf(stderr, "the erase or the insert was not applied\n");
      return 1;
    }
  }
  // Everyone arrives: 10 + 10 - 1 erased + 1 inserted.
  if (!sim.world().agents().empty() || sim.arrived_total() != 20) {
    std::fprintf(stderr, "%zu agents still walking, %zu arrived (expected 0 and 20)\n",
                 sim.world().agents().size(), sim.arrived_total());
    return 1;
  }
  std::printf("all 20 arrived after %.1f s, state hash %016llx\n", sim.time(),
              static_cast<unsigned long long>(sim.state_hash()));
  return 0;
} catch (const crowddb::Error& e) {
  std::fprintf(stderr, "embed: %s\n", e.what());
  return 1;
}
