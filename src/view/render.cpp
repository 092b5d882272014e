#include "view/render.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "crowddb/error.hpp"

namespace crowddb::view {
namespace {

constexpr double kMargin = 16, kTitle = 30, kLegend = 28;  // [px]
constexpr int kMaxSide = 16384;                            // [px] Cairo's limit is 32767

void set_rgb(cairo_t* cr, uint32_t c, double alpha = 1) {
  cairo_set_source_rgba(cr, ((c >> 16) & 0xff) / 255.0, ((c >> 8) & 0xff) / 255.0,
                        (c & 0xff) / 255.0, alpha);
}

// Speed colours: a perceptually ordered ramp (viridis' end points and three stops between).
uint32_t speed_colour(double f) {
  static const uint32_t stops[] = {0x440154, 0x3b528b, 0x21918c, 0x5ec962, 0xfde725};
  f = std::clamp(f, 0.0, 1.0) * 4;
  const int i = std::min(3, static_cast<int>(f));
  const double t = f - i;
  uint32_t out = 0;
  for (int s = 16; s >= 0; s -= 8) {
    const double a = (stops[i] >> s) & 0xff, b = (stops[i + 1] >> s) & 0xff;
    out |= static_cast<uint32_t>(std::lround(a + t * (b - a))) << s;
  }
  return out;
}

uint32_t shade_colour(Shade s) {
  switch (s) {
    case Shade::frozen:
      return colour::kFrozen;
    case Shade::arrived:
      return colour::kArrived;
    case Shade::stalled:
      return colour::kStalled;
    case Shade::waiting:
      return colour::kWaiting;
    default:
      return colour::kActive;
  }
}

void ring_path(cairo_t* cr, const Viewport& v, const std::vector<Vec2>& ring) {
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const double x = v.px(ring[i].x), y = v.py(ring[i].y);
    if (i == 0)
      cairo_move_to(cr, x, y);
    else
      cairo_line_to(cr, x, y);
  }
  cairo_close_path(cr);
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

struct Surface {
  cairo_surface_t* s;
  cairo_t* cr;
  Surface(int w, int h)
      : s(cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h)), cr(cairo_create(s)) {}
  ~Surface() {
    cairo_destroy(cr);
    cairo_surface_destroy(s);
  }
};

}  // namespace

Viewport viewport_of(const RunFile& run, int width) {
  const Bounds& b = run.bounds();
  Viewport v;
  v.width = width;
  v.scale = (width - 2 * kMargin) / b.width();
  double h = b.height() * v.scale;
  if (h > kMaxSide - 2 * kMargin - kTitle - kLegend) {  // very tall: fit the height instead
    h = kMaxSide - 2 * kMargin - kTitle - kLegend;
    v.scale = h / b.height();
  }
  v.height = static_cast<int>(std::ceil(h + 2 * kMargin + kTitle + kLegend));
  v.left = (width - b.width() * v.scale) / 2;
  v.top = kMargin + kTitle;
  v.xmin = b.xmin;
  v.ymax = b.ymax;
  return v;
}

void render_png(const RunFile& run, int64_t frame, const RenderOptions& opt,
                const std::string& out) {
  if (opt.width < 200 || opt.width > kMaxSide)
    throw Error(Error::Kind::usage, "--width: " + std::to_string(opt.width) +
                                        " pixels is outside 200 to " + std::to_string(kMaxSide));
  const std::vector<FrameAgent> agents = run.frame(frame);
  const Viewport v = viewport_of(run, opt.width);
  const Bounds& b = run.bounds();
  Surface pic(v.width, v.height);
  cairo_t* cr = pic.cr;
  if (cairo_surface_status(pic.s) != CAIRO_STATUS_SUCCESS)
    throw Error(Error::Kind::io, out + ": cannot make a " + std::to_string(v.width) + " x " +
                                     std::to_string(v.height) + " picture");
  set_rgb(cr, colour::kBackground);
  cairo_paint(cr);

  // The drawing area: floor, and what is not walkable in it.
  set_rgb(cr, colour::kFloor);
  cairo_rectangle(cr, v.px(b.xmin), v.py(b.ymax), b.width() * v.scale, b.height() * v.scale);
  cairo_fill(cr);
  set_rgb(cr, colour::kBlocked);
  for (const auto& piece : run.blocked()) {
    ring_path(cr, v, piece);
    cairo_fill(cr);
  }
  set_rgb(cr, colour::kBlocked);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, v.px(b.xmin), v.py(b.ymax), b.width() * v.scale, b.height() * v.scale);
  cairo_stroke(cr);

  // Goal areas, translucent, with their names.
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 11);
  for (const GoalShape& g : run.goals()) {
    cairo_new_path(cr);  // an arc would otherwise join the point the last label ended at
    if (g.ring.empty())
      cairo_arc(cr, v.px(g.x), v.py(g.y), std::max(g.radius * v.scale, 2.0), 0, 2 * M_PI);
    else
      ring_path(cr, v, g.ring);
    cairo_set_source_rgba(cr, 0.18, 0.63, 0.26, 0.30);
    cairo_fill_preserve(cr);
    cairo_set_source_rgba(cr, 0.18, 0.50, 0.22, 0.9);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
    double cx = g.x, cy = g.y;
    if (!g.ring.empty()) {
      cx = cy = 0;
      for (const Vec2& p : g.ring) {
        cx += p.x / static_cast<double>(g.ring.size());
        cy += p.y / static_cast<double>(g.ring.size());
      }
    }
    cairo_text_extents_t ext;
    cairo_text_extents(cr, g.name.c_str(), &ext);
    cairo_move_to(cr, v.px(cx) - ext.width / 2, v.py(cy) + ext.height / 2);
    cairo_set_source_rgba(cr, 0.10, 0.35, 0.15, 1);
    cairo_show_text(cr, g.name.c_str());
  }

  // The agents.
  double top = opt.max_speed;
  if (!(top > 0))
    for (const FrameAgent& a : agents) top = std::max(top, std::hypot(a.vx, a.vy));
  top = std::max(top, 0.1);
  std::size_t count[6] = {0, 0, 0, 0, 0, 0};
  cairo_set_line_width(cr, std::clamp(0.08 * v.scale, 0.3, 1.0));
  for (const FrameAgent& a : agents) {
    ++count[static_cast<int>(a.shade)];
    const uint32_t c = opt.colour == RenderOptions::Colour::speed
                           ? speed_colour(std::hypot(a.vx, a.vy) / top)
                           : shade_colour(a.shade);
    cairo_new_path(cr);
    cairo_arc(cr, v.px(a.x), v.py(a.y), std::max(a.radius * v.scale, 1.0), 0, 2 * M_PI);
    set_rgb(cr, c);
    cairo_fill_preserve(cr);
    cairo_set_source_rgba(cr, 0, 0, 0, 0.45);
    cairo_stroke(cr);
  }

  // Title and legend.
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, 15);
  std::string title = run.name() + "   frame " + std::to_string(frame);
  if (run.fps() > 0) title += ", t = " + fixed(static_cast<double>(frame) / run.fps(), 1) + " s";
  title += ", " + std::to_string(agents.size()) + " agents";
  cairo_move_to(cr, kMargin, kMargin + 15);
  cairo_show_text(cr, title.c_str());
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 12);
  double x = kMargin;
  const double y = v.height - kMargin + 2;
  auto key = [&](uint32_t c, const std::string& label) {
    cairo_new_path(cr);
    cairo_arc(cr, x + 6, y - 4, 6, 0, 2 * M_PI);
    set_rgb(cr, c);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    cairo_move_to(cr, x + 16, y);
    cairo_show_text(cr, label.c_str());
    cairo_text_extents_t ext;
    cairo_text_extents(cr, label.c_str(), &ext);
    x += 16 + ext.x_advance + 18;
  };
  if (opt.colour == RenderOptions::Colour::speed) {
    for (int s = 0; s <= 4; ++s)
      key(speed_colour(s / 4.0), fixed(top * s / 4, 2) + (s == 4 ? " m/s" : ""));
  } else if (run.crowddb()) {
    key(colour::kActive, "active " + std::to_string(count[0] + count[3]));
    key(colour::kStalled, "stalled " + std::to_string(count[4]));
    key(colour::kFrozen, "frozen " + std::to_string(count[1]));
    key(colour::kArrived, "arrived " + std::to_string(count[2]));
    if (count[5] > 0) key(colour::kWaiting, "waiting " + std::to_string(count[5]));
  } else {
    key(colour::kActive,
        "agents (radius " + fixed(RunFile::kDefaultRadius, 1) + " m: not in the file)");
  }
  const std::string scale_label = fixed(b.width(), 1) + " x " + fixed(b.height(), 1) + " m";
  cairo_text_extents_t ext;
  cairo_text_extents(cr, scale_label.c_str(), &ext);
  cairo_move_to(cr, v.width - kMargin - ext.x_advance, y);
  cairo_show_text(cr, scale_label.c_str());

  cairo_surface_flush(pic.s);
  if (cairo_status(cr) != CAIRO_STATUS_SUCCESS)
    throw Error(Error::Kind::io, out + ": cannot draw the picture (" +
                                     cairo_status_to_string(cairo_status(cr)) + ")");
  const std::string tmp = out + ".tmp";
  const cairo_status_t st = cairo_surface_write_to_png(pic.s, tmp.c_str());
  if (st != CAIRO_STATUS_SUCCESS) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw Error(Error::Kind::io,
                out + ": cannot write the picture (" + cairo_status_to_string(st) + ")");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, out, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw Error(Error::Kind::io, out + ": cannot write the picture (" + ec.message() + ")");
  }
}

}  // namespace crowddb::view
