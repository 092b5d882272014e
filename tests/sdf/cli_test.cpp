// The sdfsched binary: exit codes, the JSON shapes of DESIGN §9, one-line errors.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "helpers.hpp"

namespace sdf {
namespace {

using nlohmann::json;

std::string graph(const std::string& name) {
  return "'" + test::data(name) + "'";
}

bool one_line(const std::string& s) {
  return !s.empty() && s.back() == '\n' && s.find('\n') == s.size() - 1;
}

TEST(SdfschedCli, RepetitionsJson) {
  const test::Cli r = test::sdfsched("repetitions " + graph("cd2dat.xml") + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["consistent"], true);
  EXPECT_EQ(j["repetitions"].dump(), R"({"A":147,"B":147,"C":98,"D":28,"E":32,"F":160})");
  const test::Cli big = test::sdfsched("repetitions " + graph("chain65537.json") + " --json");
  EXPECT_EQ(json::parse(big.out)["repetitions"]["C"].get<uint64_t>(), 4295098369ull);
  const test::Cli text = test::sdfsched("repetitions " + graph("cd2dat.json"));
  EXPECT_EQ(text.out, "A 147\nB 147\nC 98\nD 28\nE 32\nF 160\n");
}

TEST(SdfschedCli, InconsistentAndOverflow) {
  const test::Cli r = test::sdfsched("repetitions " + graph("inconsistent.json") + " --json");
  EXPECT_EQ(r.status, 1);
  const json j = json::parse(r.out);
  EXPECT_EQ(j["consistent"], false);
  EXPECT_TRUE(j["channel"].is_string());
  EXPECT_TRUE(one_line(r.err)) << r.err;
  const test::Cli o = test::sdfsched("repetitions " + graph("overflow.json"));
  EXPECT_EQ(o.status, 1);
  EXPECT_EQ(o.out, "");
  EXPECT_NE(o.err.find("does not fit in 64 bits"), std::string::npos);
  EXPECT_TRUE(one_line(o.err));
  // A token count that overflows while scheduling names the file and the channel.
  for (const char* policy : {"static", "online", "online-bounded"}) {
    const test::Cli t =
        test::sdfsched("schedule " + graph("token_overflow.json") + " --policy " + policy);
    EXPECT_EQ(t.status, 1) << policy;
    EXPECT_NE(t.err.find("token_overflow.json: the token count on channel 'ab' does not fit in 64 "
                         "bits"),
              std::string::npos)
        << policy << ": " << t.err;
    EXPECT_TRUE(one_line(t.err)) << t.err;
  }
}

TEST(SdfschedCli, ScheduleStaticJson) {
  const test::Cli r =
      test::sdfsched("schedule " + graph("cd2dat.json") + " --policy static --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["outcome"], "returns");
  EXPECT_EQ(j["valid"], true);
  ASSERT_EQ(j["firings"].size(), 612u);
  EXPECT_EQ(j["firings"][0], "A");
  EXPECT_EQ(j["firings"][611], "F");
  EXPECT_EQ(j["buffers"]["B->C#0"], 294);
  EXPECT_EQ(j["fairness"]["max"], 0);
  EXPECT_TRUE(j["fairness"]["mean"].is_number());
}

TEST(SdfschedCli, ScheduleOnlineOutcomesAndExitStatus) {
  const test::Cli p =
      test::sdfsched("schedule " + graph("cd2dat.json") + " --policy online --json");
  EXPECT_EQ(p.status, 3);
  const json j = json::parse(p.out);
  EXPECT_EQ(j["outcome"], "periodic");
  EXPECT_EQ(j["valid"], false);
  EXPECT_EQ(j["transient"].size(), 1u);
  EXPECT_EQ(j["cycle"].size(), 1224u);
  EXPECT_EQ(j["cycle_repetitions"]["F"], 320);
  EXPECT_FALSE(j.contains("firings"));
  const test::Cli u =
      test::sdfsched("schedule " + graph("starved_cycle.json") + " --policy online --json");
  EXPECT_EQ(u.status, 3);
  const json k = json::parse(u.out);
  EXPECT_EQ(k["outcome"], "unbounded");
  EXPECT_EQ(k["channel"], "S->X#0");
  const test::Cli b =
      test::sdfsched("schedule " + graph("cd2dat.json") + " --policy online-bounded --json");
  EXPECT_EQ(b.status, 0);
  const json l = json::parse(b.out);
  EXPECT_EQ(l["outcome"], "returns");
  EXPECT_EQ(l["valid"], true);
  EXPECT_EQ(l["firings"].size(), 612u);
  const test::Cli lim = test::sdfsched("schedule " + graph("cd2dat.json") +
                                       " --policy online --max-decisions 10 --json");
  EXPECT_EQ(lim.status, 3);
  EXPECT_EQ(json::parse(lim.out)["outcome"], "limit");
  const test::Cli one = test::sdfsched("schedule " + graph("chain65537.json") +
                                       " --policy online --firings one --max-decisions 1000");
  EXPECT_EQ(one.status, 3);
  EXPECT_NE(one.out.find("outcome: limit"), std::string::npos);
}

TEST(SdfschedCli, HugePeriodsAreNotListedButStillChecked) {
  const test::Cli r = test::sdfsched("schedule " + graph("chain65537.json") + " --json");
  ASSERT_EQ(r.status, 0);
  const json j = json::parse(r.out);
  EXPECT_TRUE(j["firings"].is_null());
  EXPECT_EQ(j["period_firings"].get<uint64_t>(), 4295163907ull);
  EXPECT_EQ(j["runs"].dump(), R"([["A",1],["B",65537],["C",4295098369]])");
  EXPECT_EQ(j["valid"], true);
}

TEST(SdfschedCli, Deadlock) {
  for (const char* policy : {"static", "online", "online-bounded"}) {
    const test::Cli r =
        test::sdfsched("schedule " + graph("deadlock.json") + " --policy " + policy + " --json");
    EXPECT_EQ(r.status, 1);
    const json j = json::parse(r.out);
    EXPECT_EQ(j["deadlock"], true);
    EXPECT_EQ(j["stuck"].dump(), R"(["P","Q","R"])");
    EXPECT_TRUE(one_line(r.err));
  }
}

TEST(SdfschedCli, SimulateRateChange) {
  const test::Cli r = test::sdfsched("simulate " + graph("cd2dat.json") +
                                     " --rate-change C:4/3@100 --policy online-bounded --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["change"]["actor"], "C");
  EXPECT_EQ(j["consistent_after"], true);
  EXPECT_TRUE(j["firings_until_periodic"].is_number());
  EXPECT_EQ(j["period_valid"], true);
  EXPECT_EQ(j["buffers_before"].size(), 5u);
  EXPECT_EQ(j["buffers_after"].size(), 5u);
  EXPECT_EQ(j["repetitions_after"]["C"].get<uint64_t>() * 4,
            j["repetitions_after"]["D"].get<uint64_t>() * 7);
  const test::Cli s =
      test::sdfsched("simulate " + graph("cd2dat.json") + " --rate-change C:4/3@100 --json");
  EXPECT_EQ(s.status, 0);
  EXPECT_EQ(json::parse(s.out)["firings_until_periodic"], 0);
  const test::Cli inc =
      test::sdfsched("simulate " + graph("crlf_loop.xml") + " --rate-change X:2/1@1 --json");
  EXPECT_EQ(inc.status, 1);
  EXPECT_EQ(json::parse(inc.out)["consistent_after"], false);
}

// The thesis's form (every rate of the actor scaled) and explicit per-channel rates.
TEST(SdfschedCli, SimulateRateChangeForms) {
  const test::Cli f =
      test::sdfsched("simulate " + graph("cd2dat.json") + " --rate-change 'C*2@100' --json");
  ASSERT_EQ(f.status, 0) << f.err;
  const json j = json::parse(f.out);
  EXPECT_EQ(j["change"]["form"], "factor");
  EXPECT_EQ(j["change"]["factor"], "2/1");
  EXPECT_EQ(j["change"]["rates"], json::parse(R"({"B->C#0":{"prd":2,"cns":6},
                                                  "C->D#0":{"prd":4,"cns":7}})"));
  // C's count halves relative to the others: q' = (294, 294, 98, 56, 64, 320) / 2.
  EXPECT_EQ(j["repetitions_after"].dump(), R"({"A":147,"B":147,"C":49,"D":28,"E":32,"F":160})");
  const test::Cli p = test::sdfsched("simulate " + graph("cd2dat.json") +
                                     " --rate-change 'C:C->D#0=4,B->C#0=6@100' --json");
  ASSERT_EQ(p.status, 0) << p.err;
  const json k = json::parse(p.out);
  EXPECT_EQ(k["change"]["form"], "ports");
  EXPECT_EQ(k["repetitions_after"].dump(), j["repetitions_after"].dump());
  const test::Cli half =
      test::sdfsched("simulate " + graph("cd2dat.json") + " --rate-change 'C*1/2@1'");
  EXPECT_EQ(half.status, 1);
  EXPECT_NE(half.err.find("3·1/2 is not a whole number"), std::string::npos) << half.err;
  EXPECT_TRUE(one_line(half.err));
}

// The online rule lets S->X grow on starved_cycle before any change: there is no period to
// measure buffers over, before or after (the text printed a window of the growing run).
TEST(SdfschedCli, SimulateHasNoBuffersBeforeWhenTheOriginalRunIsUnbounded) {
  const std::string args =
      "simulate " + graph("starved_cycle.json") + " --rate-change 'S*2@1' --policy online";
  const test::Cli j = test::sdfsched(args + " --json");
  const test::Cli t = test::sdfsched(args);
  EXPECT_EQ(j.status, 3);
  EXPECT_EQ(t.status, 3);
  const json r = json::parse(j.out);
  EXPECT_EQ(r["outcome_before"], "unbounded");
  EXPECT_EQ(r["channel_before"], "S->X#0");
  EXPECT_TRUE(r["buffers_before"].is_null());
  EXPECT_NE(t.out.find("outcome before the change: unbounded (growing channel 'S->X#0'"),
            std::string::npos)
      << t.out;
  EXPECT_NE(t.out.find("buffers: S->X#0=?->?"), std::string::npos) << t.out;
  // A periodic original run has its buffers and says nothing of its outcome in the text.
  const test::Cli p = test::sdfsched("simulate " + graph("cd2dat.json") +
                                     " --rate-change C:4/3@100 --policy online");
  EXPECT_EQ(p.out.find("outcome before"), std::string::npos) << p.out;
  EXPECT_EQ(p.out.find("=?"), std::string::npos) << p.out;
}

// After a deadlock the text says there is no period, as the JSON form says null.
TEST(SdfschedCli, SimulateTextAgreesWithJsonAfterADeadlock) {
  const std::string g = test::temp_path("cyc.json");
  {
    std::ofstream f(g);
    f << R"({"actors": [{"name": "A"}, {"name": "B"}], "channels": [{"src": "A", "dst": "B",
          "prd": 1, "cns": 1}, {"src": "B", "dst": "A", "prd": 1, "cns": 1, "delay": 1}]})";
  }
  const test::Cli j = test::sdfsched("simulate '" + g + "' --rate-change A:2/2@0 --json");
  const test::Cli t = test::sdfsched("simulate '" + g + "' --rate-change A:2/2@0");
  std::remove(g.c_str());
  EXPECT_EQ(j.status, 1);
  EXPECT_EQ(t.status, 1);
  const json r = json::parse(j.out);
  EXPECT_EQ(r["outcome"], "deadlock");
  EXPECT_TRUE(r["firings_until_periodic"].is_null());
  EXPECT_NE(t.out.find("firings until periodic again: none (not periodic)\nperiod after: none\n"),
            std::string::npos)
      << t.out;
}

// A deadlock after the change names the actors below their count under every policy (the online
// ones used to give an empty list): A's rates tripled, B waits for tokens A cannot send.
TEST(SdfschedCli, SimulateNamesTheStuckActorsUnderEveryPolicy) {
  const std::string g = test::temp_path("cyc3.json");
  {
    std::ofstream f(g);
    f << R"({"actors": [{"name": "A"}, {"name": "B"}, {"name": "C"}], "channels": [
          {"src": "A", "dst": "B", "prd": 1, "cns": 1},
          {"src": "B", "dst": "A", "prd": 1, "cns": 1, "delay": 1},
          {"src": "C", "dst": "A", "prd": 1, "cns": 1}]})";
  }
  for (const char* policy : {"static", "online-bounded"}) {
    const std::string args =
        "simulate '" + g + "' --rate-change 'B*3/1@0' --policy " + std::string(policy);
    const test::Cli j = test::sdfsched(args + " --json");
    const test::Cli t = test::sdfsched(args);
    EXPECT_EQ(j.status, 1) << policy;
    const json r = json::parse(j.out);
    EXPECT_EQ(r["outcome"], "deadlock") << policy;
    EXPECT_EQ(r["stuck"], json({"A", "B"})) << policy;
    EXPECT_NE(t.out.find("stuck: A B\n"), std::string::npos) << policy << t.out;
  }
  std::remove(g.c_str());
}

TEST(SdfschedCli, ConvertRoundTrips) {
  const std::string out = test::temp_path("g.xml");
  const test::Cli x =
      test::sdfsched("convert " + graph("cd2dat.json") + " --to sdf3 -o '" + out + "'");
  ASSERT_EQ(x.status, 0) << x.err;
  const test::Cli back = test::sdfsched("repetitions '" + out + "' --json");
  std::remove(out.c_str());
  EXPECT_EQ(json::parse(back.out)["repetitions"]["F"], 160);
  const test::Cli j = test::sdfsched("convert " + graph("cd2dat.xml") + " --to json");
  EXPECT_EQ(json::parse(j.out)["channels"][0]["name"], "ab");
  const test::Cli d = test::sdfsched("convert " + graph("cd2dat.xml") + " --to dot");
  EXPECT_NE(d.out.find("\"A\" -> \"B\""), std::string::npos);
}

TEST(SdfschedCli, ThroughputAndHsdf) {
  const test::Cli j = test::sdfsched("throughput " + graph("timed_modem.xml") + " --json");
  ASSERT_EQ(j.status, 0) << j.err;
  const json t = json::parse(j.out);
  EXPECT_EQ(t["throughput"], "1/4");
  EXPECT_EQ(t["critical_cycle"].dump(), R"(["filt_0","filt_1","sink_0","src_0"])");
  EXPECT_EQ(t["cycle_time"], 8);
  EXPECT_EQ(t["cycle_tokens"], 2);
  const test::Cli text = test::sdfsched("throughput " + graph("timed_modem.xml"));
  EXPECT_EQ(text.out.substr(0, text.out.find('\n')),
            "throughput: 1/4 iterations per time unit (0.25; one iteration every 4)");
  for (const char* m : {"state-space", "mcm"})
    EXPECT_EQ(json::parse(
                  test::sdfsched("throughput " + graph("timed_modem.xml") + " --json --method " + m)
                      .out)["throughput"],
              "1/4");
  // cd2dat has one time: the others need a default.
  const test::Cli missing = test::sdfsched("throughput " + graph("cd2dat.xml"));
  EXPECT_EQ(missing.status, 1);
  EXPECT_TRUE(one_line(missing.err));
  EXPECT_NE(missing.err.find("actor 'B' has no execution time"), std::string::npos) << missing.err;
  // An acyclic chain is unbounded; a deadlock is 0 and names the cycle without tokens.
  EXPECT_EQ(
      json::parse(test::sdfsched("throughput " + graph("cd2dat.xml") + " --json --default-time 1")
                      .out)["throughput"],
      "unbounded");
  const json d = json::parse(
      test::sdfsched("throughput " + graph("deadlock.json") + " --json --default-time 1").out);
  EXPECT_EQ(d["throughput"], "0");
  EXPECT_FALSE(d["deadlock_cycle"].empty());
  // The expansion: one actor per firing, consistent with q = 1 everywhere.
  const std::string out = test::temp_path("h.json");
  ASSERT_EQ(
      test::sdfsched("convert " + graph("timed_modem.xml") + " --to hsdf -o '" + out + "'").status,
      0);
  const test::Cli q = test::sdfsched("repetitions '" + out + "' --json");
  std::remove(out.c_str());
  EXPECT_EQ(json::parse(q.out)["repetitions"].dump(),
            R"({"filt_0":1,"filt_1":1,"sink_0":1,"src_0":1})");
}

TEST(SdfschedCli, BuffersAndMinBufferSchedule) {
  // CD-to-DAT: a chain, where every channel's lower bound p + c − gcd(p, c) suffices.
  const test::Cli m = test::sdfsched("buffers " + graph("cd2dat.json") + " --json");
  ASSERT_EQ(m.status, 0) << m.err;
  const json j = json::parse(m.out);
  EXPECT_EQ(j["lower_bound_size"], 32);
  EXPECT_EQ(j["size"], 32);
  EXPECT_EQ(j["distributions"].dump(),
            R"([{"A->B#0":1,"B->C#0":4,"C->D#0":8,"D->E#0":14,"E->F#0":5}])");
  // The trade-off of the timed modem rises to its throughput with unbounded channels.
  const test::Cli p = test::sdfsched("buffers " + graph("timed_modem.xml") + " --pareto --json");
  ASSERT_EQ(p.status, 0) << p.err;
  const json k = json::parse(p.out);
  EXPECT_EQ(k["max_throughput"], "1/4");
  EXPECT_EQ(k["complete"], true);
  EXPECT_EQ(k["points"].back()["throughput"], "1/4");
  EXPECT_EQ(k["points"][0]["size"], 12);
  // A limit stops the search: the points so far, `complete` false, exit 3.
  const test::Cli lim = test::sdfsched("buffers " + graph("timed_modem.xml") +
                                       " --pareto --max-distributions 2 --json");
  EXPECT_EQ(lim.status, 3);
  const json l = json::parse(lim.out);
  EXPECT_EQ(l["complete"], false);
  EXPECT_NE(l["stopped"].get<std::string>().find("more than 2 storage distributions"),
            std::string::npos);
  EXPECT_EQ(l["points"].size(), 2u);
  // Also when the limit comes before the first point: on a ring whose channels are full at
  // the lower bounds, the first distribution deadlocks and gives no point.
  const test::Cli none = test::sdfsched("buffers " + graph("full_ring.json") +
                                        " --pareto --max-distributions 1 --json");
  EXPECT_EQ(none.status, 3) << none.err;
  const json n = json::parse(none.out);
  EXPECT_EQ(n["complete"], false);
  EXPECT_EQ(n["points"].size(), 0u);
  EXPECT_NE(n["stopped"].get<std::string>().find("more than 1 storage distributions"),
            std::string::npos);
  // --max-size binds minimal storage too: nothing of CD-to-DAT's minimal 32 fits in 31.
  const test::Cli small = test::sdfsched("buffers " + graph("cd2dat.json") + " --max-size 31");
  EXPECT_EQ(small.status, 3);
  EXPECT_TRUE(one_line(small.err));
  EXPECT_NE(small.err.find("no deadlock-free distribution of size at most 31 (the size limit)"),
            std::string::npos)
      << small.err;
  EXPECT_EQ(test::sdfsched("buffers " + graph("cd2dat.json") + " --max-size 32").status, 0);
  // The schedule within the minimal distribution: valid, buffers within it, 32 in all.
  const test::Cli s =
      test::sdfsched("schedule " + graph("cd2dat.json") + " --policy min-buffer --json");
  ASSERT_EQ(s.status, 0) << s.err;
  const json t = json::parse(s.out);
  EXPECT_EQ(t["policy"], "min-buffer");
  EXPECT_EQ(t["valid"], true);
  EXPECT_EQ(t["capacities"].dump(), j["distributions"][0].dump());
  uint64_t sum = 0;
  for (const auto& [name, v] : t["buffers"].items()) sum += v.get<uint64_t>();
  EXPECT_EQ(sum, 32u);
  // A graph that deadlocks whatever the capacities, and one without execution times.
  const test::Cli d = test::sdfsched("buffers " + graph("deadlock.json"));
  EXPECT_EQ(d.status, 1);
  EXPECT_TRUE(one_line(d.err));
  EXPECT_NE(d.err.find("deadlocks whatever the capacities (stuck: 'P', 'Q', 'R')"),
            std::string::npos)
      << d.err;
  const test::Cli u = test::sdfsched("buffers " + graph("cd2dat.xml") + " --pareto");
  EXPECT_EQ(u.status, 1);
  EXPECT_NE(u.err.find("actor 'B' has no execution time"), std::string::npos) << u.err;
}

TEST(SdfschedCli, StatsAndLatency) {
  const test::Cli s = test::sdfsched("stats " + graph("timed_modem.xml") + " --json");
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_EQ(s.out,
            R"({"actors":3,"channels":5,"self_loops":2,"initial_tokens":6,"consistent":true,)"
            R"("repetitions_sum":4,"repetitions_max":2,"components":1,"sccs":1,"largest_scc":3,)"
            R"("cyclic_sccs":1,"simple_cycles":3,"cycles_complete":true})"
            "\n");
  // An inconsistent graph is described, not refused.
  const test::Cli i = test::sdfsched("stats " + graph("inconsistent.json") + " --json");
  EXPECT_EQ(i.status, 0);
  EXPECT_EQ(json::parse(i.out)["consistent"], false);
  EXPECT_TRUE(json::parse(i.out)["repetitions_sum"].is_null());
  // The timed modem: src (3), filt (2, twice in turn: a self-loop), sink (1); 8 from src's start to
  // sink's end in the first iteration.
  const test::Cli l = test::sdfsched("latency " + graph("timed_modem.xml") +
                                     " --from src --to sink --iterations 4 --json");
  ASSERT_EQ(l.status, 0) << l.err;
  const json j = json::parse(l.out);
  EXPECT_EQ(j["per_iteration"][0], 8);
  EXPECT_EQ(j["per_iteration"].size(), 4u);
  EXPECT_EQ(j["latency"], 9);
  const test::Cli d = test::sdfsched("latency " + graph("deadlock.json") + " --default-time 1");
  EXPECT_EQ(d.status, 1);
  EXPECT_TRUE(one_line(d.err));
  EXPECT_NE(d.err.find("stuck actors: P, Q, R"), std::string::npos) << d.err;
}

// A work limit reached is exit 3 in every command (docs/sdf.md, "The CLI"), with one line on
// stderr naming it, or the partial result on stdout where the command has one (stats, --pareto).
TEST(SdfschedCli, LimitsExitWith3) {
  // The timed modem: q = (1, 2, 1), 4 firings an iteration; CD-to-DAT 612.
  const test::Cli l =
      test::sdfsched("latency " + graph("timed_modem.xml") + " --iterations 4 --max-firings 15");
  EXPECT_EQ(l.status, 3);
  EXPECT_TRUE(one_line(l.err));
  EXPECT_NE(l.err.find("take more than 15 firings"), std::string::npos) << l.err;
  EXPECT_EQ(
      test::sdfsched("latency " + graph("timed_modem.xml") + " --iterations 4 --max-firings 16")
          .status,
      0);
  const test::Cli b = test::sdfsched("buffers " + graph("cd2dat.json") + " --max-firings 611");
  EXPECT_EQ(b.status, 3);
  EXPECT_TRUE(one_line(b.err));
  EXPECT_NE(b.err.find("an iteration is 612 firings"), std::string::npos) << b.err;
  EXPECT_EQ(test::sdfsched("buffers " + graph("cd2dat.json") + " --max-firings 612").status, 0);
  const test::Cli p =
      test::sdfsched("buffers " + graph("timed_modem.xml") + " --pareto --max-firings 5 --json");
  EXPECT_EQ(p.status, 3) << p.err;
  EXPECT_EQ(json::parse(p.out)["complete"], false);
  EXPECT_NE(json::parse(p.out)["stopped"].get<std::string>().find("more than 5 firings"),
            std::string::npos)
      << p.out;
  const test::Cli s =
      test::sdfsched("stats " + graph("timed_modem.xml") + " --max-cycles 2 --json");
  EXPECT_EQ(s.status, 3);
  EXPECT_EQ(json::parse(s.out)["simple_cycles"], 2);
  EXPECT_EQ(json::parse(s.out)["cycles_complete"], false);
  EXPECT_EQ(test::sdfsched("stats " + graph("timed_modem.xml") + " --max-cycles 3").status, 0);
  // An expansion beyond its limit (Σq = 4,295,163,907): --method mcm stops (3); auto notes it
  // and answers from the state space (0).
  const std::string chain = "throughput " + graph("chain65537.json") + " --default-time 1";
  EXPECT_EQ(test::sdfsched(chain + " --method mcm").status, 3);
  const test::Cli a = test::sdfsched(chain + " --json");
  EXPECT_EQ(a.status, 0) << a.err;
  EXPECT_NE(a.err.find("note: no critical cycle: the HSDF expansion has more than"),
            std::string::npos)
      << a.err;
}

TEST(SdfschedCli, ClaimsPrintAVerdictPerClaim) {
  const test::Cli r = test::sdfsched("claims --graphs 3 --seed 5");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("- `online-bounded` completes a valid period: holds on all 60\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("- `online` returns a valid period (thesis 5.3): fails on "),
            std::string::npos);
  const json j = json::parse(test::sdfsched("claims --graphs 3 --seed 5 --json").out);
  EXPECT_EQ(j["verdicts"].size(), 9u);
  EXPECT_EQ(j["classes"][0]["bounded_change"]["changes"], 3);
}

TEST(SdfschedCli, GenerateWritesConsistentLiveGraphs) {
  const std::string out = test::temp_path("gen.xml");
  const std::string args =
      "generate --shape cyclic --actors 12 --self-loops --max-q 4 --times 1:9 --seed 11";
  const test::Cli a = test::sdfsched(args);
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_EQ(test::sdfsched(args).out, a.out);  // the seed decides
  EXPECT_NE(test::sdfsched(args + " --seed 12").out, a.out);
  const json g = json::parse(a.out);
  EXPECT_EQ(g["actors"].size(), 12u);
  for (const auto& actor : g["actors"]) {
    EXPECT_GE(actor["time"].get<int>(), 1);
    EXPECT_LE(actor["time"].get<int>(), 9);
  }
  ASSERT_EQ(test::sdfsched(args + " -o '" + out + "'").status, 0);
  EXPECT_EQ(test::slurp(out).rfind("<?xml", 0), 0u);  // SDF3 by the extension
  const test::Cli t = test::sdfsched("throughput '" + out + "' --json");
  std::remove(out.c_str());
  EXPECT_EQ(t.status, 0) << t.err;  // consistent, live, timed
  EXPECT_NE(json::parse(t.out)["throughput"], "0");
}

TEST(SdfschedCli, BadInputAndUsage) {
  struct Case {
    std::string args;
    int status;
    std::string in_err;
  };
  const Case cases[] = {
      {"repetitions " + graph("unconnected_port_crlf.xml"), 1,
       "unconnected_port_crlf.xml:12: port 'spare'"},
      {"repetitions /nonexistent.json", 1, "/nonexistent.json: cannot open"},
      {"repetitions /dev/zero", 1, "/dev/zero: not a regular file"},
      {"claims --graphs 0", 2, "--graphs: must be a whole number >= 1 (got 0)"},
      {"schedule " + graph("cd2dat.json") + " --policy fastest", 2, "--policy"},
      {"schedule", 2, "graph"},
      {"frobnicate", 2, ""},
      {"simulate " + graph("cd2dat.json") + " --rate-change C43@1", 2,
       "expected ACTOR:PRD/CNS@FIRING"},
      {"simulate " + graph("cd2dat.json") + " --rate-change C:0/3@1", 2, "not a positive integer"},
      {"simulate " + graph("cd2dat.json") + " --rate-change Z:1/3@1", 1, "unknown actor 'Z'"},
      {"simulate " + graph("cd2dat.json") + " --rate-change 'Z*2@1'", 1, "unknown actor 'Z'"},
      {"simulate " + graph("cd2dat.json") + " --rate-change 'C*0@1'", 2, "not a positive integer"},
      {"simulate " + graph("cd2dat.json") + " --rate-change 'C:X=2@1'", 1, "unknown channel 'X'"},
      {"simulate " + graph("cd2dat.json") + " --rate-change 'C:A->B#0=2@1'", 1,
       "is not a channel of 'C'"},
      {"simulate " + graph("cd2dat.json") + " --rate-change 'C:B->C#0=2,B->C#0=3@1'", 2,
       "given twice"},
      {"convert " + graph("cd2dat.json") + " --to png", 2, "--to"},
      {"buffers " + graph("cd2dat.json") + " --max-size -1", 2, "--max-size"},
      {"buffers " + graph("cd2dat.json") + " --max-distributions 0", 2, "--max-distributions"},
      {"buffers " + graph("cd2dat.json") + " --max-states 9", 2, "applies to --pareto only"},
      {"buffers " + graph("inconsistent.json"), 1, "inconsistent graph"},
      {"latency " + graph("timed_modem.xml") + " --from src", 2, "give both --from and --to"},
      {"latency " + graph("timed_modem.xml") + " --from src --to nobody", 1,
       "--to: unknown actor 'nobody'"},
      {"latency " + graph("timed_modem.xml") + " --iterations 0", 2, "--iterations"},
      {"latency " + graph("cd2dat.xml"), 1, "actor 'B' has no execution time"},
      {"latency " + graph("empty.xml"), 1, "latency: the graph has no actors"},
      {"stats " + graph("cd2dat.json") + " --max-cycles 0", 2, "--max-cycles"},
      {"latency " + graph("timed_modem.xml") + " --max-firings 0", 2, "--max-firings"},
      {"buffers " + graph("cd2dat.json") + " --max-firings 0", 2, "--max-firings"},
      {"generate --times 5:1", 2, "expected LO:HI"},
      {"generate --shape star", 2, "--shape"},
      {"generate --actors 0", 2, "--actors"},
  };
  for (const Case& c : cases) {
    const test::Cli r = test::sdfsched(c.args);
    EXPECT_EQ(r.status, c.status) << c.args << ": " << r.err;
    EXPECT_TRUE(one_line(r.err)) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.in_err), std::string::npos) << c.args << ": " << r.err;
    EXPECT_EQ(r.out, "") << c.args;
  }
}

}  // namespace
}  // namespace sdf
