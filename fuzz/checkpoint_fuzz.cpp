// libFuzzer target: checkpoints (Simulation::restore_state, what `crowddb resume` reads). The
// input is a checkpoint's body; the target appends its checksum, so mutations reach the parser
// behind it instead of stopping at the checksum. Any input must restore or end in a
// crowddb::Error; a crash, a sanitizer report, another exception type or a hang is a bug.
#include <cstdint>
#include <string>

#include "checkpoint_scenario.hpp"
#include "crowddb/error.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "util/byte_codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static crowddb::Simulation* sim = [] {
    crowddb::Scenario sc = crowddb::parse_scenario(kCheckpointScenario, "fuzz.json");
    return new crowddb::Simulation(std::move(sc.world), sc.config);
  }();
  std::string bytes(reinterpret_cast<const char*>(data), size);
  crowddb::ByteWriter sum;
  sum.u64(crowddb::checksum(bytes));
  bytes += sum.bytes();
  try {
    sim->restore_state(bytes, "fuzz");
    sim->step();  // a restored state must also run
  } catch (const crowddb::Error&) {
  }
  return 0;
}
