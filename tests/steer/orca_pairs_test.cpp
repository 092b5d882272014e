// ORCA's pass over the neighbours four at a time (pair_lanes: AVX2, chosen at run time in a
// default build) against the reference one at a time (first_or_ask, pair_rest, pair_one): the
// same entries to the bit, on random neighbours and on the cases each rule distinguishes
// (yielding, out before in asked, equal and infinite paths left, ranks beyond 2^63, the one
// ahead deciding or not, coincident centres, contacts on and beyond a tick's reach, horizons
// below a tick and beyond tau, standing wishes, caps on and off, and now and then NaN, -0.0 and
// infinities, for the comparisons' unordered and signed-zero cases), for lists of every length
// padded the way orca pads them.
#include "steer/orca_pairs.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <vector>

#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "util/rng.hpp"

namespace crowddb::steer {
namespace {

bool pairs_same_bits(double a, double b) {
  return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b);
}

// Random records for n rows, with the values the rules compare drawn from few choices so that
// ties, equal goals and crossings of goals come up often.
struct PairTable {
  std::vector<sim::AheadInput> heading;
  std::vector<Peer> peer;
  std::vector<uint8_t> yielding;
  std::vector<double> wish_x, wish_y;
  PairColumns columns() const {
    return {heading.data(), peer.data(), yielding.data(), wish_x.data(), wish_y.data()};
  }
};

double pair_pick_of(Rng& rng, std::initializer_list<double> values) {
  return *(values.begin() + rng.below(values.size()));
}

PairTable random_pair_table(Rng& rng, std::size_t n) {
  PairTable t;
  t.heading.resize(n);
  t.peer.resize(n);
  t.yielding.resize(n);
  t.wish_x.resize(n);
  t.wish_y.resize(n);
  // Now and then a value no crowd should hold, for the comparisons' NaN and signed-zero cases:
  // NaN, -0.0, infinities.
  const auto odd = [&](double usual) {
    return rng.below(40) ? usual : pair_pick_of(rng, {NAN, -0.0, 0.0, INFINITY, -INFINITY});
  };
  for (std::size_t j = 0; j < n; ++j) {
    sim::AheadInput& h = t.heading[j];
    // Positions on a coarse grid now and then: coincident centres, equal distances.
    h.x = odd(rng.below(4) ? rng.uniform(-3, 3) : 0.5 * static_cast<double>(rng.below(5)));
    h.y = odd(rng.below(4) ? rng.uniform(-3, 3) : 0.5 * static_cast<double>(rng.below(5)));
    const double a = rng.uniform(0, 6.283185307179586);
    h.way_x = odd(rng.below(8) ? std::cos(a) : 0);
    h.way_y = odd(rng.below(8) ? std::sin(a) : 0);
    h.goal_x = odd(rng.uniform(-20, 20));
    h.goal_y = odd(rng.below(6) ? rng.uniform(-20, 20) : 0);
    h.goal2 = h.goal_x * h.goal_x + h.goal_y * h.goal_y;
    h.goal = static_cast<uint32_t>(rng.below(4));
    h.left_goal = rng.below(3) ? ~0u : static_cast<uint32_t>(rng.below(4));
    Peer& p = t.peer[j];
    p.vx = odd(rng.uniform(-1.5, 1.5));
    p.vy = odd(rng.uniform(-1.5, 1.5));
    p.avoid_x = odd(rng.uniform(-1.5, 1.5));
    p.avoid_y = odd(rng.uniform(-1.5, 1.5));
    p.radius = pair_pick_of(rng, {0.2, 0.25, 0.3, rng.uniform(0.1, 0.5)});
    p.arrive = odd(pair_pick_of(rng, {INFINITY, 0.01, 0.1, 1.0, 2.0, 5.0, rng.uniform(0, 4)}));
    p.remaining = odd(pair_pick_of(rng, {INFINITY, 1.0, 2.0, rng.uniform(0, 30)}));
    p.rank = rng.below(2) ? rng.next() : (uint64_t{1} << 63) + rng.below(3);
    t.yielding[j] = rng.below(8) == 0;
    t.wish_x[j] = odd(rng.below(6) ? rng.uniform(-1.5, 1.5) : 0);
    t.wish_y[j] = odd(rng.below(6) ? rng.uniform(-1.5, 1.5) : 0);
  }
  return t;
}

struct PairEntries {
  std::vector<double> px, py, vx, vy, r, tau, share, cpx, cpy, cnx, cny;
  std::vector<uint8_t> contact, caps;
  std::vector<uint16_t> lanes;
  explicit PairEntries(std::size_t m)
      : px(m),
        py(m),
        vx(m),
        vy(m),
        r(m),
        tau(m),
        share(m),
        cpx(m),
        cpy(m),
        cnx(m),
        cny(m),
        contact(m),
        caps(m),
        lanes(m / 4 + 1) {}
  PairOut out() {
    return {px.data(),  py.data(),      vx.data(),   vy.data(),   r.data(),
            tau.data(), share.data(),   cpx.data(),  cpy.data(),  cnx.data(),
            cny.data(), contact.data(), caps.data(), lanes.data()};
  }
};

TEST(OrcaPairs, LanesMatchTheReferenceBitForBit) {
  if (!pair_lanes_avx2()) {
    std::cout << "[ note ] no lanes for the pass over the neighbours on this CPU\n";
    GTEST_SKIP();
  }
  Rng rng(20261204);
  uint64_t compared = 0, asked = 0, contacts = 0, capped = 0, yielded = 0, decided_by_place = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const std::size_t n = 2 + rng.below(30);
    const PairTable t = random_pair_table(rng, n);
    const auto i = static_cast<std::size_t>(rng.below(n));
    const double dt = pair_pick_of(rng, {0.1, 0.25, 0.05});
    const double max_speed = rng.uniform(0.5, 3);
    PairRow row{};
    row.heading = &t.heading[i];
    row.peer = &t.peer[i];
    row.yielding = t.yielding[i];
    row.x = t.heading[i].x;
    row.y = t.heading[i].y;
    row.r = t.peer[i].radius;
    row.vx = t.peer[i].vx;
    row.vy = t.peer[i].vy;
    row.reach = 2 * dt * max_speed;
    row.beyond = row.reach + kSkin + row.r;
    row.dt = dt;
    row.tau = pair_pick_of(rng, {2.0, 0.5, 0.01});  // (below a tick: the clamp's bounds cross)
    row.hi_share = pair_pick_of(rng, {0.5, 0.8, 1.0});
    row.lo_share = 1 - row.hi_share;
    row.headway = static_cast<int>(rng.below(2));
    row.gap = static_cast<int>(rng.below(2));
    if (row.headway | row.gap) {
      const double a = rng.uniform(0, 6.283185307179586);
      row.ux = std::cos(a);
      row.uy = std::sin(a);
      row.cap_reach = rng.uniform(0, 2) + row.r;
    }
    // The list: any rows but i, repeats allowed (orca pads with repeats), padded to fours.
    const std::size_t m = rng.below(14);
    const std::size_t mp = (m + 3) & ~std::size_t{3};
    std::vector<uint32_t> rows(mp);
    for (std::size_t a = 0; a < m; ++a) {
      auto j = static_cast<uint32_t>(rng.below(n));
      if (j == i) j = static_cast<uint32_t>((j + 1) % n);
      rows[a] = j;
    }
    for (std::size_t a = m; a < mp; ++a) rows[a] = rows[m - 1];
    PairEntries want(mp), got(mp);
    pair_lanes(row, t.columns(), rows.data(), mp, got.out());
    for (std::size_t a = 0; a < m; ++a) {
      const uint32_t j = rows[a];
      const int f = first_or_ask(row, t.heading[j], t.peer[j], t.yielding[j]);
      const uint32_t flags = got.lanes[a / 4], l = a % 4;
      ASSERT_EQ((flags >> (12 + l) & 1) != 0, f == kAsk) << "trial " << trial << " entry " << a;
      if (f == kAsk) {
        ++asked;
        continue;
      }
      yielded += row.yielding != t.yielding[j];
      bool place = false;
      decided_by_place += row.yielding == t.yielding[j] && std::isfinite(t.peer[i].remaining) &&
                          std::isfinite(t.peer[j].remaining) &&
                          sim::ahead(t.heading[i], t.heading[j], place);
      pair_one(row, t.columns(), j, f != 0, want.out(), a);
      const auto where = ::testing::Message() << "trial " << trial << " entry " << a;
      EXPECT_TRUE(pairs_same_bits(got.px[a], want.px[a])) << where;
      EXPECT_TRUE(pairs_same_bits(got.py[a], want.py[a])) << where;
      EXPECT_TRUE(pairs_same_bits(got.vx[a], want.vx[a])) << where;
      EXPECT_TRUE(pairs_same_bits(got.vy[a], want.vy[a])) << where;
      EXPECT_TRUE(pairs_same_bits(got.r[a], want.r[a])) << where;
      EXPECT_TRUE(pairs_same_bits(got.tau[a], want.tau[a])) << where;
      EXPECT_TRUE(pairs_same_bits(got.share[a], want.share[a])) << where;
      ASSERT_EQ(flags >> l & 1, want.contact[a]) << where;
      if (want.contact[a]) {
        ++contacts;
        EXPECT_TRUE(pairs_same_bits(got.cpx[a], want.cpx[a])) << where;
        EXPECT_TRUE(pairs_same_bits(got.cpy[a], want.cpy[a])) << where;
        EXPECT_TRUE(pairs_same_bits(got.cnx[a], want.cnx[a])) << where;
        EXPECT_TRUE(pairs_same_bits(got.cny[a], want.cny[a])) << where;
      }
      ASSERT_EQ((flags >> (4 + l) & 1) | (flags >> (8 + l) & 1) << 1, want.caps[a]) << where;
      capped += want.caps[a] != 0;
      ++compared;
    }
  }
  // Each case comes up (the trials are not all of one kind).
  EXPECT_GT(compared, 60000u);
  EXPECT_GT(asked, 1000u);
  EXPECT_GT(contacts, 1000u);
  EXPECT_GT(capped, 1000u);
  EXPECT_GT(yielded, 1000u);
  EXPECT_GT(decided_by_place, 1000u);
}

// People coming out of a goal area on their way on, into a crowd heading for it: the pairs where
// out before in decides, which the lanes leave to the reference.
constexpr const char* kPairsOutAndIn = R"({
  "name": "out-before-in", "bounds": [0, 0, 30, 16], "dt": 0.1, "seed": 5, "duration": 30,
  "goals": [{"name": "A", "area": [[12, 6], [16, 6], [16, 10], [12, 10]]},
            {"name": "B", "area": [[28, 6], [30, 6], [30, 10], [28, 10]]}],
  "groups": [
    {"name": "through", "count": 40, "radius": [0.2, 0.25], "pref_speed": [1.1, 1.5],
     "placement": {"type": "uniform", "region": [8, 4, 12, 12], "gap": 0.1}, "goal": ["A", "B"]},
    {"name": "into", "count": 40, "radius": [0.2, 0.25], "pref_speed": [1.1, 1.5],
     "placement": {"type": "uniform", "region": [18, 4, 24, 12], "gap": 0.1}, "goal": "A"}]})";

// Whole runs of orca with the lanes and with the reference on every entry: the same state after
// every tick (shipped scenarios with yielding and the stream gap, the one above, and each with
// the headway on).
TEST(OrcaPairs, RunsWithAndWithoutTheLanesAreTheSame) {
  if (!pair_lanes_avx2()) GTEST_SKIP() << "no lanes on this CPU: only the reference runs";
  const std::string dir = std::string(CROWDDB_SOURCE_DIR) + "/scenarios/";
  for (const std::string name : {"out-and-in", "bottleneck.json", "crossing.json", "circle.json"})
    for (const double time_gap : {0.0, 0.4}) {
      std::vector<uint64_t> hashes[2];
      for (const bool reference : {false, true}) {
        Scenario sc = name == "out-and-in" ? parse_scenario(kPairsOutAndIn, "out-and-in.json")
                                           : load_scenario(dir + name);
        sc.config.steering.model = "orca";
        sc.config.steering.orca.time_gap = time_gap;
        use_pair_reference(reference);
        Simulation sim(std::move(sc.world), sc.config);
        for (int k = 0; k < 150; ++k) hashes[reference].push_back(sim.step().state_hash);
        use_pair_reference(false);
      }
      EXPECT_EQ(hashes[0], hashes[1]) << name << " time_gap " << time_gap;
    }
}

TEST(OrcaPairs, LanesAreChosenWhereTheCpuHasThem) {
#if CROWDDB_TEST_AVX2_DISPATCH
  EXPECT_EQ(pair_lanes_avx2(), __builtin_cpu_supports("avx2") != 0);
#else
  if (!pair_lanes_avx2()) std::cout << "[ note ] no lanes for the pass over the neighbours\n";
#endif
}

}  // namespace
}  // namespace crowddb::steer
