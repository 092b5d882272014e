// SteerSuite test cases (<SteerBenchTestCase> XML) -> a crowddb scenario document.
// The mapping (axes, units, placement, goals, what is dropped) is in docs/importers.md.
#pragma once

#include <filesystem>
#include <string_view>

#include "io/import/importer.hpp"

namespace crowddb::io {

Imported import_steersuite(const std::filesystem::path& path, std::string_view text,
                           const LoadOptions& options);

}  // namespace crowddb::io
