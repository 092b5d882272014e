// Scenario files (docs/scenario-format.md): a JSON document describing the world (bounds,
// goals, obstacles, explicit agents and generated groups), the steering and backoff settings,
// the access paths, the tick count and the output. Loading builds a World with the agents as
// pending inserts and a SimConfig, ready for Simulation.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "crowddb/simulation.hpp"
#include "crowddb/world.hpp"

namespace crowddb {

struct OutputSpec {
  enum class Format { sqlite, csv };
  std::string path;  // empty: no trajectory output
  Format format = Format::sqlite;
  uint32_t every = 1;  // write every n-th frame (frame 0 and the last are always written)
};

struct Scenario {
  std::string name;
  std::string source;  // file name (for messages) and the JSON text (stored with trajectories)
  std::string text;
  World world;
  SimConfig config;
  uint64_t ticks = 100;
  OutputSpec output;
  std::vector<std::string> warnings;  // e.g. agents spawned overlapping; the run goes on
};

// Parses and validates a scenario. Errors are crowddb::Error with one line naming the file and
// either the line:column (malformed JSON) or the JSON pointer of the field (invalid values).
Scenario parse_scenario(std::string_view json_text, const std::string& source_name);
Scenario load_scenario(const std::filesystem::path& path);

}  // namespace crowddb
