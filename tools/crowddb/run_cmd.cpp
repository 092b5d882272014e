// `crowddb run` and `crowddb validate`: simulate a scenario file.
#include "commands.hpp"

namespace crowddb::cli {

void add_run_command(CLI::App&, Action&) {}
void add_validate_command(CLI::App&, Action&) {}

}  // namespace crowddb::cli
