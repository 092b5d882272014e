// The scenario reader's entry point for documents converted from other formats (src/io/import).
#pragma once

#include <map>
#include <string>
#include <string_view>

#include "crowddb/scenario.hpp"

namespace crowddb::io {

// Where the fields of a converted document came from: a JSON pointer ("/agents/3") and the element
// of the original file it was made from ("case.xml:57: <agent>"). An error in a field names the
// nearest origin at or above its pointer.
using Origins = std::map<std::string, std::string>;

// parse_scenario, with errors pointing into the original file when `origins` is given.
Scenario parse_document(std::string_view json_text, const std::string& source,
                        const Origins* origins);

}  // namespace crowddb::io
