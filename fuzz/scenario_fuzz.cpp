// libFuzzer target: scenario JSON. Any input must end in a Scenario or a crowddb::Error; a crash,
// a sanitizer report, another exception type or a hang is a bug.
#include <cstdint>
#include <string_view>

#include "crowddb/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    crowddb::Scenario sc = crowddb::parse_scenario(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    // Large generated worlds are legal but slow to fuzz through; the parse is what is tested.
    (void)sc;
  } catch (const crowddb::Error&) {
  }
  return 0;
}
