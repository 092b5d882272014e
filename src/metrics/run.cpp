#include "metrics/run.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "crowddb/error.hpp"
#include "io/trajectory.hpp"
#include "util/byte_codec.hpp"
#include "util/executor.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::metrics {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double hi = v[mid];
  if (v.size() % 2) return hi;
  return (hi + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid))) / 2;
}

std::string g(double v) {  // shortest form: 0.2, 5, 1e-05
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

std::string hex(uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

namespace {

constexpr std::string_view kProgressMagic = "crowddb-run-progress";

// What a run accumulates besides the simulation: saved with each checkpoint.
struct Progress {
  RunSummary* s;
  SteerBench* bench;
  std::vector<double>* tick_seconds;
  uint64_t* last_arrival;
  std::size_t *longest_frozen, *longest_stall;
  double* wall_before;  // [s] spent before the resume

  template <class F>
  void counters(F&& f) const {
    for (std::size_t* v :
         {&s->agents_at_start, &s->max_overlapping_pairs, &s->max_obstacle_overlaps,
          &s->frozen_agent_ticks, &s->freeze_iterations_total, &s->freeze_iterations_max,
          &s->gridlocked_max, &s->gridlock_streaks, &s->nudged, &s->stall_streaks, &s->stalled_max,
          &s->yields, &s->sidesteps, &s->make_ways, longest_frozen, longest_stall})
      f(*v);
  }
  // Returned, or with a sink streamed to it (and nothing returned): SteerBench's tracks of 10^6
  // agents are a hundred MB.
  std::string save(double wall_now, const ByteSink* sink = nullptr) const {
    ByteWriter out(kProgressMagic);
    if (sink) out.stream_to(*sink);
    out.u64(s->ticks);
    counters([&](std::size_t& v) { out.u64(v); });
    out.u64(*last_arrival);
    out.f64(wall_now);
    out.vec(*tick_seconds);
    bench->save(out);
    return out.seal();
  }
  void restore(std::string_view bytes) const {
    ByteReader in = ByteReader::open_sealed(bytes, kProgressMagic, "run's progress record",
                                            "checkpoint: run progress");
    s->ticks = in.u64();
    counters([&](std::size_t& v) { v = in.u64(); });
    *last_arrival = in.u64();
    *wall_before = in.f64();
    in.vec(*tick_seconds);
    bench->restore(in);
    if (!in.at_end()) in.fail("run progress: trailing data");
  }
};

}  // namespace

RunSummary run_to_end(const Scenario& sc, Simulation& sim, const RunControl& control) {
  RunSummary s;
  s.name = sc.name;
  s.source = sc.source;
  s.format = sc.format;
  s.model = sim.config().steering.model;
  s.dt = sim.config().dt;
  s.threads = sim.config().threads;
  s.ticks_planned = sc.ticks;
  s.agents_at_start = sim.world().agents().size();
  const double dt = s.dt;
  SteerBench bench(dt, sim.config().walls);
  Executor metrics_ex(sim.config().threads);  // the scores' per-row pass, between ticks
  std::vector<double> tick_seconds;
  uint64_t last_arrival = 0;
  std::size_t longest_frozen = 0, longest_stall = 0;
  double wall_before = 0;
  const Progress progress{
      &s, &bench, &tick_seconds, &last_arrival, &longest_frozen, &longest_stall, &wall_before};
  if (control.resume_from) {
    progress.restore(*control.resume_from);
    if (s.ticks != sim.ticks())
      throw Error(Error::Kind::input, "checkpoint: the run's progress is of tick " +
                                          std::to_string(s.ticks) + ", the simulation's of tick " +
                                          std::to_string(sim.ticks()));
  } else {
    bench.start(sim.world());
  }
  tick_seconds.reserve(std::min<uint64_t>(sc.ticks, 1u << 20));
  Stopwatch clock, since_checkpoint;
  io::TrajectoryWriter* w = control.writer;
  const auto checkpoint = [&] {
    if (w && control.checkpoint_every >= 0) {
      // Streamed into the output (each as often as the writer asks, the same bytes each time):
      // the simulation's state alone is 194 MB at 10^6 agents, and held whole it sat in memory
      // two or three times over while it was written.
      const double wall_now = wall_before + clock.seconds();
      w->checkpoint(
          s.ticks, [&](const ByteSink& sink) { sim.save_state(sink); },
          [&](const ByteSink& sink) { progress.save(wall_now, &sink); });
    }
    since_checkpoint.restart();
  };
  try {
    if (w && !control.resume_from) w->frame(0, sim.world());
    for (uint64_t t = s.ticks + 1; t <= sc.ticks; ++t) {
      if (control.interrupted && control.interrupted()) {
        checkpoint();  // the state after tick t - 1 is whole: a resume continues from it
        throw Error(Error::Kind::io, "interrupted at tick " + std::to_string(t - 1));
      }
      const TickMetrics& m = sim.step();
      tick_seconds.push_back(m.seconds);
      bench.tick(sim.world(), m, &metrics_ex);
      s.max_overlapping_pairs = std::max(s.max_overlapping_pairs, m.overlapping_pairs);
      s.max_obstacle_overlaps = std::max(s.max_obstacle_overlaps, m.obstacle_overlaps);
      s.frozen_agent_ticks += m.frozen;
      s.freeze_iterations_total += m.freeze_iterations;
      s.freeze_iterations_max = std::max(s.freeze_iterations_max, m.freeze_iterations);
      s.gridlocked_max = std::max(s.gridlocked_max, m.gridlocked);
      s.gridlock_streaks += m.gridlock_started;
      longest_frozen = std::max(longest_frozen, m.longest_frozen);
      s.nudged += m.nudged;
      s.stall_streaks += m.stall_started;
      s.stalled_max = std::max(s.stalled_max, m.stalled);
      longest_stall = std::max(longest_stall, m.longest_stall);
      s.yields += m.yielding;
      s.sidesteps += m.sidestepping;
      s.make_ways += m.making_way;
      if (m.arrived) last_arrival = m.tick;
      s.ticks = t;
      if (w) {
        w->frame(t, sim.world());  // the writer keeps every n-th frame
        w->metrics(m);
        if (control.checkpoint_every >= 0 && t < sc.ticks &&
            since_checkpoint.seconds() >= control.checkpoint_every)
          checkpoint();
      }
      if (control.on_tick) control.on_tick(sim, m, sc.ticks);
      if (sc.stop_when_all_arrived && m.active == 0 && sim.waiting_to_enter() == 0) {
        s.stopped_when_all_arrived = t < sc.ticks;
        break;
      }
    }
    s.wall_seconds = wall_before + clock.seconds();
    s.state_hash = sim.state_hash();
    s.steerbench = bench.totals();
    if (w) {
      io::RunInfo info;
      info.threads = s.threads;
      info.ticks = s.ticks;
      info.final_hash = s.state_hash;
      info.seconds = s.wall_seconds;
      info.summary_json = s.json();
      info.steerbench = &bench;
      w->finish(info);
    }
  } catch (const Error& e) {
    // Keep what was written: the frames up to the last tick, marked as an incomplete run.
    const std::filesystem::path kept = w ? w->stop(s.ticks, e.what()) : std::filesystem::path();
    if (kept.empty()) throw;
    throw Error(e.kind(), std::string(e.what()) + "; the run's output up to tick " +
                              std::to_string(s.ticks) + " is kept in " + kept.string() +
                              " (incomplete)");
  } catch (const std::bad_alloc&) {
    if (w) w->stop(s.ticks, "out of memory");
    throw;
  } catch (...) {
    if (w) w->stop(s.ticks, "stopped by an unexpected error");
    throw;
  }
  const TickMetrics& last = sim.last_metrics();
  s.sim_seconds = static_cast<double>(s.ticks) * dt;
  s.entered = sim.entered_total();
  s.waiting_to_enter = sim.waiting_to_enter();
  s.agents_at_end = sim.world().agents().size();
  s.agents_total = s.agents_at_start + s.entered;
  s.arrived = sim.arrived_total();
  s.still_walking = last.active;
  const auto& states = sim.world().agents().state;
  s.waiting_at_goals =
      static_cast<std::size_t>(std::count(states.begin(), states.end(), AgentState::waiting));
  s.without_path = sim.without_path();
  s.all_arrived = last.active == 0 && s.waiting_to_enter == 0;
  s.last_arrival_s = last_arrival ? static_cast<double>(last_arrival) * dt : -1;
  s.overlapping_pairs_at_end = last.overlapping_pairs;
  s.gridlocked_at_end = last.gridlocked;
  s.longest_frozen_s = static_cast<double>(longest_frozen) * dt;
  s.stalled_at_end = last.stalled;
  s.max_stalled_s = static_cast<double>(longest_stall) * dt;
  double sum = 0;
  for (double x : tick_seconds) sum += x;
  s.ms_per_tick_median = 1e3 * median(tick_seconds);
  s.ms_per_tick_mean =
      tick_seconds.empty() ? 0 : 1e3 * sum / static_cast<double>(tick_seconds.size());
  return s;
}

std::string RunSummary::json() const {
  // Times are tick counts times dt: 229 * 0.1 prints as 22.900000000000002; a nanosecond grid
  // keeps them readable without losing anything a tick can resolve.
  auto ns = [](double v) { return std::round(v * 1e9) / 1e9; };
  nlohmann::ordered_json j;
  j["name"] = name;
  j["source"] = source;
  j["format"] = format;
  j["model"] = model;
  j["dt"] = dt;
  j["threads"] = threads;
  j["ticks"] = ticks;
  j["sim_seconds"] = ns(sim_seconds);
  j["stopped_when_all_arrived"] = stopped_when_all_arrived;
  j["agents_at_start"] = agents_at_start;
  j["entered"] = entered;
  j["waiting_to_enter"] = waiting_to_enter;
  j["agents_total"] = agents_total;
  j["arrived"] = arrived;
  j["still_walking"] = still_walking;
  j["waiting_at_goals"] = waiting_at_goals;
  j["without_path"] = without_path;
  j["all_arrived"] = all_arrived;
  if (last_arrival_s >= 0)
    j["last_arrival_s"] = ns(last_arrival_s);
  else
    j["last_arrival_s"] = nullptr;
  j["max_overlapping_pairs"] = max_overlapping_pairs;
  j["max_obstacle_overlaps"] = max_obstacle_overlaps;
  j["overlapping_pairs_at_end"] = overlapping_pairs_at_end;
  j["frozen_agent_ticks"] = frozen_agent_ticks;
  j["gridlocked_at_end"] = gridlocked_at_end;
  j["longest_frozen_s"] = ns(longest_frozen_s);
  j["stall_streaks"] = stall_streaks;
  j["stalled_at_end"] = stalled_at_end;
  j["max_stalled_s"] = ns(max_stalled_s);
  j["yields"] = yields;
  j["sidesteps"] = sidesteps;
  j["make_ways"] = make_ways;
  j["wall_seconds"] = wall_seconds;
  j["ms_per_tick_median"] = ms_per_tick_median;
  j["ms_per_tick_mean"] = ms_per_tick_mean;
  j["state_hash"] = hex(state_hash);
  j["steerbench"] = {{"agents", steerbench.agents},
                     {"collisions", steerbench.collisions},
                     {"avg_collisions", steerbench.avg_collisions},
                     {"avg_time_s", steerbench.avg_time},
                     {"avg_path_length_m", steerbench.avg_path},
                     {"avg_energy", steerbench.avg_energy},
                     {"avg_acceleration", steerbench.avg_acceleration},
                     {"composite01", steerbench.composite01},
                     {"composite02", steerbench.composite02}};
  return j.dump(2) + "\n";
}

std::string RunSummary::text(const SimConfig& cfg) const {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(2);
  auto secs = [](double v) {
    std::ostringstream o;
    o.setf(std::ios::fixed);
    o.precision(1);
    o << v << " s";
    return o.str();
  };
  os << name << ": " << ticks << " ticks of " << g(dt) << " s (" << sim_seconds << " s simulated";
  if (stopped_when_all_arrived) os << ", stopped when everyone had arrived";
  os << ") in " << wall_seconds << " s, model " << model;
  if (format != "crowddb") os << ", imported from " << format;
  if (ticks > 0)
    os << "\n  speed: " << 1e3 / std::max(ms_per_tick_mean, 1e-9) << " ticks/s; per tick mean "
       << ms_per_tick_mean << " ms, median " << ms_per_tick_median << " ms; " << threads
       << " thread" << (threads > 1 ? "s" : "");
  os << "\n  agents: " << agents_at_start << " at start";
  if (entered || waiting_to_enter)
    os << ", " << entered << " entered from sources (" << waiting_to_enter << " still to enter)";
  os << ", " << agents_at_end << " at end; arrived " << arrived;
  if (last_arrival_s >= 0) os << " (the last at " << secs(last_arrival_s) << ")";
  if (sim_seconds > 0)
    os << ", " << static_cast<double>(arrived) * 60 / sim_seconds << " arrivals per minute";
  os << (all_arrived ? "; everyone arrived"
                     : "; " + std::to_string(still_walking) + " still walking");
  if (waiting_at_goals > 0) os << " (" << waiting_at_goals << " of them waiting at a goal)";
  if (without_path > 0)
    os << "; " << without_path
       << " of them with no path to their goal on the navigation mesh (their route ends short "
          "of it: a goal walled in, or out of the mesh's reach)";
  os << "\n  overlaps after a tick: at most " << max_overlapping_pairs << " agent pairs and "
     << max_obstacle_overlaps << " agent-obstacle; at the end " << overlapping_pairs_at_end
     << " pairs\n  backoff: " << (cfg.backoff ? "on" : "off") << ", " << frozen_agent_ticks
     << " agent-ticks frozen";
  if (cfg.backoff && ticks > 0)
    os << ", freeze rounds per tick mean "
       << static_cast<double>(freeze_iterations_total) / static_cast<double>(ticks) << " max "
       << freeze_iterations_max;
  os << "\n  gridlock (frozen " << g(cfg.gridlock_time) << " s in a row): " << gridlock_streaks
     << " streaks reached it, at most " << gridlocked_max << " agents at once, "
     << gridlocked_at_end << " at the end; longest frozen streak " << secs(longest_frozen_s);
  os << "\n  stalled (no progress for " << g(cfg.stall.after) << " s): " << stall_streaks
     << " times, at most " << stalled_max << " agents at once, " << stalled_at_end
     << " at the end; longest " << secs(max_stalled_s) << " without progress";
  if (cfg.stall.resolve)
    os << "; resolved by " << yields << " yields, " << sidesteps << " sidesteps and " << make_ways
       << " make-ways";
  else
    os << "; resolution off";
  os << "\n  nudge: ";
  if (cfg.nudge_after > 0)
    os << "sidestep after " << g(cfg.nudge_after) << " s frozen, " << nudged
       << " agent-ticks nudged";
  else
    os << "off (nudge_after = 0)";
  os << "\n  SteerBench (" << steerbench.agents << " agents): collisions " << steerbench.collisions
     << ", avg time " << steerbench.avg_time << " s, avg path " << steerbench.avg_path
     << " m, avg energy " << steerbench.avg_energy << ", avg acceleration "
     << steerbench.avg_acceleration << "; composite01 " << steerbench.composite01
     << ", composite02 " << steerbench.composite02;
  os << "\n  final state hash " << hex(state_hash) << "\n";
  return os.str();
}

}  // namespace crowddb::metrics
