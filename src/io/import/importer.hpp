// Importers: readers of other simulators' scenario files. Each turns a file into a crowddb scenario
// document (docs/scenario-format.md) that the ordinary scenario reader then loads, so that
// `crowddb convert FILE --to json` and `crowddb run FILE` build the same world bit for bit.
// What each format maps to, and what is dropped, is in docs/importers.md; every drop or
// approximation is also a one-line warning naming the element.
//
// A new format is a reader here and one entry in registry.cpp.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "crowddb/scenario.hpp"
#include "io/scenario_doc.hpp"

namespace crowddb::io {

struct Imported {
  nlohmann::json doc;                 // a crowddb scenario document
  Origins origins;                    // where its fields came from (for error messages)
  std::vector<std::string> warnings;  // "file:LINE: <element>: what was dropped or approximated"
};

struct Importer {
  const char* name;         // "steersuite"
  const char* description;  // one line, for --help and docs
  // Whether the file is in this format: by its extension and its first bytes.
  bool (*claims)(const std::filesystem::path& path, std::string_view head);
  // Reads the file (its text already loaded); throws Error(input) naming the file, line and
  // element of the first problem.
  Imported (*read)(const std::filesystem::path& path, std::string_view text,
                   const LoadOptions& options);
};

// Every importer, in the order they are tried.
std::span<const Importer> importers();
// The importer that claims the file, or nullptr (a crowddb scenario).
const Importer* importer_for(const std::filesystem::path& path, std::string_view head);

// The name of the first element of an XML text ("" when none): how the XML formats are told
// apart without parsing the whole file.
std::string xml_root_name(std::string_view text);

// Reads a whole file; Error(io) when it cannot.
std::string read_file(const std::filesystem::path& path);

}  // namespace crowddb::io
