// libFuzzer target: the agents and obstacles CSV readers of `crowddb query`.
#include <cstdint>
#include <string_view>

#include "crowddb/error.hpp"
#include "io/csv_tables.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    crowddb::io::parse_agents_csv(text, "fuzz.csv");
  } catch (const crowddb::Error&) {
  }
  try {
    crowddb::io::parse_obstacles_csv(text, "fuzz.csv");
  } catch (const crowddb::Error&) {
  }
  return 0;
}
