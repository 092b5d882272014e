// Still pictures of a run: one frame drawn to a PNG file (`crowddb render`), with Cairo.
#pragma once

#include <cstdint>
#include <string>

#include "view/run_file.hpp"

namespace crowddb::view {

struct RenderOptions {
  int width = 1200;  // [px] the picture's width; its height follows the drawing area's aspect
  enum class Colour { state, speed } colour = Colour::state;
  double max_speed = 0;  // [m/s] top of the speed scale; 0: the frame's fastest (at least 0.1)
};

// Where world coordinates land in the picture (y up in the world, down in the picture).
struct Viewport {
  int width = 0, height = 0;  // [px] the whole picture
  double scale = 1;           // [px/m]
  double left = 0, top = 0;   // [px] where the drawing area's (xmin, ymax) corner lands
  double xmin = 0, ymax = 0;
  double px(double x) const { return left + (x - xmin) * scale; }
  double py(double y) const { return top + (ymax - y) * scale; }
};

Viewport viewport_of(const RunFile& run, int width);

// The colours things are drawn in (0xRRGGBB), for a legend and for tests that probe pixels.
namespace colour {
constexpr uint32_t kBackground = 0xffffff, kFloor = 0xf3efe6, kBlocked = 0x4d4d4d;
constexpr uint32_t kActive = 0x1f77b4, kFrozen = 0xff7f0e, kArrived = 0x9e9e9e, kStalled = 0x9467bd,
                   kWaiting = 0x17becf;
}  // namespace colour

// Draws frame `frame` of the run: the walkable area (what is not walkable dark), the goal
// areas, every agent as a disc at its radius coloured by state or speed, a title line and a
// legend; writes it as PNG to `out` (through a temporary file beside it, renamed on success).
// Throws Error: usage for a bad frame or width, io when the file cannot be written.
void render_png(const RunFile& run, int64_t frame, const RenderOptions& opt,
                const std::string& out);

}  // namespace crowddb::view
