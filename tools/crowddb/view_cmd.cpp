// `crowddb view RUN [--port P] [--host H]`: plays a run back in the browser (docs/viewer.md).
#include <cstdio>

#include "commands.hpp"
#include "view/server.hpp"

namespace crowddb::cli {

void add_view_command(CLI::App& app, Action& action) {
  auto* sub = app.add_subcommand(
      "view", "play a run back in the browser: a local, read-only web server (Ctrl-C stops it)");
  static std::string file, host = "127.0.0.1";
  static int port = 8080;
  sub->add_option("file", file, "the run: a crowddb SQLite output or a JuPedSim trajectory file")
      ->required();
  sub->add_option("--port", port, "TCP port (0: any free port; the address is printed)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  sub->add_option("--host", host,
                  "address to listen on (default loopback only; the server is read-only)")
      ->capture_default_str();
  sub->callback([&action] {
    action = [] {
      view::RunFile run = view::RunFile::open(file);
      view::ServeOptions opt;
      opt.host = host;
      opt.port = port;
      view::serve(run, opt, [](const std::string& url) {
        std::printf("crowddb view: %s  (%s; Ctrl-C stops)\n", url.c_str(), file.c_str());
        std::fflush(stdout);
      });
      return 0;
    };
  });
}

}  // namespace crowddb::cli
