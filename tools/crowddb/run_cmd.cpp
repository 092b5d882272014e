// `crowddb run` and `crowddb validate`: simulate a scenario file.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "crowddb/error.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "experiment/experiment.hpp"
#include "io/trajectory.hpp"
#include "metrics/run.hpp"
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
  std::string behavior, summary_json;
  std::vector<std::string> overrides;
  double checkpoint_every = 60;  // [s] of wall time; SQLite output only
};

}  // namespace

// Warnings of an import already name their file and line.
void add_set_option(CLI::App* sub, std::vector<std::string>& overrides) {
  sub->add_option("--set", overrides,
                  "set a field of the scenario before it is checked: KEY=VALUE, KEY a dotted path "
                  "(steering.orca.time_gap), VALUE JSON or a string; repeatable");
}

void print_warnings(const Scenario& sc) {
  for (const auto& w : sc.warnings) {
    if (w.compare(0, sc.source.size() + 1, sc.source + ":") == 0)
      std::cerr << "crowddb: warning: " << w << "\n";
    else
      std::cerr << "crowddb: warning: " << sc.source << ": " << w << "\n";
  }
}

namespace {

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

int execute(const Scenario& sc, Simulation& sim, io::TrajectoryWriter* writer, const RunOptions& o,
            const std::string& file, const std::string* resume_from);

int run(const RunOptions& o) {
  Scenario sc = load_scenario(o.scenario, LoadOptions{o.behavior, o.overrides});
  apply_overrides(sc, o);
  print_warnings(sc);
  // Check the summary's path before running: a typo should not cost the whole run.
  if (!o.summary_json.empty() && o.summary_json != "-") {
    const std::filesystem::path dir = std::filesystem::path(o.summary_json).parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir))
      throw Error(Error::Kind::io, o.summary_json + ": no such directory");
  }
  Simulation sim =
      naming_file(o.scenario, [&] { return Simulation(std::move(sc.world), sc.config); });
  if (o.explain) {
    std::cout << sim.explain();
    return 0;
  }
  std::unique_ptr<io::TrajectoryWriter> writer;
  if (!sc.output.path.empty()) {
    writer = io::make_writer(sc.output);
    writer->begin(sc, sim.world());
  }
  return execute(sc, sim, writer.get(), o, o.scenario, nullptr);
}

// Runs a built (or restored) simulation to its end: signals, progress line, summary.
int execute(const Scenario& sc, Simulation& sim, io::TrajectoryWriter* writer, const RunOptions& o,
            const std::string& file, const std::string* resume_from) {
  g_interrupted = false;
  auto old_int = std::signal(SIGINT, on_interrupt);
  auto old_term = std::signal(SIGTERM, on_interrupt);
  const bool tty = isatty(STDERR_FILENO) && !o.quiet;
  metrics::RunControl control;
  control.writer = writer;
  control.checkpoint_every = o.checkpoint_every;
  control.resume_from = resume_from;
  control.interrupted = [] { return g_interrupted.load(); };
  Stopwatch clock, progress_clock;
  if (tty)
    control.on_tick = [&](const Simulation& s, const TickMetrics& m, uint64_t planned) {
      if (progress_clock.seconds() < 0.2 && m.tick != planned) return;
      progress_clock.restart();
      std::fprintf(stderr,
                   "\rtick %llu/%llu (%.1f s)  agents %zu  arrived %zu  stalled %zu  overlaps "
                   "%zu  %.1f ticks/s   ",
                   static_cast<unsigned long long>(m.tick),
                   static_cast<unsigned long long>(planned), m.time, m.agents, s.arrived_total(),
                   m.stalled, m.overlapping_pairs, static_cast<double>(m.tick) / clock.seconds());
    };
  metrics::RunSummary summary;
  try {
    summary = naming_file(file, [&] { return metrics::run_to_end(sc, sim, control); });
  } catch (...) {
    if (tty) std::fprintf(stderr, "\n");
    std::signal(SIGINT, old_int);
    std::signal(SIGTERM, old_term);
    throw;
  }
  if (tty) std::fprintf(stderr, "\n");
  std::signal(SIGINT, old_int);
  std::signal(SIGTERM, old_term);
  if (summary.name.empty()) summary.name = file;
  std::string text = summary.text(sim.config());
  if (writer)
    text += "  trajectories: " + sc.output.path + " (" +
            (sc.output.format == OutputSpec::Format::csv ? "csv" : "sqlite, JuPedSim format v3") +
            ")\n";
  if (!o.summary_json.empty()) {
    write_output(o.summary_json, summary.json());
    if (o.summary_json != "-") text += "  summary: " + o.summary_json + "\n";
  }
  if (o.summary_json != "-") std::cout << text;
  if (o.analyze) std::cout << sim.explain() << sim.explain_analyze();
  return 0;
}

// `crowddb resume FILE`: an interrupted run's PATH.partial, continued from its checkpoint.
int resume(const std::string& file, const RunOptions& o) {
  const io::PartialRun p = io::read_partial_run(file);
  const std::string partial = p.path.string() + ".partial";
  Scenario sc = naming_file(partial, [&] {
    return parse_scenario(p.value("scenario_json"), p.value("scenario_source"));
  });
  try {
    const nlohmann::json opt = nlohmann::json::parse(p.value("resume_options"));
    sc.ticks = opt.at("ticks").get<uint64_t>();
    sc.stop_when_all_arrived = opt.at("stop_when_all_arrived").get<bool>();
    sc.format = opt.at("format").get<std::string>();
    sc.config.threads = opt.at("threads").get<int>();
    sc.config.steering.model = opt.at("model").get<std::string>();
    sc.config.backoff = opt.at("backoff").get<bool>();
    sc.config.nudge_after = opt.at("nudge_after").get<double>();
    sc.config.navigation.enabled = opt.at("navigation").get<bool>();
    sc.config.access.ftc = opt.at("ftc").get<std::string>();
    sc.config.access.field = opt.at("field").get<std::string>();
    sc.config.access.collisions = opt.at("collisions").get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    throw Error(Error::Kind::input, partial + ": bad resume_options (" + e.what() + ")");
  }
  if (sc.config.threads < 1 || sc.config.threads > 256)
    throw Error(Error::Kind::input, partial + ": bad resume_options (threads)");
  if (o.threads > 0) sc.config.threads = o.threads;
  sc.output.path = p.path.string();
  sc.output.format = OutputSpec::Format::sqlite;
  Simulation sim = naming_file(partial, [&] {
    Simulation s(std::move(sc.world), sc.config);
    s.restore_state(p.engine, partial + ": checkpoint");
    return s;
  });
  if (p.tick >= sc.ticks)
    throw Error(Error::Kind::input, partial + ": the checkpoint is at the run's last tick");
  auto writer = io::resume_sqlite_writer(p, sc.config.dt,
                                         sc.config.ticks_for(sc.config.stall.after), sc.format);
  if (!o.quiet)
    std::cerr << "crowddb: resuming " << (sc.name.empty() ? p.value("scenario_source") : sc.name)
              << " at tick " << p.tick << " of " << sc.ticks << " (" << partial << ")\n";
  return execute(sc, sim, writer.get(), o, p.value("scenario_source"), &p.progress);
}

}  // namespace

void add_resume_command(CLI::App& app, Action& action) {
  static RunOptions o;
  static std::string file;
  auto* sub = app.add_subcommand(
      "resume", "continue an interrupted run from its last checkpoint (its PATH.partial)");
  sub->add_option("file", file, "the interrupted run's output: PATH.partial (or PATH)")->required();
  sub->add_option("--threads", o.threads,
                  "threads (default: the run's; results do not depend on it)")
      ->check(cli_checks::whole(1, 256));
  sub->add_option("--checkpoint-every", o.checkpoint_every,
                  "seconds of wall time between checkpoints (default 60)")
      ->check(cli_checks::finite(0, 1e9));
  sub->add_option("--summary-json", o.summary_json,
                  "write the run's summary as JSON to FILE (\"-\": standard output)");
  sub->add_flag("--quiet", o.quiet, "no progress line");
  sub->callback([&action] { action = [] { return resume(file, o); }; });
}

void add_run_command(CLI::App& app, Action& action) {
  static RunOptions o;
  auto* sub = app.add_subcommand("run", "simulate a scenario file (see docs/scenario-format.md)");
  sub->add_option("scenario", o.scenario,
                  "scenario file: crowddb JSON, a SteerSuite test case, a Menge project or scene, "
                  "a Vadere .scenario (docs/importers.md)")
      ->required();
  sub->add_option("--behavior", o.behavior,
                  "Menge: the behaviour file of a scene (default: the project's, or NameB.xml "
                  "beside NameS.xml)");
  sub->add_option("--summary-json", o.summary_json,
                  "write the run's summary as JSON to FILE (\"-\": standard output, instead of "
                  "the text summary); keys in docs/summary-json.md");
  add_set_option(sub, o.overrides);
  sub->add_option("--ticks", o.ticks, "number of ticks (overrides the file)")
      ->check(cli_checks::whole(0, 1'000'000'000));
  sub->add_option("--duration", o.duration, "simulated seconds (overrides the file)")
      ->check(cli_checks::finite(0, 1e9))
      ->excludes("--ticks");
  sub->add_option("--model", o.model, "steering model: orca, cfsm, thesis (overrides the file)");
  sub->add_option("--out", o.out, "trajectory output: FILE.sqlite (JuPedSim format) or FILE.csv");
  sub->add_option("--format", o.format, "output format when the extension does not say")
      ->check(CLI::IsMember({"sqlite", "csv"}));
  sub->add_flag("--no-output", o.no_output, "write no trajectories");
  sub->add_option("--every", o.every, "write every n-th frame")
      ->check(cli_checks::whole_at_least(1));
  sub->add_flag("--explain", o.explain, "print the tick's query plan and exit");
  sub->add_flag("--explain-analyze", o.analyze,
                "run, then print the plan with rows and time per operator");
  sub->add_option("--threads", o.threads, "threads (results do not depend on it)")
      ->check(cli_checks::whole(1, 256));
  sub->add_flag("--no-backoff", o.no_backoff, "switch the backoff freeze loop off");
  sub->add_option("--nudge-after", o.nudge_after,
                  "sidestep agents frozen this many seconds in a row; 0 = never (overrides the "
                  "file's nudge_after)")
      ->check(cli_checks::finite(0, 1e6));
  sub->add_flag("--no-navigation", o.no_navigation,
                "switch the path service off (agents steer straight at their goals)");
  sub->add_option("--ftc", o.ftc, "first-to-collide access path (auto, naive, ...)");
  sub->add_option("--field", o.field, "potential-field access path (auto, naive, ...)");
  sub->add_option("--collisions", o.collisions, "collision-set access path (auto, naive, ...)");
  sub->add_flag("--quiet", o.quiet, "no progress line");
  sub->add_option("--checkpoint-every", o.checkpoint_every,
                  "seconds of wall time between checkpoints in SQLite output, so `crowddb resume` "
                  "can continue an interrupted run (default 60; 0: after every tick)")
      ->check(cli_checks::finite(0, 1e9));
  sub->callback([&action] { action = [] { return run(o); }; });
}

void add_validate_command(CLI::App& app, Action& action) {
  static std::string file, behavior;
  static std::vector<std::string> overrides;
  auto* sub = app.add_subcommand("validate", "check a scenario file without running it");
  sub->add_option("scenario", file, "scenario file (any supported format)")->required();
  sub->add_option("--behavior", behavior, "Menge: the behaviour file of a scene");
  add_set_option(sub, overrides);
  sub->callback([&action] {
    action = [] {
      Scenario sc = load_scenario(file, LoadOptions{behavior, overrides});
      print_warnings(sc);
      const std::size_t agents = sc.world.agents().size(), goals = sc.world.goals().size();
      const std::size_t circles = sc.world.circles().size(), polygons = sc.world.polygons().size();
      // Also checks the access-path choices and builds the navigation meshes.
      const Simulation sim =
          naming_file(file, [&] { return Simulation(std::move(sc.world), sc.config); });
      std::cout << file << ": ok" << (sc.format == "crowddb" ? "" : " (" + sc.format + ")") << ": "
                << (sc.name.empty() ? "(unnamed)" : sc.name) << ", " << agents << " agents, "
                << goals << " goals, " << circles << " circles, " << polygons << " polygons, "
                << sc.ticks << " ticks\n";
      return 0;
    };
  });
}

}  // namespace crowddb::cli
