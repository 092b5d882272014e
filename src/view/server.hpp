// `crowddb view`: a local, read-only web server that plays a run back in the browser. The page
// (viewer/, bundled at build time and embedded here) fetches:
//   GET /api/run                   name, frame range, fps, bounds, blocked polygons, goal areas,
//                                  the most agents in a frame (JSON)
//   GET /api/metrics               per-tick metrics of a crowddb run (JSON arrays)
//   GET /api/frames?from=K&count=N frames K .. K+N-1 (at most 1000), binary, little-endian:
//     u32 0x46424443 ("CDBF"), u32 frames; per frame: i32 frame, u32 n, then f64 id[n],
//     f32 x[n], f32 y[n], f32 radius[n], f32 speed[n], i32 goal[n] (-1: none), u8 state[n]
//     (0 active, 1 frozen, 2 arrived, 3 unknown, 4 stalled), zero padding to a multiple of 8
//     bytes.
#pragma once

#include <functional>
#include <string>

#include "view/run_file.hpp"

namespace crowddb::view {

struct ServeOptions {
  std::string host = "127.0.0.1";  // loopback only, unless asked
  int port = 8080;                 // 0: any free port
};

// Whether this build embeds the page (built without npm: the API only, and a page saying so).
bool viewer_page_embedded();

// The bodies the server answers with (also for tests without a socket).
std::string run_json(const RunFile& run);
std::string metrics_json(const RunFile& run);
std::string frames_binary(const RunFile& run, int64_t from, int64_t count);

// Serves `run` until the process is stopped; calls ready(url) once listening. Throws Error(io)
// when the port is taken or the address cannot be bound.
void serve(RunFile& run, const ServeOptions& opt,
           const std::function<void(const std::string&)>& ready);

}  // namespace crowddb::view
