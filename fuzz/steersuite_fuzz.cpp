// libFuzzer target: the SteerSuite importer (src/io/import/steersuite.cpp). Any input must end in
// an imported document or a crowddb::Error; a crash, a sanitizer report, another exception type
// or a hang is a bug. Seed it with SteerSuite test cases (tests/data/import/steersuite/ or
// SteerSuite's testcases/ folder). Agents are capped at 1000 so that placements stay quick.
#include <cstdint>
#include <string_view>

#include "crowddb/error.hpp"
#include "io/import/steersuite.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    crowddb::io::Imported im = crowddb::io::import_steersuite(
        "fuzz.xml", std::string_view(reinterpret_cast<const char*>(data), size), {}, 1000);
    (void)im;
  } catch (const crowddb::Error&) {
  }
  return 0;
}
