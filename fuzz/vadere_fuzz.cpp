// libFuzzer target: the Vadere importer (src/io/import/vadere.cpp). Any input must end in an
// imported document or a crowddb::Error; a crash, a sanitizer report, another exception type or
// a hang is a bug. Seed it with Vadere files, e.g. tests/data/import/vadere/*.scenario.
#include <cstdint>
#include <string_view>

#include "crowddb/error.hpp"
#include "io/import/vadere.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    crowddb::io::Imported im = crowddb::io::import_vadere(
        "fuzz.scenario", std::string_view(reinterpret_cast<const char*>(data), size), {});
    (void)im;
  } catch (const crowddb::Error&) {
  }
  return 0;
}
