// `crowddb convert FILE --to json`: another simulator's scenario as an editable crowddb scenario.
#include <iostream>

#include "commands.hpp"
#include "crowddb/scenario.hpp"

namespace crowddb::cli {

void add_convert_command(CLI::App& app, Action& action) {
  static std::string file, to = "json", out = "-", behavior;
  static std::vector<std::string> overrides;
  auto* sub = app.add_subcommand(
      "convert",
      "write a SteerSuite, Menge or Vadere scenario as a crowddb scenario (docs/importers.md)");
  sub->add_option("scenario", file, "the file to convert (any supported format)")->required();
  sub->add_option("--to", to, "target format (json: crowddb's scenario format)")
      ->check(CLI::IsMember({"json"}));
  sub->add_option("--out", out, "output file (default: standard output)");
  sub->add_option("--behavior", behavior, "Menge: the behaviour file of a scene");
  add_set_option(sub, overrides);
  sub->callback([&action] {
    action = [] {
      const Converted c = convert_scenario(file, LoadOptions{behavior, overrides});
      for (const std::string& w : c.warnings) std::cerr << "crowddb: warning: " << w << "\n";
      write_output(out, c.json);
      if (out != "-")
        std::cerr << "crowddb: " << file << " (" << c.format << ") -> " << out << "\n";
      return 0;
    };
  });
}

}  // namespace crowddb::cli
