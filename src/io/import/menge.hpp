// Menge files -> a crowddb scenario document (docs/importers.md).
#pragma once

#include <filesystem>
#include <string_view>

#include "io/import/importer.hpp"

namespace crowddb::io {

Imported import_menge(const std::filesystem::path& path, std::string_view text,
                   const LoadOptions& options);

}  // namespace crowddb::io
