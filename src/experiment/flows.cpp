// Validation against data (issue "crowds that flow", item 7): the steering models' speed-density
// relation in a corridor (RiMEA test 4) beside Weidmann's curve, and the flow through
// bottlenecks of 0.8-2.5 m beside the flow a specific flow of 1.9 /(m s) gives (the value usually
// quoted for the Juelich experiments, Seyfried et al. 2009; ../shared/VALIDATION.md §2 says to
// check it against the paper before making it a threshold, so it is a line on the plot here).
// Stated, not asserted: the figures are written to CSV and plotted; docs/validation.md discusses
// them.
//
//   fd          a ring corridor 4 m wide (radii 13 and 17 m) filled in lanes at a set density
//               (0.5 ... 4 per m^2, radius 0.2 m, preferred speeds uniform in 1.2-1.5 m/s), all
//               walking counter-clockwise from sector to sector (48 sector goals, in sequence);
//               the ring is periodic, so the density stays the set one: the mean tangential
//               speed of everyone over 60 s after a 10 s transient. (A straight corridor with a
//               finite crowd empties its measuring area within half a minute.)
//   bottleneck  150 people (radius 0.2-0.25 m) leave a 10 x 10 m room through a bottleneck 4 m
//               long and b wide; the flow is counted where they leave the bottleneck, between the
//               10th and the 90th percentile of the crossings (start and end transients cut)
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <numbers>
#include <ostream>
#include <sstream>
#include <unordered_map>

#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "experiment/experiment.hpp"
#include "io/overrides.hpp"
#include "steer/model.hpp"
#include "util/rng.hpp"

namespace crowddb::experiment {
namespace {

using nlohmann::json;

// Weidmann (1993), as Vadere codes it (VALIDATION.md §2): v0 1.34 m/s, gamma 1.913, rho_max 5.4.
double weidmann(double rho) {
  return rho <= 0 ? 1.34 : std::max(0.0, 1.34 * (1 - std::exp(-1.913 * (1 / rho - 1 / 5.4))));
}

// The models compared: those asked for, or every model but the thesis's rule (its own units).
std::vector<std::string> models(const Options& opt) {
  if (!opt.models.empty()) return opt.models;
  std::vector<std::string> m;
  for (const auto& info : steer::model_registry())
    if (info.name != "thesis") m.push_back(info.name);
  return m;
}

// A document of the experiment, with the fields the user set (Options::overrides).
Scenario read(json& doc, const Options& opt, const std::string& source) {
  io::apply_overrides(doc, opt.overrides);
  return parse_scenario(doc.dump(), source);
}

}  // namespace

void run_fd(const Options& opt) {
  // A ring corridor: periodic, so the density stays what it was set to.
  const double r_in = 13, r_out = 17, W = r_out - r_in;
  const int sectors = 48, laps = 15;  // 7.5 degree sectors: a chord dips 3 cm into the inner wall
  const double warm = 10, measure = opt.quick ? 15 : 60;
  const double area = std::numbers::pi * (r_out * r_out - r_in * r_in);
  const std::vector<double> densities =
      opt.quick ? std::vector<double>{1, 3} : std::vector<double>{0.5, 1, 1.5, 2, 2.5, 3, 3.5, 4};
  const std::string cols[] = {"model", "set_density",    "density", "speed",
                              "flow",  "weidmann_speed", "agents",  "seconds"};
  CsvWriter csv(opt.out_dir / "fd.csv", cols);
  std::ostringstream table;
  table << "Speed against density in a ring corridor 4 m wide (inner radius " << r_in
        << " m; RiMEA 4 asks for a straight one: periodic ends are what the ring gives), whole "
           "ring over "
        << measure << " s after " << warm << " s\n"
        << machine_note(opt.threads) << "\n\n"
        << std::setw(8) << "model" << std::setw(10) << "set rho" << std::setw(10) << "rho"
        << std::setw(10) << "v [m/s]" << std::setw(12) << "J [1/(m s)]" << std::setw(12)
        << "Weidmann v"
        << "\n";
  // The walkable ring (a 96-gon pair) and the sector goals that keep everyone walking around.
  auto ring_wkt = [&] {
    std::ostringstream w;
    w.precision(17);
    w << "POLYGON((";
    for (int k = 0; k <= 96; ++k) {
      const double a = 2 * std::numbers::pi * (k % 96) / 96;
      w << (k ? ", " : "") << r_out * std::cos(a) << " " << r_out * std::sin(a);
    }
    w << "), (";
    for (int k = 0; k <= 96; ++k) {
      const double a = -2 * std::numbers::pi * (k % 96) / 96;
      w << (k ? ", " : "") << r_in * std::cos(a) << " " << r_in * std::sin(a);
    }
    w << "))";
    return w.str();
  }();
  json goals = json::array();
  for (int k = 0; k < sectors; ++k) {
    const double a0 = 2 * std::numbers::pi * k / sectors,
                 a1 = 2 * std::numbers::pi * (k + 1) / sectors;
    const double i0 = r_in + 0.01, o0 = r_out - 0.01;
    goals.push_back({{"name", "s" + std::to_string(k)},
                     {"area",
                      {{i0 * std::cos(a0), i0 * std::sin(a0)},
                       {o0 * std::cos(a0), o0 * std::sin(a0)},
                       {o0 * std::cos(a1), o0 * std::sin(a1)},
                       {i0 * std::cos(a1), i0 * std::sin(a1)}}}});
  }
  for (const std::string& model : models(opt))
    for (double rho : densities) {
      // Lanes of agents at spacing s = 1 / sqrt(rho), across and along the ring.
      const double s = 1 / std::sqrt(rho);
      const int lanes = std::max(1, static_cast<int>(std::floor(W / s)));
      json agents = json::array();
      Rng rng = Rng::stream(opt.seed, static_cast<uint64_t>(rho * 100));
      for (int l = 0; l < lanes; ++l) {
        const double rr = r_in + (W - (lanes - 1) * s) / 2 + l * s;
        const int along = static_cast<int>(std::floor(2 * std::numbers::pi * rr / s));
        for (int j = 0; j < along; ++j) {
          const double a = 2 * std::numbers::pi * j / along;
          // Its next sector (counter-clockwise), then the following ones for `laps` laps.
          const int first =
              (static_cast<int>(std::floor(a / (2 * std::numbers::pi) * sectors)) + 1) % sectors;
          json seq = json::array();
          for (int q = 0; q < laps * sectors; ++q)
            seq.push_back("s" + std::to_string((first + q) % sectors));
          agents.push_back({{"x", rr * std::cos(a)},
                            {"y", rr * std::sin(a)},
                            {"radius", 0.2},
                            {"pref_speed", rng.uniform(1.2, 1.5)},
                            {"max_speed", 1.5},
                            {"goal", seq}});
        }
      }
      json d = {{"bounds", {-r_out - 0.5, -r_out - 0.5, r_out + 0.5, r_out + 0.5}},
                {"walls", false},
                {"walkable", ring_wkt},
                {"dt", 0.1},
                {"seed", opt.seed},
                {"threads", opt.threads},
                {"duration", warm + measure},
                {"steering", {{"model", model}}},
                {"goals", goals},
                {"agents", agents}};
      Scenario sc = read(d, opt, "fd");
      const uint64_t ticks = sc.ticks, warm_ticks = sc.config.ticks_for(warm, 0);
      const std::size_t n = sc.world.agents().size();
      Simulation sim(std::move(sc.world), sc.config);
      double v_sum = 0;
      uint64_t samples = 0;
      const auto t0 = std::chrono::steady_clock::now();
      for (uint64_t k = 1; k <= ticks; ++k) {
        sim.step();
        if (k <= warm_ticks) continue;
        const AgentTable& t = sim.world().agents();
        double vt = 0;  // counter-clockwise tangential speed
        for (std::size_t i = 0; i < t.size(); ++i) {
          const double r = std::sqrt(t.x[i] * t.x[i] + t.y[i] * t.y[i]);
          vt += (-t.y[i] * t.vx[i] + t.x[i] * t.vy[i]) / r;
        }
        v_sum += vt / static_cast<double>(t.size());
        ++samples;
      }
      const double secs =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double r = static_cast<double>(n) / area, v = v_sum / static_cast<double>(samples);
      csv.row(std::vector<std::string>{
          model, std::to_string(rho), std::to_string(r), std::to_string(v), std::to_string(r * v),
          std::to_string(weidmann(r)), std::to_string(n), std::to_string(secs)});
      table << std::setw(8) << model << std::setw(10) << rho << std::fixed << std::setprecision(2)
            << std::setw(10) << r << std::setw(10) << v << std::setw(12) << r * v << std::setw(12)
            << weidmann(r) << std::defaultfloat << "\n";
      if (opt.log)
        *opt.log << "fd: " << model << " density " << r << " /m^2: " << v << " m/s (" << n
                 << " agents, " << secs << " s)\n"
                 << std::flush;
    }
  csv.close();
  {
    std::ofstream f(opt.out_dir / "fd.txt");
    f << table.str();
  }
  std::string script =
      "set terminal pngcairo size 1000,650 font ',11'\n"
      "set output 'fd.png'\n"
      "set datafile separator ','\n"
      "set title 'Speed against density: a ring corridor 4 m wide, all walking one way (RiMEA 4)'\n"
      "set xlabel 'density [1/m^2]'\nset ylabel 'speed [m/s]'\n"
      "set xrange [0:5.5]\nset yrange [0:1.6]\nset grid\nset key top right\n"
      "weidmann(r) = r <= 0 ? 1.34 : 1.34 * (1 - exp(-1.913 * (1 / r - 1 / 5.4)))\n"
      "plot weidmann(x) with lines lw 2 dt 2 lc rgb 'black' title 'Weidmann 1993'";
  int pt = 5;
  for (const std::string& m : models(opt))
    script += ", \\\n     'fd.csv' using ($1 eq '" + m + "' ? $3 : 1/0):4 skip 1 with points pt " +
              std::to_string(pt++) + " ps 1.5 title '" + m + "'";
  // gnuplot compares strings with eq only inside a ternary on a string column: use strcol.
  for (std::size_t at; (at = script.find("$1 eq")) != std::string::npos;)
    script.replace(at, 5, "strcol(1) eq");
  plot(opt.out_dir, "fd", script + "\n");
}

void run_bottleneck(const Options& opt) {
  const std::vector<double> widths =
      opt.quick ? std::vector<double>{1.0, 2.0} : std::vector<double>{0.8, 1.0, 1.2, 1.6, 2.0, 2.5};
  const int people = opt.quick ? 60 : 150;
  const std::string cols[] = {"model",  "width",   "flow",     "specific_flow", "people",
                              "passed", "seconds", "flow_min", "flow_max",      "seeds"};
  CsvWriter csv(opt.out_dir / "bottleneck.csv", cols);
  std::ostringstream table;
  table << "Flow through a bottleneck 4 m long, " << people
        << " people from a 10 x 10 m room (10th to 90th percentile of the crossings)";
  if (opt.seeds > 1)
    table << "; the mean over seeds " << opt.seed << "-" << opt.seed + opt.seeds - 1
          << " and its range";
  table << "\n"
        << machine_note(opt.threads) << "\n\n"
        << std::setw(8) << "model" << std::setw(10) << "b [m]" << std::setw(12) << "J [1/s]"
        << std::setw(14) << "J/b [1/(m s)]" << (opt.seeds > 1 ? "   J min-max [1/s]" : "") << "\n";
  // One run: the flow between the 10th and the 90th percentile of the crossings of x = 14 m.
  struct Run {
    double flow = 0;
    std::size_t passed = 0;
    double seconds = 0;
  };
  auto run_once = [&](const std::string& model, double b, uint64_t seed) {
    const double y0 = 5 - b / 2, y1 = 5 + b / 2, x_exit = 14;
    json d = {
        {"bounds", {0, 0, 20, 10}},
        {"dt", 0.1},
        {"seed", seed},
        {"threads", opt.threads},
        {"duration", 400},
        {"steering", {{"model", model}}},
        {"obstacles",
         {{{"type", "polygon"}, {"vertices", {{10, 0}, {14, 0}, {14, y0}, {10, y0}}}},
          {{"type", "polygon"}, {"vertices", {{10, y1}, {14, y1}, {14, 10}, {10, 10}}}}}},
        {"goals", {{{"name", "out"}, {"area", {{19, 0}, {20, 0}, {20, 10}, {19, 10}}}}}},
        {"groups",
         {{{"count", people},
           {"placement", {{"type", "uniform"}, {"region", {0.3, 0.3, 9.7, 9.7}}, {"gap", 0.05}}},
           {"radius", {0.2, 0.25}},
           {"pref_speed", {1.2, 1.5}},
           {"goal", "out"}}}},
        {"navigation", json::object()}};
    Scenario sc = read(d, opt, "bottleneck");
    const uint64_t ticks = sc.ticks;
    Simulation sim(std::move(sc.world), sc.config);
    std::unordered_map<uint64_t, double> last_x;
    std::vector<double> crossings;
    const auto t0 = std::chrono::steady_clock::now();
    for (uint64_t k = 1; k <= ticks && sim.world().agents().size(); ++k) {
      sim.step();
      const AgentTable& t = sim.world().agents();
      for (std::size_t i = 0; i < t.size(); ++i) {
        auto [it, fresh] = last_x.try_emplace(t.id[i], t.x[i]);
        if (!fresh && it->second < x_exit && t.x[i] >= x_exit)
          crossings.push_back(static_cast<double>(k) * sc.config.dt);
        it->second = t.x[i];
      }
    }
    Run r;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.passed = crossings.size();
    std::sort(crossings.begin(), crossings.end());
    if (crossings.size() >= 10) {
      const std::size_t a = crossings.size() / 10, z = crossings.size() * 9 / 10;
      r.flow = static_cast<double>(z - a) / (crossings[z] - crossings[a]);
    }
    return r;
  };
  for (const std::string& model : models(opt))
    for (double b : widths) {
      double sum = 0, lo = INFINITY, hi = -INFINITY, secs = 0;
      std::size_t passed = 0;
      for (int s = 0; s < opt.seeds; ++s) {
        const Run r = run_once(model, b, opt.seed + static_cast<uint64_t>(s));
        sum += r.flow;
        lo = std::min(lo, r.flow);
        hi = std::max(hi, r.flow);
        passed += r.passed;
        secs += r.seconds;
        if (opt.log)
          *opt.log << "bottleneck: " << model << " b " << b << " m, seed "
                   << opt.seed + static_cast<uint64_t>(s) << ": J " << r.flow << " /s, " << r.passed
                   << " of " << people << " passed (" << r.seconds << " s)\n"
                   << std::flush;
      }
      const double flow = sum / opt.seeds;
      const std::size_t everyone = static_cast<std::size_t>(people) * opt.seeds;
      csv.row(std::vector<std::string>{
          model, std::to_string(b), std::to_string(flow), std::to_string(flow / b),
          std::to_string(everyone), std::to_string(passed), std::to_string(secs),
          std::to_string(lo), std::to_string(hi), std::to_string(opt.seeds)});
      table << std::setw(8) << model << std::setw(10) << b << std::fixed << std::setprecision(2)
            << std::setw(12) << flow << std::setw(14) << flow / b;
      if (opt.seeds > 1) table << std::setw(12) << lo << "-" << hi;
      table << std::defaultfloat << "\n";
    }
  csv.close();
  {
    std::ofstream f(opt.out_dir / "bottleneck.txt");
    f << table.str();
  }
  std::string script =
      "set terminal pngcairo size 1000,650 font ',11'\n"
      "set output 'bottleneck.png'\n"
      "set datafile separator ','\n"
      "set title 'Flow through a bottleneck against its width'\n"
      "set xlabel 'width b [m]'\nset ylabel 'flow J [1/s]'\n"
      "set xrange [0.6:2.7]\nset yrange [0:*]\nset grid\nset key top left\n"
      "plot 1.9 * x with lines lw 2 dt 2 lc rgb 'black' title 'J = 1.9 b (specific flow as usually "
      "quoted for the Juelich experiments)'";
  int pt = 5;
  for (const std::string& m : models(opt))
    // With several seeds, bars from the smallest to the largest flow.
    script += ", \\\n     'bottleneck.csv' using (strcol(1) eq '" + m + "' ? $2 : 1/0):3" +
              (opt.seeds > 1 ? ":8:9 skip 1 with yerrorlines" : " skip 1 with linespoints") +
              " pt " + std::to_string(pt++) + " ps 1.5 title '" + m + "'";
  plot(opt.out_dir, "bottleneck", script + "\n");
}

}  // namespace crowddb::experiment
