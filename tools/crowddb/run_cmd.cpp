// `crowddb run` and `crowddb validate`: simulate a scenario file.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "experiment/experiment.hpp"
#include "io/trajectory.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::cli {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void on_interrupt(int) {
  g_interrupted = true;
}

struct RunOptions {
  std::string scenario;
  int64_t ticks = -1;
  double duration = -1;
  std::string model;
  std::string out, format;
  bool no_output = false;
  bool explain = false, analyze = false, quiet = false, no_backoff = false, no_navigation = false;
  int threads = 0;
  int64_t every = 0;
  double nudge_after = -1;
  std::string ftc, field, collisions;
};

std::string hex(uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

void print_warnings(const Scenario& sc) {
  for (const auto& w : sc.warnings)
    std::cerr << "crowddb: warning: " << sc.source << ": " << w << "\n";
}

// Applies the command-line overrides to a loaded scenario.
void apply_overrides(Scenario& sc, const RunOptions& o) {
  if (o.ticks >= 0) sc.ticks = static_cast<uint64_t>(o.ticks);
  if (o.duration >= 0) sc.ticks = sc.config.ticks_for(o.duration, 0);
  if (!o.model.empty()) sc.config.steering.model = o.model;
  if (o.threads > 0) sc.config.threads = o.threads;
  if (o.no_backoff) sc.config.backoff = false;
  if (o.nudge_after >= 0) sc.config.nudge_after = o.nudge_after;
  if (o.no_navigation) sc.config.navigation.enabled = false;
  if (!o.ftc.empty()) sc.config.access.ftc = o.ftc;
  if (!o.field.empty()) sc.config.access.field = o.field;
  if (!o.collisions.empty()) sc.config.access.collisions = o.collisions;
  if (!o.out.empty()) {
    sc.output.path = o.out;
    const bool csv = o.out.size() >= 4 && o.out.compare(o.out.size() - 4, 4, ".csv") == 0;
    sc.output.format = csv ? OutputSpec::Format::csv : OutputSpec::Format::sqlite;
  }
  if (!o.format.empty())
    sc.output.format = o.format == "csv" ? OutputSpec::Format::csv : OutputSpec::Format::sqlite;
  if (o.every > 0) sc.output.every = static_cast<uint32_t>(o.every);
  if (o.no_output) sc.output.path.clear();
}

int run(const RunOptions& o) {
  Scenario sc = load_scenario(o.scenario);
  apply_overrides(sc, o);
  print_warnings(sc);
  Simulation sim(std::move(sc.world), sc.config);
  if (o.explain) {
    std::cout << sim.explain();
    return 0;
  }
  std::unique_ptr<io::TrajectoryWriter> writer;
  if (!sc.output.path.empty()) {
    writer = io::make_writer(sc.output);
    writer->begin(sc, sim.world());
  }
  g_interrupted = false;
  auto old_int = std::signal(SIGINT, on_interrupt);
  auto old_term = std::signal(SIGTERM, on_interrupt);
  const bool tty = isatty(STDERR_FILENO) && !o.quiet;
  const std::size_t agents_at_start = sim.world().agents().size();
  std::vector<double> tick_seconds;
  std::size_t max_pairs = 0, max_obstacle = 0, frozen_total = 0;
  std::size_t iterations_total = 0, iterations_max = 0, gridlock_max = 0, gridlock_streaks = 0;
  std::size_t longest_frozen = 0, nudged_total = 0;
  std::size_t stall_streaks = 0, stall_max = 0, longest_stall = 0, yield_total = 0,
              sidestep_total = 0;
  uint64_t last_arrival = 0;
  Stopwatch clock, progress_clock;
  try {
    if (writer) writer->frame(0, sim.world());
    for (uint64_t t = 1; t <= sc.ticks; ++t) {
      if (g_interrupted)
        throw Error(Error::Kind::io,
                    "interrupted at tick " + std::to_string(t - 1) + "; no output kept");
      const TickMetrics& m = sim.step();
      tick_seconds.push_back(m.seconds);
      max_pairs = std::max(max_pairs, m.overlapping_pairs);
      max_obstacle = std::max(max_obstacle, m.obstacle_overlaps);
      frozen_total += m.frozen;
      iterations_total += m.freeze_iterations;
      iterations_max = std::max(iterations_max, m.freeze_iterations);
      gridlock_max = std::max(gridlock_max, m.gridlocked);
      gridlock_streaks += m.gridlock_started;
      longest_frozen = std::max(longest_frozen, m.longest_frozen);
      nudged_total += m.nudged;
      stall_streaks += m.stall_started;
      stall_max = std::max(stall_max, m.stalled);
      longest_stall = std::max(longest_stall, m.longest_stall);
      yield_total += m.yielding;
      sidestep_total += m.sidestepping;
      if (m.arrived) last_arrival = m.tick;
      if (writer) {
        writer->frame(t, sim.world());  // the writer keeps every n-th frame
        writer->metrics(m);
      }
      if (tty && (progress_clock.seconds() > 0.2 || t == sc.ticks)) {
        progress_clock.restart();
        std::fprintf(
            stderr,
            "\rtick %llu/%llu (%.1f s)  agents %zu  arrived %zu  stalled %zu  overlaps %zu  "
            "%.1f ticks/s   ",
            static_cast<unsigned long long>(t), static_cast<unsigned long long>(sc.ticks), m.time,
            m.agents, sim.arrived_total(), m.stalled, m.overlapping_pairs,
            static_cast<double>(t) / clock.seconds());
      }
    }
    if (tty) std::fprintf(stderr, "\n");
    if (writer) {
      io::RunInfo info;
      info.threads = sc.config.threads;
      info.ticks = sc.ticks;
      info.final_hash = sim.state_hash();
      info.seconds = clock.seconds();
      writer->finish(info);
    }
  } catch (...) {
    if (tty) std::fprintf(stderr, "\n");
    if (writer) writer->abort();
    std::signal(SIGINT, old_int);
    std::signal(SIGTERM, old_term);
    throw;
  }
  std::signal(SIGINT, old_int);
  std::signal(SIGTERM, old_term);

  const double total = clock.seconds();
  double sum = 0;
  for (double s : tick_seconds) sum += s;
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(2);
  const std::string name = sc.name.empty() ? o.scenario : sc.name;
  const double dt = sc.config.dt;
  const double sim_seconds = static_cast<double>(sc.ticks) * dt;
  auto g = [](double v) {  // shortest form: 0.2, 5, 1e-05
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return std::string(buf);
  };
  auto secs = [&](std::size_t ticks) {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(1);
    s << static_cast<double>(ticks) * dt << " s";
    return s.str();
  };
  os << name << ": " << sc.ticks << " ticks of " << g(dt) << " s (" << sim_seconds
     << " s simulated) in " << total << " s, model " << sc.config.steering.model;
  if (!tick_seconds.empty()) {
    os << "\n  speed: " << static_cast<double>(sc.ticks) / std::max(sum, 1e-12)
       << " ticks/s; per tick mean " << 1e3 * sum / static_cast<double>(tick_seconds.size())
       << " ms, median " << 1e3 * experiment::median(tick_seconds) << " ms; " << sc.config.threads
       << " thread" << (sc.config.threads > 1 ? "s" : "");
  }
  os << "\n  agents: " << agents_at_start << " at start";
  if (!sim.world().sources().empty())
    os << ", " << sim.entered_total() << " entered from sources (" << sim.waiting_to_enter()
       << " still to enter)";
  os << ", " << sim.world().agents().size() << " at end; arrived " << sim.arrived_total();
  if (last_arrival) os << " (the last at " << secs(last_arrival) << ")";
  if (sim_seconds > 0)
    os << ", " << static_cast<double>(sim.arrived_total()) * 60 / sim_seconds
       << " arrivals per minute";
  os << "\n  overlaps after a tick: at most " << max_pairs << " agent pairs and " << max_obstacle
     << " agent-obstacle; at the end " << sim.last_metrics().overlapping_pairs
     << " pairs\n  backoff: " << (sc.config.backoff ? "on" : "off") << ", " << frozen_total
     << " agent-ticks frozen";
  if (sc.config.backoff && sc.ticks > 0)
    os << ", freeze rounds per tick mean "
       << static_cast<double>(iterations_total) / static_cast<double>(sc.ticks) << " max "
       << iterations_max;
  os << "\n  gridlock (frozen " << g(sc.config.gridlock_time)
     << " s in a row): " << gridlock_streaks << " streaks reached it, at most " << gridlock_max
     << " agents at once, " << sim.last_metrics().gridlocked
     << " at the end; longest frozen streak " << secs(longest_frozen);
  os << "\n  stalled (no progress for " << g(sc.config.stall.after) << " s): " << stall_streaks
     << " times, at most " << stall_max << " agents at once, " << sim.last_metrics().stalled
     << " at the end; longest " << secs(longest_stall) << " without progress";
  if (sc.config.stall.resolve)
    os << "; resolved by " << yield_total << " yields and " << sidestep_total << " sidesteps";
  else
    os << "; resolution off";
  os << "\n  nudge: ";
  if (sc.config.nudge_after > 0)
    os << "sidestep after " << g(sc.config.nudge_after) << " s frozen, " << nudged_total
       << " agent-ticks nudged";
  else
    os << "off (nudge_after = 0)";
  os << "\n  final state hash " << hex(sim.state_hash()) << "\n";
  if (writer)
    os << "  trajectories: " << sc.output.path << " ("
       << (sc.output.format == OutputSpec::Format::csv ? "csv" : "sqlite, JuPedSim format v3")
       << ")\n";
  std::cout << os.str();
  if (o.analyze) std::cout << sim.explain() << sim.explain_analyze();
  return 0;
}

}  // namespace

void add_run_command(CLI::App& app, Action& action) {
  static RunOptions o;
  auto* sub = app.add_subcommand("run", "simulate a scenario file (see docs/scenario-format.md)");
  sub->add_option("scenario", o.scenario, "scenario JSON file")->required();
  sub->add_option("--ticks", o.ticks, "number of ticks (overrides the file)")
      ->check(CLI::Range(int64_t{0}, int64_t{1'000'000'000}));
  sub->add_option("--duration", o.duration, "simulated seconds (overrides the file)")
      ->check(CLI::Range(0.0, 1e9))
      ->excludes("--ticks");
  sub->add_option("--model", o.model, "steering model: orca, cfsm, thesis (overrides the file)");
  sub->add_option("--out", o.out, "trajectory output: FILE.sqlite (JuPedSim format) or FILE.csv");
  sub->add_option("--format", o.format, "output format when the extension does not say")
      ->check(CLI::IsMember({"sqlite", "csv"}));
  sub->add_flag("--no-output", o.no_output, "write no trajectories");
  sub->add_option("--every", o.every, "write every n-th frame")->check(CLI::PositiveNumber);
  sub->add_flag("--explain", o.explain, "print the tick's query plan and exit");
  sub->add_flag("--explain-analyze", o.analyze,
                "run, then print the plan with rows and time per operator");
  sub->add_option("--threads", o.threads, "threads (results do not depend on it)")
      ->check(CLI::Range(1, 256));
  sub->add_flag("--no-backoff", o.no_backoff, "switch the backoff freeze loop off");
  sub->add_option("--nudge-after", o.nudge_after,
                  "sidestep agents frozen this many seconds in a row; 0 = never (overrides the "
                  "file's nudge_after)")
      ->check(CLI::Range(0.0, 1e6));
  sub->add_flag("--no-navigation", o.no_navigation,
                "switch the path service off (agents steer straight at their goals)");
  sub->add_option("--ftc", o.ftc, "first-to-collide access path (auto, naive, ...)");
  sub->add_option("--field", o.field, "potential-field access path (auto, naive, ...)");
  sub->add_option("--collisions", o.collisions, "collision-set access path (auto, naive, ...)");
  sub->add_flag("--quiet", o.quiet, "no progress line");
  sub->callback([&action] { action = [] { return run(o); }; });
}

void add_validate_command(CLI::App& app, Action& action) {
  static std::string file;
  auto* sub = app.add_subcommand("validate", "check a scenario file without running it");
  sub->add_option("scenario", file, "scenario JSON file")->required();
  sub->callback([&action] {
    action = [] {
      Scenario sc = load_scenario(file);
      print_warnings(sc);
      const std::size_t agents = sc.world.agents().size(), goals = sc.world.goals().size();
      const std::size_t circles = sc.world.circles().size(), polygons = sc.world.polygons().size();
      Simulation sim(std::move(sc.world), sc.config);  // also checks the access-path choices
      std::cout << file << ": ok: " << (sc.name.empty() ? "(unnamed)" : sc.name) << ", " << agents
                << " agents, " << goals << " goals, " << circles << " circles, " << polygons
                << " polygons, " << sc.ticks << " ticks\n";
      return 0;
    };
  });
}

}  // namespace crowddb::cli
