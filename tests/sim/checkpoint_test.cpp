// Checkpoints (Simulation::save_state / restore_state): a run restored from a checkpoint
// continues bit-identically to the run that saved it, on any thread count; damaged or foreign
// checkpoints are refused with Error(input), never a crash.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "crowddb/error.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "support/cli.hpp"
#include "util/byte_codec.hpp"

namespace crowddb {
namespace {

Simulation build(const std::string& name, int threads, std::vector<std::string> overrides = {}) {
  // A name with a slash is a path in the source tree (tests/data/...), else a shipped scenario.
  const std::string file =
      name.find('/') != std::string::npos ? name + ".json" : "scenarios/" + name + ".json";
  Scenario sc = load_scenario(test::source_path(file), LoadOptions{{}, std::move(overrides)});
  sc.config.threads = threads;
  return Simulation(std::move(sc.world), sc.config);
}

// The uninterrupted run's hash after every tick, and its checkpoint at each of `at`.
struct Reference {
  std::vector<uint64_t> hash;  // [tick]
  std::vector<std::string> saved;
};

Reference run_reference(const std::string& name, uint64_t ticks, const std::vector<uint64_t>& at,
                        const std::vector<std::string>& overrides = {}) {
  Simulation sim = build(name, 1, overrides);
  Reference r;
  r.hash.push_back(sim.state_hash());
  std::size_t next = 0;
  for (uint64_t t = 0;; ++t) {
    while (next < at.size() && at[next] == t) {
      r.saved.push_back(sim.save_state());
      ++next;
    }
    if (t == ticks) break;
    r.hash.push_back(sim.step().state_hash);
  }
  return r;
}

// Scenarios with sources, navigation (searches in flight across the checkpoint), idling
// arrivals, goal sequences and stalemates. The bottleneck's people of radius 0.3 (the 0.5 class,
// whose mesh has no 1.2 m door) find the door on the narrow mesh: those searches are in flight too.
TEST(Checkpoint, ARestoredRunContinuesBitIdenticallyOnAnyThreadCount) {
  struct Case {
    std::string name;
    uint64_t ticks;
    std::vector<uint64_t> at;
    std::vector<std::string> overrides;
  };
  const Case cases[] = {
      {"airport", 140, {0, 1, 97}, {}},
      {"serpentine", 300, {0, 5, 150}, {}},
      {"bottleneck", 200, {3, 120}, {}},
      {"bottleneck", 200, {2, 3, 151}, {"groups.0.radius=0.3", "groups.0.count=60"}},
      {"crossing", 260, {2, 200}, {"goals.0.wait=[1, 4]", "goals.1.wait=2"}},  // people waiting
      // goal sequences: the goal each left (out before in) crosses the checkpoint
      {"crossing",
       420,
       {2, 330},
       {R"(groups.0.goal=["east", "north"])", R"(groups.1.goal=["north", "east"])"}},
      // people stalled in a passage: searches round them (with congestion costs) dispatched in
      // ticks 301 and 310, due two ticks later: in flight at 301, 302 and 310
      {"tests/data/passage", 340, {301, 302, 310}, {}},
  };
  for (const Case& c : cases) {
    const Reference ref = run_reference(c.name, c.ticks, c.at, c.overrides);
    for (std::size_t k = 0; k < c.at.size(); ++k)
      for (int threads : {1, 2}) {
        Simulation sim = build(c.name, threads, c.overrides);
        sim.restore_state(ref.saved[k]);
        ASSERT_EQ(sim.ticks(), c.at[k]);
        ASSERT_EQ(sim.state_hash(), ref.hash[c.at[k]]);
        // Saving again gives the same bytes: nothing is lost or invented on the way.
        EXPECT_EQ(sim.save_state(), ref.saved[k]) << c.name << " at " << c.at[k];
        for (uint64_t t = c.at[k] + 1; t <= c.ticks; ++t)
          ASSERT_EQ(sim.step().state_hash, ref.hash[t])
              << c.name << ": restored at tick " << c.at[k] << " on " << threads
              << " threads, differs at tick " << t;
      }
  }
}

// The checkpoint streamed to a sink (as crowddb run writes it into its output) is the
// checkpoint returned whole, byte for byte: 8,000 agents, a state of several pieces.
TEST(Checkpoint, StreamedIsTheSameBytes) {
  Scenario sc = parse_scenario(R"({"bounds": [0, 0, 400, 400], "seed": 4,
    "goals": [{"name": "g", "x": 399, "y": 200}],
    "groups": [{"count": 8000, "radius": 0.3, "goal": "g",
                "placement": {"type": "uniform", "region": [0, 0, 400, 400]}}]})",
                               "big.json");
  sc.config.threads = 2;
  Simulation sim(std::move(sc.world), sc.config);
  for (int t = 0; t < 10; ++t) sim.step();
  std::string streamed;
  std::size_t pieces = 0;
  sim.save_state([&](std::string_view piece) {
    streamed.append(piece);
    ++pieces;
  });
  EXPECT_TRUE(streamed == sim.save_state());
  EXPECT_GT(pieces, 1u);
}

TEST(Checkpoint, CountersContinueToo) {
  Simulation a = build("airport", 2);
  for (int t = 0; t < 150; ++t) a.step();
  Simulation b = build("airport", 1);
  b.restore_state(a.save_state());
  EXPECT_EQ(b.arrived_total(), a.arrived_total());
  EXPECT_EQ(b.entered_total(), a.entered_total());
  EXPECT_EQ(b.waiting_to_enter(), a.waiting_to_enter());
  for (int t = 0; t < 100; ++t) {
    const TickMetrics& ma = a.step();
    const TickMetrics& mb = b.step();
    ASSERT_EQ(ma.state_hash, mb.state_hash);
    ASSERT_EQ(ma.stalled, mb.stalled);
    ASSERT_EQ(ma.longest_stall, mb.longest_stall);
    ASSERT_EQ(ma.entered, mb.entered);
  }
  EXPECT_EQ(b.arrived_total(), a.arrived_total());
}

std::string error_of(Simulation& sim, std::string_view bytes) {
  try {
    sim.restore_state(bytes, "cp");
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::input);
    return e.what();
  }
  return "";
}

TEST(Checkpoint, ForeignAndDamagedCheckpointsAreRefused) {
  Simulation source = build("serpentine", 1);
  for (int t = 0; t < 40; ++t) source.step();
  const std::string bytes = source.save_state();

  Simulation other = build("u_trap", 1);
  EXPECT_NE(error_of(other, bytes).find("another scenario"), std::string::npos);
  Simulation reseeded = build("serpentine", 1, {"seed=7"});
  EXPECT_NE(error_of(reseeded, bytes).find("another scenario"), std::string::npos);
  Simulation sim = build("serpentine", 1);
  EXPECT_NE(error_of(sim, "").find("cp: ends too early"), std::string::npos);
  EXPECT_NE(error_of(sim, "SQLite format 3").find("cp:"), std::string::npos);

  // Every truncation and every flipped byte is refused (the checksum). Behind the checksum the
  // parser checks every length and value: with the checksum made right again, a flipped byte is
  // refused or restores a valid state (a flipped bit in a column the hash does not cover), and
  // never crashes (the sanitizer build runs this too).
  // (One simulation takes them all: a refused restore may leave it half restored, which the
  // next attempt overwrites.)
  for (std::size_t n = 0; n < bytes.size(); ++n)
    ASSERT_NE(error_of(sim, std::string_view(bytes).substr(0, n)), "") << "truncated at " << n;
  int refused = 0;
  const std::size_t body = bytes.size() - 8;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::string flipped = bytes;
    flipped[i] = static_cast<char>(flipped[i] ^ 0x5a);
    ASSERT_NE(error_of(sim, flipped).find("cp:"), std::string::npos) << "flipped at " << i;
    if (i >= body) continue;
    ByteWriter sum;  // the checksum of the damaged body
    sum.u64(checksum(std::string_view(flipped).substr(0, body)));
    flipped.replace(body, 8, sum.bytes());
    refused += !error_of(sim, flipped).empty();
  }
  EXPECT_GT(refused, static_cast<int>(body) / 10);
  sim.restore_state(bytes);  // and the intact bytes still restore
  EXPECT_EQ(sim.state_hash(), source.state_hash());
}

}  // namespace
}  // namespace crowddb
