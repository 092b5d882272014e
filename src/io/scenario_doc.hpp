// The scenario reader's entry point for documents converted from other formats (src/io/import).
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "crowddb/scenario.hpp"

namespace crowddb::io {

// Where the fields of a converted document came from: a JSON pointer ("/agents/3") and the element
// of the original file it was made from ("case.xml:57: <agent>"). An error in a field names the
// nearest origin at or above its pointer.
using Origins = std::map<std::string, std::string>;

// A scenario file's JSON, read strictly: a syntax error names its line and column, a duplicate
// key is an error (nlohmann keeps the last one silently). Error(input) naming `source`.
nlohmann::json parse_json_strict(std::string_view text, const std::string& source);

// parse_scenario, with errors pointing into the original file when `origins` is given.
Scenario parse_document(std::string_view json_text, const std::string& source,
                        const Origins* origins);

}  // namespace crowddb::io
