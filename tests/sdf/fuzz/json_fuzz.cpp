#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sdf::fuzz::exercise(&sdf::read_json, std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
