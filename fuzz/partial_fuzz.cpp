// libFuzzer target: an interrupted run's PATH.partial as `crowddb resume` opens it before the
// scenario and the checkpoint are restored (those have scenario_fuzz and checkpoint_fuzz): the
// crowddb_run keys, the latest checkpoint's records and their pieces (io::read_partial_run), then
// the output reopened to go on writing after the checkpoint's tick (io::resume_sqlite_writer).
// Errors must be crowddb::Error with one line; anything else (a crash, a sanitizer report, an
// allocation the file's size does not justify, an unbounded loop) is a finding.
// Seeds: fuzz/corpus/partial (real .partial files, one with its checkpoint in pieces).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "crowddb/error.hpp"
#include "io/trajectory.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = "/tmp/partial_fuzz_" + std::to_string(getpid()) + ".sqlite";
  static const std::string partial = path + ".partial";
  std::error_code ec;
  for (const char* extra : {"-wal", "-shm", "-journal"})
    std::filesystem::remove(partial + extra, ec);
  if (std::FILE* f = std::fopen(partial.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  } else {
    return 0;
  }
  const auto one_line = [](const crowddb::Error& e) {
    const std::string msg = e.what();
    if (msg.empty() || msg.find('\n') != std::string::npos) __builtin_trap();
  };
  try {
    const crowddb::io::PartialRun p = crowddb::io::read_partial_run(partial);
    auto writer = crowddb::io::resume_sqlite_writer(p, 0.1, 20, "json");
  } catch (const crowddb::Error& e) {
    one_line(e);
  }
  return 0;
}
