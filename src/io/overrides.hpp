// Overrides of a scenario document's fields from the command line (crowddb run/bench --set),
// applied before the document is validated, so every file format takes them the same way.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace crowddb::io {

// Each override is "KEY=VALUE": KEY a dotted path ("steering.orca.time_gap"; a number indexes an
// array: "groups.0.count"), VALUE JSON text, or a plain string when it is not JSON ("orca").
// Missing objects on the path are created. Throws Error(usage) naming the override when KEY or
// VALUE is malformed or the path runs through a value that is not an object or array.
void apply_overrides(nlohmann::json& doc, const std::vector<std::string>& overrides);

}  // namespace crowddb::io
