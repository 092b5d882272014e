// Subcommands of the `crowddb` CLI. Each registers its options on the app and returns the
// action to run after parsing; actions throw crowddb::Error, which main turns into one line on
// stderr and the exit status (2 usage, 1 other).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "crowddb/error.hpp"
#include "crowddb/scenario.hpp"

namespace crowddb::cli {

using Action = std::function<int()>;

void add_query_commands(CLI::App& app, Action& action);
void add_run_command(CLI::App& app, Action& action);
void add_resume_command(CLI::App& app, Action& action);
void add_validate_command(CLI::App& app, Action& action);
void add_experiment_command(CLI::App& app, Action& action);
void add_fit_kernel_command(CLI::App& app, Action& action);
void add_verify_command(CLI::App& app, Action& action);
void add_convert_command(CLI::App& app, Action& action);
void add_bench_command(CLI::App& app, Action& action);
void add_render_command(CLI::App& app, Action& action);
void add_view_command(CLI::App& app, Action& action);

// The --set KEY=VALUE option (LoadOptions::overrides) of the commands that load scenarios.
void add_set_option(CLI::App* sub, std::vector<std::string>& overrides);

// Prints a loaded scenario's warnings on stderr, one line each, naming the file.
void print_warnings(const Scenario& sc);

// Runs `work`; an input error it throws that does not yet name a file (one the engine finds
// after loading, such as a navigation mesh that cannot be built) is said to be about `file`.
template <class F>
auto naming_file(const std::string& file, F&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const Error& e) {
    const std::string msg = e.what();
    if (e.kind() != Error::Kind::input || msg.rfind(file, 0) == 0) throw;
    throw Error(Error::Kind::input, file + ": " + msg);
  }
}

// Shortest decimal that reads back as the same double.
std::string format_number(double v);

// Writes `text` to `path` atomically: a temporary file beside it, renamed on success, so a
// failed run never leaves a half-written file that looks complete. "-" writes to stdout.
void write_output(const std::string& path, const std::string& text);

}  // namespace crowddb::cli
