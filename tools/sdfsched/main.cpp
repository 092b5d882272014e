// sdfsched: SDF scheduling from the command line (DESIGN §9, docs/sdf.md).
// Exit status: 0 ok; 1 inconsistent graph, deadlock or bad input; 2 usage; 3 no full answer: an
// online outcome other than `returns` (simulate: other than `returns` or `periodic`), or a work
// limit of an analysis reached (an Error(limit); buffers --pareto and stats print what they
// found before it).
#include <CLI/CLI.hpp>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_checks.hpp"
#include "sdf/buffers.hpp"
#include "sdf/checker.hpp"
#include "sdf/claims.hpp"
#include "sdf/generate.hpp"
#include "sdf/graph.hpp"
#include "sdf/io.hpp"
#include "sdf/latency.hpp"
#include "sdf/metrics.hpp"
#include "sdf/online.hpp"
#include "sdf/rates.hpp"
#include "sdf/repetitions.hpp"
#include "sdf/schedule.hpp"
#include "sdf/stats.hpp"
#include "sdf/throughput.hpp"

namespace {

using Json = nlohmann::ordered_json;
using sdf::Error;

// The graph file a command works on: errors found after reading it (a count that overflows,
// memory running out) name it, as parse errors do.
std::string current_input;

sdf::Graph read_graph(const std::string& path) {
  current_input = path;
  return sdf::read_graph_file(path);
}

std::string about_input() {
  return current_input.empty() ? "" : current_input + ": ";
}

void print_json(const Json& j) {
  std::cout << j.dump() << "\n";
}

// An object keyed by unique names, in order. ordered_json's operator[] searches its members
// linearly (quadratic over 10^5 actors: 13 s); names are unique, so members are appended to
// its vector directly.
template <class NameOf>
Json keyed(size_t n, NameOf&& name_of, std::span<const uint64_t> v) {
  Json j = Json::object();
  auto& members = j.get_ref<Json::object_t&>();
  using Base = Json::object_t::Container;
  static_cast<Base&>(members).reserve(n);
  for (size_t i = 0; i < n; ++i) static_cast<Base&>(members).emplace_back(name_of(i), v[i]);
  return j;
}

Json per_actor(const sdf::Graph& g, std::span<const uint64_t> v) {
  return keyed(
      g.actor_count(), [&](size_t a) { return g.actor_name(static_cast<sdf::ActorId>(a)); }, v);
}

Json per_channel(const sdf::Graph& g, std::span<const uint64_t> v) {
  return keyed(
      g.channel_count(),
      [&](size_t c) { return std::string(g.channel_name(static_cast<sdf::ChannelId>(c))); }, v);
}

Json actor_list(const sdf::Graph& g, std::span<const sdf::ActorId> actors) {
  Json j = Json::array();
  for (sdf::ActorId a : actors) j.push_back(g.actor_name(a));
  return j;
}

// Expanded firings, or null when there are more than `max` of them.
Json firings(const sdf::Graph& g, std::span<const sdf::Run> runs, uint64_t max) {
  if (sdf::total_firings(runs) > max) return nullptr;
  Json j = Json::array();
  for (const sdf::Run& r : runs)
    for (uint64_t i = 0; i < r.count; ++i) j.push_back(g.actor_name(r.actor));
  return j;
}

Json run_list(const sdf::Graph& g, std::span<const sdf::Run> runs) {
  Json j = Json::array();
  for (const sdf::Run& r : runs) j.push_back(Json::array({g.actor_name(r.actor), r.count}));
  return j;
}

std::string describe_channel(const sdf::Graph& g, sdf::ChannelId c) {
  const sdf::Channel& ch = g.channel(c);
  std::string s = "'" + std::string(g.channel_name(c)) + "' (";
  s += g.actor_name(ch.src);
  s += " -> ";
  s += g.actor_name(ch.dst);
  s += ", prd " + std::to_string(ch.prd) + ", cns " + std::to_string(ch.cns) + ")";
  return s;
}

// Repetitions or the inconsistency report (exit 1).
struct Consistency {
  sdf::Repetitions rep;
  int status = 0;
};

Consistency consistency(const sdf::Graph& g, bool json) {
  Consistency c{sdf::compute_repetitions(g), 0};
  if (c.rep.consistent) return c;
  const sdf::Channel& ch = g.channel(c.rep.channel);
  if (json) {
    print_json({{"consistent", false},
                {"channel", g.channel_name(c.rep.channel)},
                {"src", g.actor_name(ch.src)},
                {"dst", g.actor_name(ch.dst)},
                {"prd", ch.prd},
                {"cns", ch.cns},
                {"q_src", c.rep.q_src},
                {"q_dst", c.rep.q_dst}});
  }
  std::cerr << "sdfsched: inconsistent graph: the balance equation of channel "
            << describe_channel(g, c.rep.channel) << " fails (" << c.rep.q_src << "*" << ch.prd
            << " != " << c.rep.q_dst << "*" << ch.cns << ")\n";
  c.status = 1;
  return c;
}

int report_deadlock(const sdf::Graph& g, const sdf::StaticSchedule& s, bool json) {
  if (json) {
    Json cycle = Json::array();
    for (sdf::ChannelId c : s.starved_cycle) cycle.push_back(std::string(g.channel_name(c)));
    print_json({{"deadlock", true},
                {"stuck", actor_list(g, s.stuck)},
                {"starved_cycle", cycle},
                {"fired", per_actor(g, s.fired)}});
  }
  std::string stuck;
  for (sdf::ActorId a : s.stuck) stuck += (stuck.empty() ? "" : ", ") + g.actor_name(a);
  std::string cycle;
  for (sdf::ChannelId c : s.starved_cycle)
    cycle += (cycle.empty() ? "" : ", ") + std::string(g.channel_name(c));
  std::cerr << "sdfsched: deadlock: stuck actors: " << stuck << "; cycle lacking tokens: " << cycle
            << "\n";
  return 1;
}

sdf::Policy parse_policy(const std::string& p) {
  if (p == "static") return sdf::Policy::static_order;
  if (p == "online") return sdf::Policy::online;
  return sdf::Policy::online_bounded;
}

struct RunFlags {
  std::string firings = "floor";
  uint64_t max_decisions = 100'000'000;
  uint64_t growth_periods = 16;
  uint64_t max_list = 1'000'000;
  void add(CLI::App* cmd) {
    cmd->add_option("--firings", firings,
                    "firings per online decision: floor (⌊key⌋, the thesis) or one")
        ->check(CLI::IsMember({"floor", "one"}));
    cmd->add_option("--max-decisions", max_decisions,
                    "online: stop with outcome `limit` after this many decisions")
        ->check(crowddb::cli_checks::whole_at_least(1));
    cmd->add_option("--growth-periods", growth_periods,
                    "online: a channel holding more than its delay plus this many periods' tokens "
                    "is `unbounded`")
        ->check(crowddb::cli_checks::whole_at_least(1));
    cmd->add_option("--max-list", max_list, "list firings/runs only up to this many");
  }
  sdf::OnlineRunOptions options(bool bounded) const {
    sdf::OnlineRunOptions o;
    o.scheduler.firings = firings == "one" ? sdf::FiringRule::one : sdf::FiringRule::floor_key;
    o.scheduler.bounded = bounded;
    o.max_decisions = max_decisions;
    o.growth_periods = growth_periods;
    o.max_listed_runs = max_list;
    return o;
  }
};

void print_text_metrics(const sdf::Graph& g, const sdf::Metrics& m) {
  std::cout << "buffers:";
  for (sdf::ChannelId c = 0; c < g.channel_count(); ++c)
    std::cout << " " << std::string(g.channel_name(c)) << "=" << m.buffers[c];
  std::cout << "\nfairness: max " << m.fairness.max << ", mean " << m.fairness.mean << " over "
            << m.fairness.decisions << " decisions\n";
}

int cmd_repetitions(const std::string& path, bool json) {
  const sdf::Graph g = read_graph(path);
  const Consistency c = consistency(g, json);
  if (c.status) return c.status;
  if (json) {
    print_json({{"consistent", true}, {"repetitions", per_actor(g, c.rep.q)}});
  } else {
    // One buffer, one write: a stream insertion per line costs ~50 ms on 10^6 actors.
    std::string out;
    char digits[24];
    for (sdf::ActorId a = 0; a < g.actor_count(); ++a) {
      out += g.actor_name(a);
      out += ' ';
      out.append(digits, std::to_chars(digits, digits + sizeof digits, c.rep.q[a]).ptr);
      out += '\n';
      if (out.size() > (1u << 20)) {
        std::cout.write(out.data(), static_cast<std::streamsize>(out.size()));
        out.clear();
      }
    }
    std::cout.write(out.data(), static_cast<std::streamsize>(out.size()));
  }
  return 0;
}

int cmd_schedule(const std::string& path, const std::string& policy_text, bool json,
                 const RunFlags& flags) {
  const sdf::Graph g = read_graph(path);
  const Consistency c = consistency(g, json);
  if (c.status) return c.status;
  const std::vector<uint64_t>& q = c.rep.q;
  const sdf::StaticSchedule st = sdf::static_schedule(g, q);
  if (!st.complete) return report_deadlock(g, st, json);
  // The two single-period schedules: the ready queue, and the ready queue within a minimal
  // deadlock-free storage distribution (min-buffer).
  if (policy_text == "static" || policy_text == "min-buffer") {
    std::vector<uint64_t> capacity;
    const std::vector<sdf::Run> runs =
        policy_text == "static" ? st.runs : sdf::min_buffer_schedule(g, &capacity);
    const sdf::CheckResult check = sdf::check_period(g, q, runs);
    const sdf::Metrics m = sdf::measure(g, q, sdf::Eligibility::owing, runs);
    if (!json) {
      std::cout << "outcome: returns ("
                << (check.valid ? "valid period" : "INVALID: " + check.reason)
                << ")\nperiod: " << sdf::total_firings(runs) << " firings in " << runs.size()
                << " decisions\nschedule: " << sdf::run_length_form(g, runs) << "\n";
      if (!capacity.empty()) {
        std::cout << "within capacities:";
        for (sdf::ChannelId ch = 0; ch < g.channel_count(); ++ch)
          std::cout << " " << std::string(g.channel_name(ch)) << "=" << capacity[ch];
        std::cout << "\n";
      }
      print_text_metrics(g, m);
      return check.valid ? 0 : 1;
    }
    Json j;
    j["policy"] = policy_text;
    j["outcome"] = "returns";
    j["valid"] = check.valid;
    j["repetitions"] = per_actor(g, q);
    j["decisions"] = runs.size();
    j["period_firings"] = sdf::total_firings(runs);
    j["firings"] = firings(g, runs, flags.max_list);
    j["runs"] = runs.size() <= flags.max_list ? run_list(g, runs) : Json(nullptr);
    if (!capacity.empty()) j["capacities"] = per_channel(g, capacity);
    j["buffers"] = per_channel(g, m.buffers);
    j["fairness"] = {{"max", m.fairness.max}, {"mean", m.fairness.mean}};
    print_json(j);
    return check.valid ? 0 : 1;
  }
  const sdf::Policy policy = parse_policy(policy_text);
  Json j;
  j["policy"] = sdf::policy_name(policy);
  const sdf::OnlineRunOptions opt = flags.options(policy == sdf::Policy::online_bounded);
  const sdf::OnlineRun run = sdf::run_online(g, q, opt);
  const std::span<const sdf::Run> runs(run.runs);
  bool valid = false;
  std::string why;
  if (run.outcome == sdf::Outcome::returns && run.runs_listed) {
    const sdf::CheckResult check = sdf::check_period(g, q, runs);
    valid = check.valid;
    why = check.reason;
  } else if (run.outcome == sdf::Outcome::returns) {
    why = "period too long to list and check (raise --max-list)";
  }
  // A periodic cycle is checked too: from the state where it starts, it must be admissible
  // and return to that state (a valid period from there, though not from the initial state).
  Json cycle_check = nullptr;
  if (run.outcome == sdf::Outcome::periodic && run.runs_listed) {
    const sdf::CheckResult pre = sdf::check_admissible(g, runs.first(run.transient_decisions));
    const sdf::CheckResult cyc =
        sdf::check_period(g, q, runs.subspan(run.transient_decisions), pre.tokens);
    cycle_check = cyc.valid ? Json("valid period from the cycle's start state") : Json(cyc.reason);
  }
  const int status = run.outcome == sdf::Outcome::returns ? (valid ? 0 : 1) : 3;
  if (!json) {
    std::cout << "outcome: " << sdf::outcome_name(run.outcome);
    if (run.outcome == sdf::Outcome::returns)
      std::cout << " (" << (valid ? "valid period" : "NOT CHECKED/INVALID: " + why) << ")";
    if (run.channel)
      std::cout << ": channel " << describe_channel(g, *run.channel) << " keeps growing";
    std::cout << "\n";
    if (run.outcome == sdf::Outcome::periodic) {
      std::cout << "transient: " << run.transient_firings << " firings in "
                << run.transient_decisions << " decisions\ncycle: " << run.cycle_firings
                << " firings in " << run.cycle_decisions << " decisions";
      if (!cycle_check.is_null()) std::cout << " (" << cycle_check.get<std::string>() << ")";
      std::cout << "\n";
      if (run.runs_listed) {
        std::cout << "transient schedule: "
                  << sdf::run_length_form(g, runs.first(run.transient_decisions))
                  << "\ncycle schedule: "
                  << sdf::run_length_form(g, runs.subspan(run.transient_decisions)) << "\n";
      }
    } else if (run.outcome == sdf::Outcome::returns) {
      std::cout << "period: " << run.cycle_firings << " firings in " << run.cycle_decisions
                << " decisions\n";
      if (run.runs_listed) std::cout << "schedule: " << sdf::run_length_form(g, runs) << "\n";
    } else {
      std::cout << "stopped after " << run.decisions_explored << " decisions\n";
    }
    print_text_metrics(g, run.metrics);
    return status;
  }
  j["outcome"] = sdf::outcome_name(run.outcome);
  j["valid"] = valid;
  j["repetitions"] = per_actor(g, q);
  j["decisions"] = run.transient_decisions + run.cycle_decisions;
  if (run.outcome == sdf::Outcome::returns) {
    j["period_firings"] = run.cycle_firings;
    j["firings"] = run.runs_listed ? firings(g, runs, flags.max_list) : Json(nullptr);
    j["runs"] = run.runs_listed ? run_list(g, runs) : Json(nullptr);
  } else if (run.outcome == sdf::Outcome::periodic) {
    j["transient"] = run.runs_listed
                         ? firings(g, runs.first(run.transient_decisions), flags.max_list)
                         : Json(nullptr);
    j["cycle"] = run.runs_listed ? firings(g, runs.subspan(run.transient_decisions), flags.max_list)
                                 : Json(nullptr);
    j["transient_firings"] = run.transient_firings;
    j["cycle_firings"] = run.cycle_firings;
    j["cycle_repetitions"] = per_actor(g, run.cycle_fired);
    j["cycle_check"] = cycle_check;
  } else {
    if (run.channel) j["channel"] = std::string(g.channel_name(*run.channel));
    j["decisions_explored"] = run.decisions_explored;
  }
  j["buffers"] = per_channel(g, run.metrics.buffers);
  j["fairness"] = {{"max", run.metrics.fairness.max}, {"mean", run.metrics.fairness.mean}};
  print_json(j);
  return status;
}

// --rate-change in its three forms (docs/sdf.md): ACTOR:PRD/CNS@FIRING, ACTOR*NUM[/DEN]@FIRING
// and ACTOR:CHANNEL=RATE[,CHANNEL=RATE...]@FIRING. Actor and channel names may contain ':' and
// '*': the actor is the longest prefix that names one and leaves a well-formed rest.
struct ParsedChange {
  sdf::RateChange change;
  std::string form;           // uniform, factor, ports
  uint64_t prd = 0, cns = 0;  // uniform
  uint64_t num = 0, den = 0;  // factor
};

ParsedChange parse_rate_change(const sdf::Graph& g, const std::string& spec) {
  const std::string expected =
      "expected ACTOR:PRD/CNS@FIRING, ACTOR*FACTOR@FIRING or ACTOR:CHANNEL=RATE,...@FIRING";
  const auto at = spec.rfind('@');
  if (at == std::string::npos)
    throw Error(Error::Kind::usage, "--rate-change '" + spec + "': " + expected);
  auto whole = [](std::string_view s, uint64_t& v) {
    const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    return !s.empty() && ec == std::errc() && p == s.data() + s.size();
  };
  auto number = [&](std::string_view s, bool positive) {
    uint64_t v = 0;
    if (!whole(s, v) || (positive && v == 0))
      throw Error(Error::Kind::usage, "--rate-change '" + spec + "': '" + std::string(s) +
                                          "' is not a " + (positive ? "positive" : "non-negative") +
                                          " integer");
    return v;
  };
  // N/D (or N when `slash_optional`), both whole numbers.
  auto fraction = [&](std::string_view s, bool slash_optional) {
    const auto slash = s.find('/');
    uint64_t a = 0, b = 1;
    if (slash == std::string_view::npos) return slash_optional && whole(s, a);
    return whole(s.substr(0, slash), a) && whole(s.substr(slash + 1), b);
  };
  const std::string_view head(spec.data(), at);
  const uint64_t firing = number(std::string_view(spec).substr(at + 1), false);
  ParsedChange out;
  bool unknown_actor = false;  // a well-formed change for an actor the graph does not have
  for (size_t i = head.size(); i-- > 0;) {
    if (head[i] != ':' && head[i] != '*') continue;
    const auto a = g.find_actor(head.substr(0, i));
    const std::string_view rest = head.substr(i + 1);
    const bool well_formed =
        head[i] == '*' ? fraction(rest, true)
                       : fraction(rest, false) || rest.find('=') != std::string_view::npos;
    if (!well_formed) continue;
    if (!a) {
      unknown_actor = true;
      continue;
    }
    if (head[i] == '*') {
      const auto slash = rest.find('/');
      out.form = "factor";
      out.num = number(rest.substr(0, slash), true);
      out.den = slash == std::string_view::npos ? 1 : number(rest.substr(slash + 1), true);
      out.change = sdf::RateChange::scaled(g, *a, out.num, out.den, firing);
      return out;
    }
    if (fraction(rest, false)) {
      const auto slash = rest.find('/');
      out.form = "uniform";
      out.prd = number(rest.substr(0, slash), true);
      out.cns = number(rest.substr(slash + 1), true);
      out.change = sdf::RateChange::uniform(g, *a, out.prd, out.cns, firing);
      return out;
    }
    {
      out.form = "ports";
      out.change.actor = *a;
      out.change.at_firing = firing;
      size_t from = 0;
      while (from <= rest.size()) {
        const size_t comma = std::min(rest.find(',', from), rest.size());
        const std::string_view item = rest.substr(from, comma - from);
        const auto eq = item.rfind('=');
        if (eq == std::string_view::npos)
          throw Error(Error::Kind::usage, "--rate-change '" + spec + "': '" + std::string(item) +
                                              "' is not CHANNEL=RATE");
        const std::string name(item.substr(0, eq));
        const auto c = g.find_channel(name);
        if (!c) throw Error(Error::Kind::input, "--rate-change: unknown channel '" + name + "'");
        const sdf::Channel& ch = g.channel(*c);
        if (ch.src != *a && ch.dst != *a)
          throw Error(Error::Kind::input, "--rate-change: channel '" + name +
                                              "' is not a channel of '" + g.actor_name(*a) + "'");
        const uint64_t rate = number(item.substr(eq + 1), true);
        for (const sdf::ChannelRates& r : out.change.rates)
          if (r.channel == *c)
            throw Error(Error::Kind::usage, "--rate-change: channel '" + name + "' given twice");
        // An output's prd, an input's cns; a self-loop (both) keeps prd = cns.
        out.change.rates.push_back(
            {*c, ch.src == *a ? rate : ch.prd, ch.dst == *a ? rate : ch.cns});
        from = comma + 1;
      }
      return out;
    }
  }
  // Name the actor for the most likely reading: everything before the last ':' or '*'.
  const auto sep = head.find_last_of(":*");
  if (sep != std::string_view::npos && unknown_actor)
    throw Error(Error::Kind::input,
                "--rate-change: unknown actor '" + std::string(head.substr(0, sep)) + "'");
  throw Error(Error::Kind::usage, "--rate-change '" + spec + "': " + expected);
}

int cmd_simulate(const std::string& path, const std::string& policy_text,
                 const std::string& change_text, bool json, const RunFlags& flags) {
  const sdf::Graph g = read_graph(path);
  const Consistency c = consistency(g, json);
  if (c.status) return c.status;
  const sdf::StaticSchedule st = sdf::static_schedule(g, c.rep.q);
  if (!st.complete) return report_deadlock(g, st, json);
  const ParsedChange parsed = parse_rate_change(g, change_text);
  const sdf::RateChange& rc = parsed.change;
  const sdf::Policy policy = parse_policy(policy_text);
  const sdf::RateChangeResult r = sdf::simulate_rate_change(
      g, policy, rc, flags.options(policy == sdf::Policy::online_bounded));
  const sdf::Graph& g2 = r.changed;
  int status = 0;
  if (!r.after.consistent) {
    status = 1;
  } else if (r.outcome == sdf::Outcome::deadlock) {
    status = 1;
  } else if (r.outcome != sdf::Outcome::returns && r.outcome != sdf::Outcome::periodic) {
    status = 3;
  }
  if (!json) {
    std::cout << "policy: " << sdf::policy_name(policy) << "\nchange: " << g.actor_name(rc.actor);
    if (parsed.form == "uniform")
      std::cout << " to prd " << parsed.prd << ", cns " << parsed.cns;
    else if (parsed.form == "factor")
      std::cout << " rates times " << parsed.num << "/" << parsed.den;
    std::cout << " (";
    for (size_t i = 0; i < rc.rates.size(); ++i)
      std::cout << (i ? ", " : "") << std::string(g.channel_name(rc.rates[i].channel)) << " "
                << rc.rates[i].prd << ":" << rc.rates[i].cns;
    std::cout << ") after firing " << rc.at_firing << "\n";
    if (r.outcome_before != sdf::Outcome::returns && r.outcome_before != sdf::Outcome::periodic) {
      std::cout << "outcome before the change: " << sdf::outcome_name(r.outcome_before);
      if (r.channel_before)
        std::cout << " (growing channel " << describe_channel(g, *r.channel_before) << ")";
      std::cout << "\n";
    }
    if (!r.after.consistent) {
      std::cerr << "sdfsched: the changed graph is inconsistent: channel "
                << describe_channel(g2, r.after.channel) << "\n";
      return status;
    }
    std::cout << "outcome after the change: " << sdf::outcome_name(r.outcome) << "\n";
    if (r.outcome == sdf::Outcome::deadlock) {
      std::string stuck;
      for (sdf::ActorId a : r.stuck) stuck += " " + g2.actor_name(a);
      std::cout << "stuck:" << stuck << "\n";
    }
    if (r.channel) std::cout << "growing channel: " << describe_channel(g2, *r.channel) << "\n";
    // As in the JSON form: the transient and period exist only when the run became periodic.
    const bool periodic = r.outcome == sdf::Outcome::returns || r.outcome == sdf::Outcome::periodic;
    if (periodic)
      std::cout << "firings until periodic again: " << r.firings_until_periodic
                << "\nperiod after: " << r.period_firings << " firings ("
                << (r.period_checked ? (r.period_valid ? "valid" : "NOT VALID") : "not checked")
                << ")\n";
    else
      std::cout << "firings until periodic again: none (not periodic)\nperiod after: none\n";
    std::cout << "buffers:";
    for (sdf::ChannelId ch = 0; ch < g.channel_count(); ++ch) {
      std::cout << " " << std::string(g.channel_name(ch)) << "="
                << (r.buffers_before.empty() ? std::string("?")
                                             : std::to_string(r.buffers_before[ch]))
                << "->";
      std::cout << (r.buffers_after.empty() ? std::string("?")
                                            : std::to_string(r.buffers_after[ch]));
    }
    std::cout << "\n";
    return status;
  }
  Json j;
  j["policy"] = sdf::policy_name(policy);
  Json change = {{"actor", g.actor_name(rc.actor)}, {"form", parsed.form}};
  if (parsed.form == "uniform") change["prd"] = parsed.prd, change["cns"] = parsed.cns;
  if (parsed.form == "factor")
    change["factor"] = std::to_string(parsed.num) + "/" + std::to_string(parsed.den);
  // Appended directly, as in keyed(): each channel once (operator[] would search linearly).
  Json rates = Json::object();
  auto& members = static_cast<Json::object_t::Container&>(rates.get_ref<Json::object_t&>());
  members.reserve(rc.rates.size());
  for (const sdf::ChannelRates& cr : rc.rates)
    members.emplace_back(std::string(g.channel_name(cr.channel)),
                         Json{{"prd", cr.prd}, {"cns", cr.cns}});
  change["rates"] = std::move(rates);
  change["at_firing"] = rc.at_firing;
  j["change"] = std::move(change);
  j["repetitions_before"] = per_actor(g, r.q_before);
  j["tokens_at_change"] = per_channel(g, r.tokens_at_change);
  j["outcome_before"] = sdf::outcome_name(r.outcome_before);
  if (r.channel_before) j["channel_before"] = std::string(g.channel_name(*r.channel_before));
  j["buffers_before"] = r.buffers_before.empty() ? Json(nullptr) : per_channel(g, r.buffers_before);
  j["consistent_after"] = r.after.consistent;
  if (!r.after.consistent) {
    j["channel"] = std::string(g2.channel_name(r.after.channel));
    print_json(j);
    std::cerr << "sdfsched: the changed graph is inconsistent: channel "
              << describe_channel(g2, r.after.channel) << "\n";
    return status;
  }
  j["repetitions_after"] = per_actor(g2, r.q_after);
  j["outcome"] = sdf::outcome_name(r.outcome);
  if (r.outcome == sdf::Outcome::deadlock) j["stuck"] = actor_list(g2, r.stuck);
  if (r.channel) j["channel"] = std::string(g2.channel_name(*r.channel));
  const bool periodic = r.outcome == sdf::Outcome::returns || r.outcome == sdf::Outcome::periodic;
  j["firings_until_periodic"] = periodic ? Json(r.firings_until_periodic) : Json(nullptr);
  j["period_firings"] = periodic ? Json(r.period_firings) : Json(nullptr);
  j["period_valid"] = r.period_checked ? Json(r.period_valid) : Json(nullptr);
  j["buffers_after"] = r.buffers_after.empty() ? Json(nullptr) : per_channel(g2, r.buffers_after);
  print_json(j);
  return status;
}

int cmd_throughput(const std::string& path, const std::string& method,
                   std::optional<uint64_t> default_time, bool json) {
  const sdf::Graph g = read_graph(path);
  const Consistency c = consistency(g, json);
  if (c.status) return c.status;
  // The state space gives the value (SDF3's method); the cycle-ratio analysis names the
  // critical cycle and, under auto, checks the value.
  std::optional<sdf::Throughput> ss, mcm;
  if (method != "mcm") ss = sdf::throughput_state_space(g, default_time);
  if (method != "state-space") {
    try {
      mcm = sdf::throughput_mcm(g, default_time);
    } catch (const Error& e) {
      if (method == "mcm" || e.kind() == Error::Kind::overflow) throw;
      std::cerr << "sdfsched: note: no critical cycle: " << e.what() << "\n";
    }
  }
  if (ss && mcm && ss->str() != mcm->str())
    throw std::logic_error("throughput: the state space gives " + ss->str() +
                           " but the cycle ratio " + mcm->str());
  const sdf::Throughput& t = ss ? *ss : *mcm;
  if (json) {
    Json j;
    j["throughput"] = t.str();
    j["critical_cycle"] =
        mcm && !mcm->critical_cycle.empty() ? Json(mcm->critical_cycle) : Json(nullptr);
    if (mcm && !mcm->critical_cycle.empty()) {
      j["cycle_time"] = mcm->cycle_time;
      j["cycle_tokens"] = mcm->cycle_tokens;
    }
    if (mcm && !mcm->deadlock_cycle.empty()) j["deadlock_cycle"] = mcm->deadlock_cycle;
    if (ss) j["states"] = ss->states;
    print_json(j);
    return 0;
  }
  std::cout << "throughput: " << t.str();
  if (!t.unbounded && t.num != 0)
    std::cout << " iterations per time unit ("
              << static_cast<double>(t.num) / static_cast<double>(t.den) << "; one iteration every "
              << static_cast<double>(t.den) / static_cast<double>(t.num) << ")";
  if (t.unbounded) std::cout << " (no cycle with execution time constrains the graph)";
  if (!t.unbounded && t.num == 0) std::cout << " (the graph deadlocks)";
  std::cout << "\n";
  auto chain = [](const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& f : v) s += f + " -> ";
    return s + (v.empty() ? "" : v.front());
  };
  if (mcm && !mcm->critical_cycle.empty())
    std::cout << "critical cycle: " << chain(mcm->critical_cycle) << " (time " << mcm->cycle_time
              << ", tokens " << mcm->cycle_tokens << ")\n";
  if (mcm && !mcm->deadlock_cycle.empty())
    std::cout << "cycle without tokens: " << chain(mcm->deadlock_cycle) << "\n";
  if (ss) std::cout << "states explored: " << ss->states << "\n";
  return 0;
}

Json distribution_list(const sdf::Graph& g, const std::vector<std::vector<uint64_t>>& ds) {
  Json j = Json::array();
  for (const auto& d : ds) j.push_back(per_channel(g, d));
  return j;
}

void print_distribution(const sdf::Graph& g, const std::vector<uint64_t>& d) {
  std::cout << " ";
  for (sdf::ChannelId c = 0; c < g.channel_count(); ++c)
    std::cout << " " << std::string(g.channel_name(c)) << "=" << d[c];
  std::cout << "\n";
}

int cmd_buffers(const std::string& path, bool pareto, std::optional<uint64_t> default_time,
                const sdf::BufferLimits& limits, bool json) {
  const sdf::Graph g = read_graph(path);
  const Consistency c = consistency(g, json);
  if (c.status) return c.status;
  const std::vector<uint64_t> lb = sdf::buffer_lower_bounds(g);
  uint64_t lb_size = 0;
  for (uint64_t v : lb) lb_size = lb_size + v < lb_size ? UINT64_MAX : lb_size + v;
  Json j;
  j["lower_bounds"] = per_channel(g, lb);
  j["lower_bound_size"] = lb_size;
  if (!pareto) {
    const sdf::StorageSearch s = sdf::minimal_storage(g, limits);
    if (json) {
      j["size"] = s.size;
      j["distributions"] = distribution_list(g, s.distributions);
      j["explored"] = s.explored;
      j["firings"] = s.firings;
      print_json(j);
      return 0;
    }
    std::cout << "lower bounds: " << lb_size << " in total\n";
    print_distribution(g, lb);
    std::cout << "minimal deadlock-free storage: " << s.size << " (" << s.distributions.size()
              << (s.distributions.size() == 1 ? " distribution" : " distributions") << "; "
              << s.explored << " explored, " << s.firings << " firings simulated)\n";
    for (const auto& d : s.distributions) print_distribution(g, d);
    return 0;
  }
  const sdf::ParetoSearch s = sdf::storage_throughput_pareto(g, default_time, limits);
  const int status = s.complete ? 0 : 3;
  if (json) {
    j["max_throughput"] = s.max_throughput.str();
    Json points = Json::array();
    for (const sdf::ParetoPoint& p : s.points)
      points.push_back({{"size", p.size},
                        {"throughput", p.throughput.str()},
                        {"distributions", distribution_list(g, p.distributions)}});
    j["points"] = std::move(points);
    j["complete"] = s.complete;
    if (!s.complete) j["stopped"] = s.stopped;
    j["explored"] = s.explored;
    j["states"] = s.states;
    j["firings"] = s.firings;
    print_json(j);
    return status;
  }
  std::cout << "lower bounds: " << lb_size
            << " in total\nthroughput with unbounded channels: " << s.max_throughput.str() << "\n";
  for (const sdf::ParetoPoint& p : s.points) {
    std::cout << "size " << p.size << ": throughput " << p.throughput.str() << " ("
              << p.distributions.size()
              << (p.distributions.size() == 1 ? " distribution)" : " distributions)") << "\n";
    for (const auto& d : p.distributions) print_distribution(g, d);
  }
  if (s.complete)
    std::cout << "complete: the last point reaches the throughput with unbounded channels ("
              << s.explored << " distributions explored, " << s.states << " states, " << s.firings
              << " firings)\n";
  else
    std::cout << "INCOMPLETE: " << s.stopped << " (" << s.explored << " distributions explored, "
              << s.states << " states, " << s.firings << " firings)\n";
  return status;
}

int cmd_stats(const std::string& path, const sdf::StatsLimits& limits, bool json) {
  const sdf::Graph g = read_graph(path);
  const sdf::GraphStats s = sdf::graph_stats(g, limits);
  auto opt = [](const std::optional<uint64_t>& v) { return v ? Json(*v) : Json(nullptr); };
  if (json) {
    print_json({{"actors", s.actors},
                {"channels", s.channels},
                {"self_loops", s.self_loops},
                {"initial_tokens", opt(s.initial_tokens)},
                {"consistent", s.repetitions_overflow ? Json(nullptr) : Json(s.consistent)},
                {"repetitions_sum", opt(s.repetitions_sum)},
                {"repetitions_max", opt(s.repetitions_max)},
                {"components", s.components},
                {"sccs", s.sccs},
                {"largest_scc", s.largest_scc},
                {"cyclic_sccs", s.cyclic_sccs},
                {"simple_cycles", s.simple_cycles},
                {"cycles_complete", s.cycles_complete}});
    return s.cycles_complete ? 0 : 3;
  }
  auto text = [](const std::optional<uint64_t>& v) {
    return v ? std::to_string(*v) : std::string("beyond 64 bits");
  };
  std::cout << "actors: " << s.actors << "\nchannels: " << s.channels << " (" << s.self_loops
            << " self-loops)\ninitial tokens: " << text(s.initial_tokens) << "\nconsistent: "
            << (s.repetitions_overflow ? "undecided (a repetition count beyond 64 bits)"
                                       : (s.consistent ? "yes" : "no"))
            << "\n";
  if (s.consistent)
    std::cout << "repetitions: sum " << text(s.repetitions_sum) << ", max "
              << text(s.repetitions_max) << "\n";
  std::cout << "connected components: " << s.components
            << "\nstrongly connected components: " << s.sccs << " (largest " << s.largest_scc
            << " actors; " << s.cyclic_sccs
            << " with a cycle)\nsimple cycles: " << (s.cycles_complete ? "" : "at least ")
            << s.simple_cycles << (s.cycles_complete ? "" : " (the count stopped at its limit)")
            << "\n";
  return s.cycles_complete ? 0 : 3;  // a limit cut the count short
}

int cmd_latency(const std::string& path, const std::string& from, const std::string& to,
                uint64_t iterations, uint64_t max_firings, std::optional<uint64_t> default_time,
                bool json) {
  const sdf::Graph g = read_graph(path);
  const Consistency c = consistency(g, json);
  if (c.status) return c.status;
  sdf::LatencyOptions o;
  o.iterations = iterations;
  o.max_firings = max_firings;
  auto actor = [&](const std::string& name, const char* option) {
    const auto a = g.find_actor(name);
    if (!a) throw Error(Error::Kind::input, std::string(option) + ": unknown actor '" + name + "'");
    return *a;
  };
  if (from.empty() != to.empty())
    throw Error(Error::Kind::usage, "latency: give both --from and --to, or neither");
  if (!from.empty()) o.from = actor(from, "--from"), o.to = actor(to, "--to");
  const sdf::Latency l = sdf::latency(g, o, default_time);
  if (l.deadlock) {
    if (json) print_json({{"deadlock", true}, {"stuck", actor_list(g, l.stuck)}});
    std::string stuck;
    for (sdf::ActorId a : l.stuck) stuck += (stuck.empty() ? "" : ", ") + g.actor_name(a);
    std::cerr << "sdfsched: deadlock: " << iterations
              << " iteration(s) cannot complete; stuck actors: " << stuck << "\n";
    return 1;
  }
  if (json) {
    Json per = Json::array();
    for (int64_t v : l.per_iteration) per.push_back(v);
    print_json({{"from", from.empty() ? Json(nullptr) : Json(from)},
                {"to", to.empty() ? Json(nullptr) : Json(to)},
                {"iterations", iterations},
                {"latency", l.max},
                {"iteration", l.iteration},
                {"per_iteration", per},
                {"makespan", l.makespan}});
    return 0;
  }
  std::cout << "latency: " << l.max << " (iteration " << l.iteration << ", "
            << (from.empty() ? "span of all actors"
                             : "from the start of " + from + " to the end of " + to)
            << ")\nper iteration:";
  for (int64_t v : l.per_iteration) std::cout << " " << v;
  std::cout << "\nmakespan of " << iterations << " iteration(s): " << l.makespan << "\n";
  return 0;
}

// To stdout, or written beside the target and renamed, so a failed run never leaves half a file.
int write_output(const std::string& text, const std::string& out) {
  if (out.empty() || out == "-") {
    std::cout << text;
    return 0;
  }
  const std::string tmp = out + ".partial";
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) throw Error(Error::Kind::io, out + ": cannot write");
    f << text;
    if (!f.flush()) throw Error(Error::Kind::io, out + ": write error");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, out, ec);
  if (ec) throw Error(Error::Kind::io, out + ": " + ec.message());
  return 0;
}

int cmd_convert(const std::string& path, const std::string& to, const std::string& out) {
  const sdf::Graph g = read_graph(path);
  auto by_output = [&](const sdf::Graph& h) {
    const bool as_json = out.size() >= 5 && out.compare(out.size() - 5, 5, ".json") == 0;
    return as_json ? sdf::write_json(h) : sdf::write_sdf3(h);
  };
  const std::string text = to == "json"   ? sdf::write_json(g)
                           : to == "dot"  ? sdf::write_dot(g)
                           : to == "hsdf" ? by_output(sdf::to_hsdf(g))
                                          : sdf::write_sdf3(g);
  return write_output(text, out);
}

struct GenerateFlags {
  std::string shape = "dag";
  uint32_t actors = 8;
  bool homogeneous = false, self_loops = false;
  uint32_t max_q = 12, max_multiplier = 3, extra_percent = 50, back_percent = 30, max_rate = 0;
  std::string times;  // LO:HI
  uint64_t seed = 1;
  std::string format;  // json | sdf3; default by the output's extension, else json
};

int cmd_generate(const GenerateFlags& f, const std::string& out) {
  sdf::gen::Spec spec;
  const std::pair<const char*, sdf::gen::Shape> shapes[] = {
      {"chain", sdf::gen::Shape::chain},   {"fan-out", sdf::gen::Shape::fan_out},
      {"fan-in", sdf::gen::Shape::fan_in}, {"dag", sdf::gen::Shape::dag},
      {"cyclic", sdf::gen::Shape::cyclic}, {"cyclic-random", sdf::gen::Shape::cyclic_random}};
  for (const auto& [name, shape] : shapes)
    if (f.shape == name) spec.shape = shape;
  spec.actors = f.actors;
  spec.multirate = !f.homogeneous;
  spec.self_loops = f.self_loops;
  spec.max_q = f.max_q;
  spec.max_multiplier = f.max_multiplier;
  spec.max_rate = f.max_rate;
  spec.extra_percent = f.extra_percent;
  spec.back_percent = f.back_percent;
  uint64_t lo = 0, hi = 0;
  if (!f.times.empty()) {
    const auto colon = f.times.find(':');
    auto whole = [&](std::string_view t, uint64_t& v) {
      const auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
      return !t.empty() && ec == std::errc() && p == t.data() + t.size();
    };
    const std::string_view t(f.times);
    if (colon == std::string::npos || !whole(t.substr(0, colon), lo) ||
        !whole(t.substr(colon + 1), hi) || lo > hi || hi >= (uint64_t{1} << 63))
      throw Error(Error::Kind::usage,
                  "--times '" + f.times + "': expected LO:HI, whole numbers, LO <= HI < 2^63");
  }
  crowddb::Rng rng(f.seed);
  sdf::gen::Generated gd = sdf::gen::generate(spec, rng);
  sdf::Graph& g = gd.graph;
  g.name = f.shape + "_" + std::to_string(f.actors) + "_seed" + std::to_string(f.seed);
  if (!f.times.empty()) {
    crowddb::Rng time_rng = crowddb::Rng::stream(f.seed, 1);  // times do not move the graph
    for (sdf::ActorId a = 0; a < g.actor_count(); ++a)
      g.set_actor_time(a, lo + (hi > lo ? time_rng.below(hi - lo + 1) : 0));
  }
  const bool xml = f.format == "sdf3" || (f.format.empty() && out.size() >= 4 &&
                                          out.compare(out.size() - 4, 4, ".xml") == 0);
  return write_output(xml ? sdf::write_sdf3(g) : sdf::write_json(g), out);
}

int cmd_claims(uint64_t graphs, uint64_t seed, bool json, const std::string& save_dir) {
  sdf::claims::Options opts;
  opts.graphs_per_class = graphs;
  opts.seed = seed;
  const sdf::claims::Report r = sdf::claims::run(opts);
  auto stats = [](const sdf::claims::PolicyStats& s) {
    return Json{{"returns", s.returns},
                {"periodic", s.periodic},
                {"unbounded", s.unbounded},
                {"unbounded_confirmed", s.unbounded_confirmed},
                {"deadlock", s.deadlock},
                {"limit", s.limit},
                {"fairness_violations", s.fairness_violations},
                {"fairness_violations_weak", s.fairness_violations_weak},
                {"max_wait", s.max_wait},
                {"checker_failures", s.checker_failures}};
  };
  if (!save_dir.empty()) {
    std::filesystem::create_directories(save_dir);
    for (const auto& [claim, g] : r.counterexamples) {
      std::ofstream f(save_dir + "/" + claim + ".json");
      f << sdf::write_json(g);
    }
  }
  auto change_stats = [](const sdf::claims::RateChangeStats& s) {
    return Json{
        {"changes", s.changes},   {"periodic_again", s.periodic_again},
        {"at_once", s.at_once},   {"unbounded", s.unbounded},
        {"deadlock", s.deadlock}, {"limit", s.limit},
        {"invalid", s.invalid},   {"max_firings_until_periodic", s.max_firings_until_periodic}};
  };
  const std::vector<sdf::claims::Verdict> verdicts = sdf::claims::verdicts(r);
  auto example = [&](const sdf::claims::Verdict& v) -> std::string {
    if (v.counterexample.empty()) return {};
    const sdf::Graph& g = r.counterexamples.at(v.counterexample);
    std::string s = v.counterexample + " (" + std::to_string(g.actor_count()) + " actors, " +
                    std::to_string(g.channel_count()) + " channels";
    if (v.counterexample.find("-change-") != std::string::npos) s += ", change " + g.name;
    return s + ")";
  };
  if (json) {
    Json j = Json::array();
    for (const auto& c : r.classes)
      j.push_back({{"class", c.name},
                   {"graphs", c.graphs},
                   {"online", stats(c.online)},
                   {"online_one", stats(c.online_one)},
                   {"bounded", stats(c.bounded)},
                   {"online_change", change_stats(c.online_change)},
                   {"bounded_change", change_stats(c.bounded_change)},
                   {"buffers_on_common_graphs",
                    {{"graphs", c.common},
                     {"static", c.buffers_static},
                     {"online", c.buffers_online},
                     {"bounded", c.buffers_bounded}}}});
    Json ce = Json::object();
    for (const auto& [claim, g] : r.counterexamples) ce[claim] = Json::parse(sdf::write_json(g));
    Json vs = Json::array();
    for (const auto& v : verdicts)
      vs.push_back(
          {{"claim", v.claim},
           {"fails", v.fails},
           {"graphs", v.graphs},
           {"counterexample", v.counterexample.empty() ? Json(nullptr) : Json(v.counterexample)}});
    print_json({{"classes", j}, {"verdicts", vs}, {"counterexamples", ce}});
    return 0;
  }
  auto outcomes = [](const sdf::claims::PolicyStats& s) {
    std::string t = std::to_string(s.returns) + " / " + std::to_string(s.periodic) + " / " +
                    std::to_string(s.unbounded);
    if (s.unbounded) t += " (" + std::to_string(s.unbounded_confirmed) + " confirmed)";
    if (s.limit + s.deadlock) t += " +" + std::to_string(s.limit + s.deadlock) + " other";
    return t;
  };
  std::cout << "| class | graphs | online: returns / periodic / unbounded | max wait >= n-1 | "
               "max wait > n-1 | max wait | --firings one: returns / periodic / unbounded | "
               "bounded valid | checker failures | buffers static : online : bounded (graphs) | "
               "after a rate change, online: periodic (at once) / unbounded / deadlock | "
               "after a rate change, bounded: valid / deadlock |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : r.classes) {
    const auto& o = c.online;
    std::cout << "| " << c.name << " | " << c.graphs << " | " << outcomes(o) << " | "
              << o.fairness_violations << " | " << o.fairness_violations_weak << " | " << o.max_wait
              << " | " << outcomes(c.online_one) << " | " << c.bounded.returns << " | "
              << o.checker_failures + c.online_one.checker_failures + c.bounded.checker_failures
              << " | " << c.buffers_static << " : " << c.buffers_online << " : "
              << c.buffers_bounded << " (" << c.common << ") | " << c.online_change.periodic_again
              << " (" << c.online_change.at_once << ") / "
              << c.online_change.unbounded + c.online_change.limit << " / "
              << c.online_change.deadlock << " | " << c.bounded_change.periodic_again << " / "
              << c.bounded_change.deadlock << " |\n";
  }
  std::cout << "\n";
  for (const auto& v : verdicts) {
    std::cout << "- " << v.claim << ": ";
    if (v.fails == 0)
      std::cout << "holds on all " << v.graphs << "\n";
    else
      std::cout << "fails on " << v.fails << " of " << v.graphs << "; smallest counter-example "
                << example(v) << "\n";
  }
  std::cout << "\nsmallest counter-examples:";
  for (const auto& [claim, g] : r.counterexamples)
    std::cout << " " << claim << " (" << g.actor_count() << " actors, " << g.channel_count()
              << " channels)";
  std::cout << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sdfsched: Synchronous Data-Flow scheduling (see docs/sdf.md)", "sdfsched"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "sdfsched 0.1.0");
  std::function<int()> action;
  std::string graph, policy = "static", to, out, change;
  bool json = false;
  RunFlags flags;

  auto* rep = app.add_subcommand("repetitions", "the repetitions vector (or the failing channel)");
  rep->add_option("graph", graph, "SDF3 XML (.xml) or JSON (.json) graph")->required();
  rep->add_flag("--json", json, "JSON output");
  rep->callback([&] { action = [&] { return cmd_repetitions(graph, json); }; });

  auto* sch = app.add_subcommand("schedule", "one period by the static or an online scheduler");
  sch->add_option("graph", graph, "SDF3 XML (.xml) or JSON (.json) graph")->required();
  sch->add_option("--policy", policy,
                  "static, min-buffer (the ready queue within a minimal deadlock-free storage "
                  "distribution), online or online-bounded")
      ->check(CLI::IsMember({"static", "min-buffer", "online", "online-bounded"}));
  sch->add_flag("--json", json, "JSON output");
  flags.add(sch);
  sch->callback([&] { action = [&] { return cmd_schedule(graph, policy, json, flags); }; });

  auto* sim = app.add_subcommand("simulate", "change an actor's rates mid-period and continue");
  sim->add_option("graph", graph, "SDF3 XML (.xml) or JSON (.json) graph")->required();
  sim->add_option(
         "--rate-change", change,
         "ACTOR:PRD/CNS@FIRING (every output PRD, every input CNS), ACTOR*NUM[/DEN]@FIRING "
         "(every rate of ACTOR scaled) or ACTOR:CHANNEL=RATE,...@FIRING")
      ->required();
  sim->add_option("--policy", policy, "static, online or online-bounded")
      ->check(CLI::IsMember({"static", "online", "online-bounded"}));
  sim->add_flag("--json", json, "JSON output");
  flags.add(sim);
  sim->callback([&] { action = [&] { return cmd_simulate(graph, policy, change, json, flags); }; });

  auto* conv = app.add_subcommand("convert", "write the graph as SDF3 XML, JSON or DOT");
  conv->add_option("graph", graph, "SDF3 XML (.xml) or JSON (.json) graph")->required();
  conv->add_option("--to", to,
                   "sdf3, json, dot, or hsdf (the homogeneous expansion, as SDF3 XML or as JSON "
                   "when the output file ends in .json)")
      ->required()
      ->check(CLI::IsMember({"sdf3", "json", "dot", "hsdf"}));
  conv->add_option("-o,--output", out, "output file (default: standard output)");
  conv->callback([&] { action = [&] { return cmd_convert(graph, to, out); }; });

  std::string method = "auto";
  std::optional<uint64_t> default_time;
  auto* thr = app.add_subcommand(
      "throughput", "iterations per time unit of self-timed execution, and a critical cycle");
  thr->add_option("graph", graph, "SDF3 XML (.xml) or JSON (.json) graph with execution times")
      ->required();
  thr->add_option("--method", method,
                  "state-space (SDF3's), mcm (maximum cycle ratio of the HSDF expansion) or auto "
                  "(both; they must agree)")
      ->check(CLI::IsMember({"auto", "state-space", "mcm"}));
  thr->add_option("--default-time", default_time, "execution time of actors that have none");
  thr->add_flag("--json", json, "JSON output");
  thr->callback(
      [&] { action = [&] { return cmd_throughput(graph, method, default_time, json); }; });

  bool pareto = false;
  sdf::BufferLimits limits;
  auto* buf = app.add_subcommand(
      "buffers", "minimal deadlock-free storage per channel, or the storage-throughput trade-off");
  buf->add_option("graph", graph, "SDF3 XML (.xml) or JSON (.json) graph")->required();
  buf->add_flag("--pareto", pareto,
                "every size at which the best throughput grows, up to the throughput with "
                "unbounded channels (needs execution times)");
  buf->add_option("--default-time", default_time, "execution time of actors that have none");
  buf->add_option("--max-distributions", limits.max_distributions,
                  "stop after exploring this many storage distributions")
      ->check(crowddb::cli_checks::whole_at_least(1));
  auto* max_states = buf->add_option("--max-states", limits.max_states,
                                     "--pareto: stop after storing this many states over all "
                                     "explorations (minimal storage stores none)")
                         ->check(crowddb::cli_checks::whole_at_least(1));
  buf->add_option("--max-size", limits.max_size, "explore no distribution larger")
      ->check(crowddb::cli_checks::whole_at_least(0));
  buf->add_option("--max-firings", limits.max_firings_per_run,
                  "stop when the run of one distribution would simulate more firings")
      ->check(crowddb::cli_checks::whole_at_least(1));
  buf->add_flag("--json", json, "JSON output");
  buf->callback([&] {
    if (!pareto && max_states->count() > 0)
      throw CLI::ValidationError("--max-states",
                                 "applies to --pareto only (minimal storage runs "
                                 "untimed and stores no states)");
    action = [&] { return cmd_buffers(graph, pareto, default_time, limits, json); };
  });

  sdf::StatsLimits stats_limits;
  auto* sta = app.add_subcommand(
      "stats", "sizes, repetitions sum, components, strongly connected components, simple cycles");
  sta->add_option("graph", graph, "SDF3 XML (.xml) or JSON (.json) graph")->required();
  sta->add_option("--max-cycles", stats_limits.max_cycles, "stop counting cycles after this many")
      ->check(crowddb::cli_checks::whole_at_least(1));
  sta->add_flag("--json", json, "JSON output");
  sta->callback([&] { action = [&] { return cmd_stats(graph, stats_limits, json); }; });

  std::string from, to_actor;
  uint64_t iterations = 1;
  auto* lat = app.add_subcommand(
      "latency", "latency of self-timed execution over the first iterations (docs/sdf.md)");
  lat->add_option("graph", graph, "SDF3 XML (.xml) or JSON (.json) graph with execution times")
      ->required();
  lat->add_option("--from", from, "source actor (with --to): from its first firing's start");
  lat->add_option("--to", to_actor, "destination actor: to its iteration's last firing's end");
  lat->add_option("--iterations", iterations, "iterations to simulate (the latency is the largest)")
      ->check(crowddb::cli_checks::whole_at_least(1));
  lat->add_option("--default-time", default_time, "execution time of actors that have none");
  uint64_t max_firings = sdf::LatencyOptions{}.max_firings;
  lat->add_option("--max-firings", max_firings,
                  "refuse when the iterations take more firings (K times the repetitions sum)")
      ->check(crowddb::cli_checks::whole_at_least(1));
  lat->add_flag("--json", json, "JSON output");
  lat->callback([&] {
    action = [&] {
      return cmd_latency(graph, from, to_actor, iterations, max_firings, default_time, json);
    };
  });

  GenerateFlags gf;
  auto* gen = app.add_subcommand("generate", "write a random consistent graph (JSON or SDF3)");
  gen->add_option("--shape", gf.shape, "chain, fan-out, fan-in, dag, cyclic or cyclic-random")
      ->check(CLI::IsMember({"chain", "fan-out", "fan-in", "dag", "cyclic", "cyclic-random"}));
  gen->add_option("--actors", gf.actors, "number of actors")
      ->check(crowddb::cli_checks::whole(1, 50'000'000));
  gen->add_flag("--homogeneous", gf.homogeneous, "every rate 1");
  gen->add_flag("--self-loops", gf.self_loops, "SDF3's one-token self-loop on every actor");
  gen->add_option("--max-q", gf.max_q,
                  "repetition counts drawn from {1,2,3,4,5,6,8,9,10,12} up to this")
      ->check(crowddb::cli_checks::whole(1, 12));
  gen->add_option("--max-multiplier", gf.max_multiplier,
                  "rates are (q_dst, q_src)/gcd times a multiplier from {1,2,3} up to this")
      ->check(crowddb::cli_checks::whole(1, 3));
  gen->add_option("--max-rate", gf.max_rate,
                  "every rate at most this (rates are 1 to 36 without it; 1: homogeneous)")
      ->check(crowddb::cli_checks::whole(1, 1'000'000));
  gen->add_option("--extra-percent", gf.extra_percent,
                  "dag/cyclic: extra forward channels, % of the actors")
      ->check(crowddb::cli_checks::whole(0, 1000));
  gen->add_option("--back-percent", gf.back_percent, "cyclic: back channels, % of the actors")
      ->check(crowddb::cli_checks::whole(0, 1000));
  gen->add_option("--times", gf.times, "LO:HI: random execution times in [LO, HI]");
  gen->add_option("--seed", gf.seed, "random seed");
  gen->add_option("--format", gf.format, "json or sdf3 (default: sdf3 for -o *.xml, else json)")
      ->check(CLI::IsMember({"json", "sdf3"}));
  gen->add_option("-o,--output", out, "output file (default: standard output)");
  gen->callback([&] { action = [&] { return cmd_generate(gf, out); }; });

  uint64_t graphs = 100, seed = 1;
  std::string save;
  auto* cl = app.add_subcommand("claims", "test the thesis's claims on random consistent graphs");
  cl->add_option("--graphs", graphs, "graphs per class")
      ->check(crowddb::cli_checks::whole_at_least(1));
  cl->add_option("--seed", seed, "random seed");
  cl->add_option("--save-counterexamples", save, "directory for the smallest counter-examples");
  cl->add_flag("--json", json, "JSON output");
  cl->callback([&] { action = [&] { return cmd_claims(graphs, seed, json, save); }; });

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string msg = e.what();
    while (!msg.empty() && msg.back() == '\n') msg.pop_back();
    std::cerr << "sdfsched: " << msg << " (see --help)\n";
    return 2;
  }
  try {
    return action ? action() : 0;
  } catch (const Error& e) {
    const std::string msg = e.what();
    const bool named = !current_input.empty() && msg.rfind(current_input, 0) == 0;
    std::cerr << "sdfsched: " << (named ? "" : about_input()) << msg << "\n";
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    std::cerr << "sdfsched: " << about_input() << "out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "sdfsched: internal error: " << e.what() << "\n";
    return 1;
  }
}
