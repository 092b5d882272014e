// Vadere .scenario files (JSON, releases 0.1 to 2.4) -> a crowddb scenario document
// (docs/importers/vadere.md lists every element and key and what becomes of it).
#pragma once

#include <filesystem>
#include <string_view>

#include "io/import/importer.hpp"

namespace crowddb::io {

Imported import_vadere(const std::filesystem::path& path, std::string_view text,
                       const LoadOptions& options);

}  // namespace crowddb::io
