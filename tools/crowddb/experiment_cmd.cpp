// `crowddb experiment NAME --out DIR [--quick]`: the thesis's experiments (DESIGN.md §7).
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "crowddb/error.hpp"
#include "experiment/experiment.hpp"
#include "io/overrides.hpp"
#include "steer/model.hpp"

namespace crowddb::cli {

void add_experiment_command(CLI::App& app, Action& action) {
  auto* sub =
      app.add_subcommand("experiment", "reproduce an experiment of the thesis (CSV + PNG plots)");
  static std::string name, out;
  static experiment::Options opts;
  std::string names;
  for (const auto& e : experiment::registry()) names += "\n  " + e.name + ": " + e.description;
  sub->add_option("name", name,
                  "experiment:" + (names.empty() ? std::string(" (none registered yet)") : names))
      ->required();
  sub->add_option("--out", out, "output folder (created if missing)")->required();
  sub->add_flag("--quick", opts.quick, "small sizes, for tests and a first look");
  sub->add_option("--threads", opts.threads, "threads")->check(cli_checks::whole(1, 256));
  sub->add_option("--seed", opts.seed, "base seed");
  sub->add_option("--seeds", opts.seeds,
                  "bottleneck: run each case with this many seeds from --seed on and report the "
                  "mean flow and its range (default 1)")
      ->check(cli_checks::whole(1, 1000));
  sub->add_option("--model", opts.models,
                  "fd, bottleneck: run only this steering model (repeatable; default: every model "
                  "but thesis)");
  add_set_option(sub, opts.overrides);
  sub->callback([&action] {
    action = [] {
      const auto& e = experiment::find(name);
      if (!e.runs_scenarios && (!opts.models.empty() || !opts.overrides.empty()))
        throw Error(Error::Kind::usage,
                    "--model and --set apply to the experiments that run scenarios (fd, "
                    "bottleneck), not to " +
                        name);
      if (!e.averages_seeds && opts.seeds != 1)
        throw Error(Error::Kind::usage,
                    "--seeds applies to the bottleneck experiment, not to " + name);
      for (const std::string& m : opts.models) steer::find_model(m);
      for (const std::string& s : opts.overrides)
        if (s.rfind("steering.model=", 0) == 0)
          throw Error(Error::Kind::usage, "--set " + s + ": pick models with --model");
      {  // a malformed --set is the command's error, before anything runs
        nlohmann::json probe = nlohmann::json::object();
        io::apply_overrides(probe, opts.overrides);
      }
      std::error_code ec;
      std::filesystem::create_directories(out, ec);
      if (ec || !std::filesystem::is_directory(out))
        throw Error(Error::Kind::io, out + ": cannot create output folder");
      opts.out_dir = out;
      opts.log = &std::cerr;
      e.run(opts);
      return 0;
    };
  });
}

}  // namespace crowddb::cli
