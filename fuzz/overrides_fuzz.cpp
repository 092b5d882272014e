// libFuzzer target: --set KEY=VALUE overrides (src/io/overrides.cpp). The input is split into
// lines, each one override, applied to a small scenario document. Any input must end in the
// document changed or a crowddb::Error; a crash, a sanitizer report or another exception is a bug.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "crowddb/error.hpp"
#include "io/overrides.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> items;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto nl = text.find('\n', start);
    items.push_back(text.substr(start, nl == std::string::npos ? nl : nl - start));
    if (nl == std::string::npos) break;
    start = nl + 1;
  }
  nlohmann::json doc = nlohmann::json::parse(
      R"({"name": "n", "steering": {"orca": {}}, "groups": [{"count": 5}, {"count": 2}]})");
  try {
    crowddb::io::apply_overrides(doc, items);
    (void)doc.dump();
  } catch (const crowddb::Error&) {
  }
  return 0;
}
