#include <string>

#include "fuzz_common.hpp"
#include "sdf/json_detail.hpp"

namespace {

// What a reader made of the text: "" for a graph, else its error.
std::string error_of(std::string_view text, sdf::detail::ScanThread scan) {
  try {
    (void)sdf::detail::read_sdf3_with(text, "fuzz", nullptr, 2, scan);
  } catch (const sdf::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  sdf::fuzz::exercise(&sdf::read_sdf3, text);
  // The scan on a thread of its own, two actors or channels per hand-over, also looking up the
  // channels' actors and ports itself: the same outcome as on the calling thread.
  const std::string caller = error_of(text, sdf::detail::ScanThread::caller);
  if (error_of(text, sdf::detail::ScanThread::own) != caller ||
      error_of(text, sdf::detail::ScanThread::own_resolving) != caller)
    std::abort();
  return 0;
}
