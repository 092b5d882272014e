// SteerSuite test cases (<SteerBenchTestCase> XML) -> a crowddb scenario document.
// The mapping (axes, units, placement, goals, what is dropped) is in docs/importers.md.
#pragma once

#include <filesystem>
#include <string_view>

#include "io/import/importer.hpp"

namespace crowddb::io {

Imported import_steersuite(const std::filesystem::path& path, std::string_view text,
                           const LoadOptions& options);
// The same with a smaller cap on the number of agents (the fuzzer's, to keep runs short).
Imported import_steersuite(const std::filesystem::path& path, std::string_view text,
                           const LoadOptions& options, std::size_t max_agents);

}  // namespace crowddb::io
