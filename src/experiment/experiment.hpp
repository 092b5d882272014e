// Reproductions of the thesis's experiments (DESIGN.md §7) as `crowddb experiment NAME`. Each
// writes CSV files and PNG plots (gnuplot) into an output folder; --quick shrinks the sizes so
// the test suite can run it.
#pragma once

#include <filesystem>
#include <fstream>
#include <functional>
#include <iosfwd>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace crowddb::experiment {

struct Options {
  std::filesystem::path out_dir;
  bool quick = false;
  int threads = 1;
  uint64_t seed = 1;
  int seeds = 1;  // experiments that average over seeds: seed, seed + 1, ..., seed + seeds - 1
  std::ostream* log = nullptr;  // progress lines; may be null
  // Experiments that run scenario documents (fd, bottleneck): the steering models to run (empty:
  // every model the experiment compares) and fields to set in each document before it is read
  // ("KEY=VALUE" as crowddb run --set), to validate a parameter set against the data.
  std::vector<std::string> models;
  std::vector<std::string> overrides;
};

struct Experiment {
  std::string name;         // "e1"
  std::string description;  // one line for --help
  std::function<void(const Options&)> run;
  bool runs_scenarios = false;  // takes Options::models and Options::overrides
  bool averages_seeds = false;  // takes Options::seeds
};

// All registered experiments, in name order. Add new ones in registry.cpp.
const std::vector<Experiment>& registry();
// Throws crowddb::Error(usage) listing the valid names when unknown.
const Experiment& find(std::string_view name);

// A CSV file written row by row; numbers in shortest round-trip form.
class CsvWriter {
 public:
  CsvWriter(const std::filesystem::path& path, std::span<const std::string> header);
  void row(std::span<const double> values);
  void row(std::span<const std::string> cells);
  void close();

 private:
  std::filesystem::path path_;
  std::ofstream out_;
};

// Runs gnuplot on `script` (which should `set output` to a PNG in out_dir); the script is kept
// beside the plot as NAME.gp so users can restyle it. Throws crowddb::Error(io) on failure.
void plot(const std::filesystem::path& out_dir, const std::string& name, const std::string& script);

struct MeanSd {
  double mean = 0;
  double sd = 0;  // sample standard deviation
};
MeanSd mean_sd(std::span<const double> values);
double median(std::vector<double> values);

// One line describing where a figure was measured: CPU model, load average, threads, build flags.
std::string machine_note(int threads);

}  // namespace crowddb::experiment
