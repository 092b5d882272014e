// Menge projects, scene and behaviour files -> a crowddb scenario document. The mapping (which
// element becomes what, what is dropped or approximated, and how a behaviour's state machine is
// compiled into per-agent goal sequences) is in docs/importers/menge.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "io/import/importer.hpp"

namespace crowddb::io {

// A project file (<Project>), or a scene (<Experiment>) with options.behavior or with NameB.xml
// beside NameS.xml. A behaviour file (<BFSM>) alone is an error saying what to pass instead.
Imported import_menge(const std::filesystem::path& path, std::string_view text,
                      const LoadOptions& options);

// What a project file adds to a scene and behaviour pair (defaults: Menge's, for a scene loaded
// without a project).
struct ProjectSettings {
  std::string name;            // the document's name (the project's or the scene's stem)
  std::string origin;          // "project.xml:LINE: <Project>" for messages; "" without one
  std::string model = "orca";  // Menge's pedestrian model
  bool model_given = false;    // false: none was named (orca assumed, with a warning)
  double time_step = -1;       // [s] the project's timeStep; <= 0: the scene's time_step
  uint64_t sub_steps = 0;      // the project's subSteps (dt = time_step / (1 + subSteps))
  double duration = 400;       // [s] Menge's default
  uint64_t seed = 0;           // `random`; 0 (Menge: a time-based seed) gives seed 1
  std::size_t max_agents = kMaxScenarioAgents;  // more is an error (fuzzing lowers it)
};

// The in-memory entry (fuzzing, tests): a scene and a behaviour text with the names used in
// messages. Throws Error(input) naming "file:LINE: <element>" of the first problem.
Imported import_menge_pair(std::string_view scene_text, const std::string& scene_name,
                           std::string_view behavior_text, const std::string& behavior_name,
                           const ProjectSettings& settings);

}  // namespace crowddb::io
