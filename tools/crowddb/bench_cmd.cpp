// `crowddb bench DIR|FILE...`: runs many scenarios (any supported format) and prints one row each,
// for comparing models and versions. A file that fails to load or run gives a row with its error;
// the others still run.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "crowddb/error.hpp"
#include "io/import/importer.hpp"
#include "io/overrides.hpp"
#include "metrics/run.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::cli {
namespace {

namespace fs = std::filesystem;

struct BenchOptions {
  std::vector<std::string> paths;
  std::string model, csv;
  std::vector<std::string> overrides;
  int threads = 0;
  double duration = -1;
  bool quiet = false;
};

bool scenario_extension(const fs::path& p) {
  std::string e = p.extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e == ".json" || e == ".xml" || e == ".scenario";
}

// The scene a Menge project names (its `scene` attribute, relative to the project), if any.
fs::path project_scene(const fs::path& project, const std::string& head) {
  auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  for (std::size_t at = head.find("scene"); at != std::string::npos;
       at = head.find("scene", at + 1)) {
    if (at == 0 || !space(head[at - 1])) continue;
    std::size_t k = at + 5;
    while (k < head.size() && space(head[k])) ++k;
    if (k >= head.size() || head[k] != '=') continue;
    ++k;
    while (k < head.size() && space(head[k])) ++k;
    if (k >= head.size() || (head[k] != '"' && head[k] != '\'')) continue;
    const auto end = head.find(head[k], k + 1);
    if (end == std::string::npos) return {};
    std::error_code ec;
    return fs::weakly_canonical(project.parent_path() / head.substr(k + 1, end - k - 1), ec);
  }
  return {};
}

// The files a directory contributes: scenarios of every format, but of Menge only what runs on
// its own: projects, and scenes that no project names and whose folder has no project (never
// behaviour files or the viewer's <View> files).
std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> all;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && scenario_extension(e.path())) all.push_back(e.path());
  std::sort(all.begin(), all.end());
  std::vector<fs::path> out;
  std::map<fs::path, bool> has_project;
  std::set<fs::path> named_scenes;
  std::vector<std::pair<fs::path, std::string>> roots;
  for (const fs::path& p : all) {
    std::string head = io::read_file(p).substr(0, 4096);
    const std::string root = io::xml_root_name(head);
    roots.emplace_back(p, root);
    if (root == "Project") {
      has_project[p.parent_path()] = true;
      if (fs::path scene = project_scene(p, head); !scene.empty()) named_scenes.insert(scene);
    }
  }
  for (const auto& [p, root] : roots) {
    if (root == "BFSM" || root == "View") continue;
    std::error_code ec;
    if (root == "Experiment" &&
        (has_project.count(p.parent_path()) || named_scenes.count(fs::weakly_canonical(p, ec))))
      continue;
    out.push_back(p);
  }
  return out;
}

struct Row {
  std::string file, error;
  metrics::RunSummary s;
};

std::string num(double v, int precision = 2) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(precision);
  os << v;
  return os.str();
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

int bench(const BenchOptions& o) {
  {  // a malformed --set is the command's error, not every row's
    nlohmann::json probe = nlohmann::json::object();
    io::apply_overrides(probe, o.overrides);
  }
  std::vector<fs::path> files;
  for (const std::string& p : o.paths) {
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      const auto in = files_in(p);
      if (in.empty()) throw Error(Error::Kind::io, p + ": no scenario files in this directory");
      files.insert(files.end(), in.begin(), in.end());
    } else if (fs::exists(p, ec)) {
      files.emplace_back(p);
    } else {
      throw Error(Error::Kind::io, p + ": no such file or directory");
    }
  }
  if (!o.csv.empty() && o.csv != "-") {
    const fs::path dir = fs::path(o.csv).parent_path();
    if (!dir.empty() && !fs::is_directory(dir))
      throw Error(Error::Kind::io, o.csv + ": no such directory");
  }
  const bool tty = isatty(STDERR_FILENO) && !o.quiet;
  std::vector<Row> rows;
  std::size_t failed = 0;
  for (std::size_t k = 0; k < files.size(); ++k) {
    Row row;
    row.file = files[k].string();
    try {
      Scenario sc = load_scenario(files[k], LoadOptions{{}, o.overrides});
      if (!o.model.empty()) sc.config.steering.model = o.model;
      if (o.threads > 0) sc.config.threads = o.threads;
      if (o.duration >= 0) sc.ticks = sc.config.ticks_for(o.duration, 0);
      sc.output.path.clear();
      if (!o.quiet) print_warnings(sc);
      Simulation sim(std::move(sc.world), sc.config);
      metrics::RunControl control;
      Stopwatch progress;
      if (tty)
        control.on_tick = [&](const Simulation&, const TickMetrics& m, uint64_t planned) {
          if (progress.seconds() < 0.2) return;
          progress.restart();
          std::fprintf(stderr, "\r[%zu/%zu] %s: tick %llu/%llu   ", k + 1, files.size(),
                       row.file.c_str(), static_cast<unsigned long long>(m.tick),
                       static_cast<unsigned long long>(planned));
        };
      row.s = metrics::run_to_end(sc, sim, control);
    } catch (const Error& e) {
      row.error = e.what();
      ++failed;
    } catch (const std::exception& e) {
      row.error = std::string("internal error: ") + e.what();
      ++failed;
    }
    if (tty) std::fprintf(stderr, "\r\033[K");
    if (!o.quiet)
      std::fprintf(
          stderr, "[%zu/%zu] %s: %s\n", k + 1, files.size(), row.file.c_str(),
          row.error.empty() ? (row.s.all_arrived ? "everyone arrived" : "ran") : row.error.c_str());
    rows.push_back(std::move(row));
  }

  // The table.
  std::ostringstream t;
  t << std::left << std::setw(44) << "scenario" << std::right << std::setw(11) << "format"
    << std::setw(7) << "agents" << std::setw(8) << "arrived" << std::setw(5) << "all"
    << std::setw(9) << "last [s]" << std::setw(9) << "overlaps" << std::setw(8) << "stalled"
    << std::setw(10) << "stall [s]" << std::setw(8) << "frozen" << std::setw(12) << "composite02"
    << std::setw(9) << "wall [s]" << std::setw(9) << "ms/tick"
    << "\n";
  std::size_t all_arrived = 0;
  for (const Row& r : rows) {
    std::string name = r.file;
    if (name.size() > 43) name = "..." + name.substr(name.size() - 40);
    t << std::left << std::setw(44) << name << std::right;
    if (!r.error.empty()) {
      t << "  error: " << r.error << "\n";
      continue;
    }
    const auto& s = r.s;
    all_arrived += s.all_arrived;
    t << std::setw(11) << s.format << std::setw(7) << s.agents_total << std::setw(8) << s.arrived
      << std::setw(5) << (s.all_arrived ? "yes" : "no") << std::setw(9)
      << (s.last_arrival_s >= 0 ? num(s.last_arrival_s, 1) : "-") << std::setw(9)
      << (std::to_string(s.max_overlapping_pairs) + "/" + std::to_string(s.max_obstacle_overlaps))
      << std::setw(8) << s.stalled_at_end << std::setw(10) << num(s.max_stalled_s, 1)
      << std::setw(8) << s.frozen_agent_ticks << std::setw(12) << num(s.steerbench.composite02)
      << std::setw(9) << num(s.wall_seconds) << std::setw(9) << num(s.ms_per_tick_median, 3)
      << "\n";
  }
  t << rows.size() << " scenarios: " << all_arrived << " with everyone arrived, "
    << rows.size() - failed - all_arrived << " with someone left, " << failed << " failed\n";
  std::cout << t.str();

  if (!o.csv.empty()) {
    std::ostringstream c;
    c << "file,format,name,model,status,agents_total,arrived,all_arrived,last_arrival_s,"
         "sim_seconds,ticks,max_overlapping_pairs,max_obstacle_overlaps,stalled_at_end,"
         "without_path,max_stalled_s,frozen_agent_ticks,collisions,composite01,composite02,wall_"
         "seconds,"
         "ms_per_tick_median,state_hash,error\n";
    for (const Row& r : rows) {
      const auto& s = r.s;
      c << csv_field(r.file) << ",";
      if (!r.error.empty()) {
        c << ",,,error,,,,,,,,,,,,,,,,,,," << csv_field(r.error) << "\n";
        continue;
      }
      c << s.format << "," << csv_field(s.name) << "," << s.model << ",ok," << s.agents_total << ","
        << s.arrived << "," << (s.all_arrived ? 1 : 0) << ","
        << (s.last_arrival_s >= 0 ? format_number(s.last_arrival_s) : "") << ","
        << format_number(s.sim_seconds) << "," << s.ticks << "," << s.max_overlapping_pairs << ","
        << s.max_obstacle_overlaps << "," << s.stalled_at_end << "," << s.without_path << ","
        << format_number(s.max_stalled_s) << "," << s.frozen_agent_ticks << ","
        << s.steerbench.collisions << "," << format_number(s.steerbench.composite01) << ","
        << format_number(s.steerbench.composite02) << "," << format_number(s.wall_seconds) << ","
        << format_number(s.ms_per_tick_median) << "," << metrics::hex(s.state_hash) << ",\n";
    }
    write_output(o.csv, c.str());
  }
  return failed ? 1 : 0;
}

}  // namespace

void add_bench_command(CLI::App& app, Action& action) {
  static BenchOptions o;
  auto* sub = app.add_subcommand(
      "bench", "run many scenarios (any supported format) and print one row each");
  sub->add_option("paths", o.paths, "scenario files, or directories to search (recursively)")
      ->required();
  sub->add_option("--model", o.model, "steering model for every run: orca, cfsm, thesis");
  add_set_option(sub, o.overrides);
  sub->add_option("--csv", o.csv, "also write the table as CSV to FILE (\"-\": standard output)");
  sub->add_option("--threads", o.threads, "threads per run (results do not depend on it)")
      ->check(cli_checks::whole(1, 256));
  sub->add_option("--duration", o.duration, "simulated seconds per run (overrides the files)")
      ->check(cli_checks::finite(0, 1e9));
  sub->add_flag("--quiet", o.quiet, "no progress and no warnings on stderr");
  sub->callback([&action] { action = [] { return bench(o); }; });
}

}  // namespace crowddb::cli
