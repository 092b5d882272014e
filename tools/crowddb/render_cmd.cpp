// `crowddb render RUN [--frame K | --time S] [--out FILE.png] [--width PX] [--color state|speed]`:
// a still picture of one frame of a run (a crowddb output or a JuPedSim trajectory file), for
// reports, without a browser (docs/viewer.md).
#include <cmath>

#include "commands.hpp"
#include "view/render.hpp"

namespace crowddb::cli {

void add_render_command(CLI::App& app, Action& action) {
  auto* sub = app.add_subcommand(
      "render", "draw one frame of a run (crowddb output or JuPedSim trajectory) as a PNG picture");
  static std::string file, out, color = "state";
  static int64_t frame = 0;
  static double time = -1, max_speed = 0;
  static int width = 1200;
  sub->add_option("file", file, "the run: a crowddb SQLite output or a JuPedSim trajectory file")
      ->required();
  static CLI::Option* f = nullptr;
  f = sub->add_option("--frame", frame, "frame number (default: the last frame)");
  sub->add_option("--time", time, "the frame at this time [s] (the nearest frame)")
      ->excludes(f)
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--out", out, "PNG file to write (default: FILE's name with .png)");
  sub->add_option("--width", width, "picture width in pixels (200 to 16384)")
      ->capture_default_str();
  sub->add_option("--color", color, "colour agents by state (active, stalled, frozen, arrived) or speed")
      ->check(CLI::IsMember({"state", "speed"}))
      ->capture_default_str();
  sub->add_option("--max-speed", max_speed,
                  "top of the speed scale [m/s] (default: the frame's fastest)")
      ->check(CLI::NonNegativeNumber);
  sub->callback([&action] {
    action = [] {
      const view::RunFile run = view::RunFile::open(file);
      int64_t k = f->count() ? frame : run.last_frame();
      if (time >= 0) {
        if (!(run.fps() > 0))
          throw Error(Error::Kind::usage,
                      file + ": --time needs the file's frame rate (metadata fps), which it lacks; "
                             "use --frame");
        // Frame k is at time k / fps (as the picture's title and the viewer say).
        const double at = std::round(time * run.fps());
        if (!(at <= static_cast<double>(run.last_frame())))
          throw Error(Error::Kind::usage,
                      file + ": --time " + format_number(time) + " s is after the last frame (" +
                          format_number(static_cast<double>(run.last_frame()) / run.fps()) +
                          " s)");
        k = static_cast<int64_t>(at);
      }
      view::RenderOptions opt;
      opt.width = width;
      opt.colour = color == "speed" ? view::RenderOptions::Colour::speed
                                    : view::RenderOptions::Colour::state;
      opt.max_speed = max_speed;
      std::string path = out;
      if (path.empty()) {
        std::filesystem::path p(file);
        if (p.extension() == ".partial") p.replace_extension();
        path = p.replace_extension(".png").string();
      }
      view::render_png(run, k, opt, path);
      return 0;
    };
  });
}

}  // namespace crowddb::cli
