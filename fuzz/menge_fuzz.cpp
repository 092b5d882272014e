// libFuzzer target: Menge scene + behaviour XML. The input is split at the first "\n----\n" into
// the scene and the behaviour text (without one, the whole input is the scene and the behaviour
// is a single final state). Any input must end in a crowddb scenario or a crowddb::Error; a
// crash, a sanitizer report, another exception type or a hang is a bug.
#include <cstdint>
#include <string>
#include <string_view>

#include "crowddb/error.hpp"
#include "io/import/menge.hpp"
#include "io/scenario_doc.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  constexpr std::string_view kSeparator = "\n----\n";
  const std::size_t cut = in.find(kSeparator);
  const std::string_view scene = in.substr(0, cut);
  const std::string_view behavior =
      cut == std::string_view::npos
          ? std::string_view("<BFSM><State name=\"Walk\" final=\"1\"/></BFSM>")
          : in.substr(cut + kSeparator.size());
  crowddb::io::ProjectSettings settings;
  settings.name = "fuzz";
  settings.model_given = true;
  // Large generated crowds are legal but slow to fuzz through; the reading is what is tested.
  settings.max_agents = 10'000;
  try {
    const crowddb::io::Imported im =
        crowddb::io::import_menge_pair(scene, "fuzzS.xml", behavior, "fuzzB.xml", settings);
    crowddb::io::parse_document(im.doc.dump(), "fuzzS.xml", &im.origins);
  } catch (const crowddb::Error&) {
  }
  return 0;
}
