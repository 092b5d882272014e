// crowddb: the crowd simulation database's command-line tool.
#include <iostream>

#include "commands.hpp"
#include "crowddb/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"crowddb: crowd simulation as an in-memory database (see README.md)", "crowddb"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "crowddb 0.1.0");
  crowddb::cli::Action action;
  crowddb::cli::add_run_command(app, action);
  crowddb::cli::add_resume_command(app, action);
  crowddb::cli::add_validate_command(app, action);
  crowddb::cli::add_query_commands(app, action);
  crowddb::cli::add_experiment_command(app, action);
  crowddb::cli::add_fit_kernel_command(app, action);
  crowddb::cli::add_verify_command(app, action);
  crowddb::cli::add_convert_command(app, action);
  crowddb::cli::add_bench_command(app, action);
  crowddb::cli::add_render_command(app, action);
  crowddb::cli::add_view_command(app, action);
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
    std::cerr << "crowddb: " << msg << " (see --help)\n";
    return 2;
  }
  try {
    return action ? action() : 0;
  } catch (const crowddb::Error& e) {
    std::cerr << "crowddb: " << e.what() << "\n";
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    // Name the work that ran out: the command line holds its files.
    std::string command = "crowddb";
    for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
    if (command.size() > 200) command = command.substr(0, 197) + "...";
    std::cerr << "crowddb: out of memory (in: " << command << ")\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "crowddb: internal error: " << e.what() << "\n";
    return 1;
  }
}
