// libFuzzer target: a trajectory file as `crowddb render` and `crowddb view` read it (an SQLite
// file, crowddb's or JuPedSim's): open, index the frames, read the first and last frame, the
// metrics, and the server's answers. Errors must be crowddb::Error with one line; anything else
// (a crash, a sanitizer report, an unbounded loop) is a finding. Seeds: fuzz/corpus/runfile.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "crowddb/error.hpp"
#include "view/server.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = "/tmp/runfile_fuzz_" + std::to_string(getpid()) + ".sqlite";
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  } else {
    return 0;
  }
  try {
    crowddb::view::RunFile run = crowddb::view::RunFile::open(path);
    run.index_frames();
    (void)crowddb::view::run_json(run);
    (void)crowddb::view::metrics_json(run);
    if (run.last_frame() >= run.first_frame()) {
      (void)run.frame(run.first_frame());
      (void)run.frame(run.last_frame());
      (void)crowddb::view::frames_binary(run, run.first_frame(), 3);
    }
  } catch (const crowddb::Error& e) {
    const std::string msg = e.what();
    if (msg.empty() || msg.find('\n') != std::string::npos) __builtin_trap();
  }
  return 0;
}
