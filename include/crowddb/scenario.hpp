// Scenario files (docs/scenario-format.md): a JSON document describing the world (bounds,
// goals, obstacles, explicit agents and generated groups), the steering and backoff settings,
// the access paths, the tick count and the output. Loading builds a World with the agents as
// pending inserts and a SimConfig, ready for Simulation.
//
// load_scenario also reads other simulators' files (docs/importers.md): SteerSuite test cases,
// Menge projects and scene + behaviour pairs, Vadere .scenario files. They are converted to a
// crowddb document first (convert_scenario gives it), so both routes build the same world.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "crowddb/simulation.hpp"
#include "crowddb/world.hpp"

namespace crowddb {

// A scenario places at most this many agents at load time (explicit agents and groups together;
// importers count the agents they convert). Loading and validating need about 0.6 KB and 3 us per
// agent (2*10^6 uniformly placed: 1.13 GB, 5.8 s), so the limit bounds `validate` of any file;
// sources add agents during the run and are bounded by their own `count` instead.
inline constexpr std::size_t kMaxScenarioAgents = 2'000'000;

struct OutputSpec {
  enum class Format { sqlite, csv };
  std::string path;  // empty: no trajectory output
  Format format = Format::sqlite;
  // Write the state after every n-th tick: frame k holds tick k * every (JuPedSim frames are
  // evenly spaced, so a last tick that is not a multiple of `every` is not written).
  uint32_t every = 1;
};

struct Scenario {
  std::string name;
  std::string source;  // file name (for messages) and the JSON text (stored with trajectories)
  std::string text;
  World world;
  SimConfig config;
  uint64_t ticks = 100;
  // End the run at the first tick after which no agent is still heading for a goal and no source
  // has agents left to let in (key "stop_when_all_arrived"; imports of formats whose runs end so).
  bool stop_when_all_arrived = false;
  std::string format = "crowddb";  // the file's format: crowddb, steersuite, menge, vadere
  OutputSpec output;
  std::vector<std::string> warnings;  // e.g. agents spawned overlapping; the run goes on
};

// Parses and validates a crowddb scenario document. Errors are crowddb::Error with one line
// naming the file and either the line:column (malformed JSON) or the JSON pointer of the field
// (invalid values).
Scenario parse_scenario(std::string_view json_text, const std::string& source_name);

struct LoadOptions {
  // Menge: the behaviour file to pair with a scene file. Empty: a project file names both, and a
  // scene NameS.xml pairs with NameB.xml beside it.
  std::filesystem::path behavior;
  // Fields to set in the (converted) document before it is validated: "KEY=VALUE", KEY a dotted
  // path ("steering.orca.time_gap", "groups.0.count"), VALUE JSON or a plain string (crowddb
  // run/bench --set). Applied in order.
  std::vector<std::string> overrides;
};

// The format of a file: "crowddb", "steersuite", "menge" or "vadere" (by extension and content).
std::string scenario_format(const std::filesystem::path& path);

// Loads a scenario file of any supported format. Errors name the file, line (or JSON pointer) and
// element; an import's warnings (what was dropped or approximated) come first in `warnings`.
Scenario load_scenario(const std::filesystem::path& path, const LoadOptions& options = {});

// The crowddb scenario document equivalent to a file of any supported format (a crowddb file:
// its own text), with the import's warnings.
struct Converted {
  std::string json;
  std::string format;
  std::vector<std::string> warnings;
};
Converted convert_scenario(const std::filesystem::path& path, const LoadOptions& options = {});

}  // namespace crowddb
