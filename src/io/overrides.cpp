#include "io/overrides.hpp"

#include <charconv>
#include <nlohmann/json.hpp>

#include "crowddb/error.hpp"

namespace crowddb::io {
namespace {

[[noreturn]] void fail(const std::string& item, const std::string& what) {
  throw Error(Error::Kind::usage, "--set '" + item + "': " + what);
}

}  // namespace

void apply_overrides(nlohmann::json& doc, const std::vector<std::string>& overrides) {
  for (const std::string& item : overrides) {
    try {  // a document holds UTF-8 only (writing it out would throw)
      (void)nlohmann::json(item).dump();
    } catch (const nlohmann::json::type_error&) {
      const std::string shown =
          nlohmann::json(item).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      fail(shown.substr(1, shown.size() - 2), "not valid UTF-8");
    }
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0) fail(item, "expected KEY=VALUE");
    const std::string key = item.substr(0, eq), text = item.substr(eq + 1);
    nlohmann::json value = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (value.is_discarded()) value = text;  // not JSON: a string ("orca")
    nlohmann::json* at = &doc;
    std::size_t start = 0;
    while (true) {
      const auto dot = key.find('.', start);
      const std::string seg = key.substr(start, dot == std::string::npos ? dot : dot - start);
      if (seg.empty()) fail(item, "empty key segment in '" + key + "'");
      if (at->is_null()) *at = nlohmann::json::object();
      if (at->is_array()) {
        std::size_t index = 0;
        const auto [end, ec] = std::from_chars(seg.data(), seg.data() + seg.size(), index);
        if (ec != std::errc() || end != seg.data() + seg.size())
          fail(item, "'" + seg + "' indexes an array: expected a number");
        if (index >= at->size())
          fail(item, "index " + seg + " is past the array's end (" + std::to_string(at->size()) +
                         " elements)");
        at = &(*at)[index];
      } else if (at->is_object()) {
        at = &(*at)[seg];
      } else {
        fail(item, (start ? "'" + key.substr(0, start - 1) + "'" : std::string("the document")) +
                       " is not an object");
      }
      if (dot == std::string::npos) break;
      start = dot + 1;
    }
    *at = std::move(value);
  }
}

}  // namespace crowddb::io
