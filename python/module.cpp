// The Python module crowddb._core (pybind11): simulations loaded from files or built from numpy
// arrays, stepped with the GIL released, their agent columns read as numpy views without copying,
// the crowd queries on arrays, trajectory output, and the SDF functions (sdf_module.cpp).
// python/crowddb/__init__.py re-exports it; python/crowddb/_core.pyi types it.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <atomic>
#include <cstring>
#include <optional>

#include "bindings.hpp"
#include "crowddb/query.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "io/trajectory.hpp"
#include "metrics/run.hpp"
#include "util/streamed_record.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace crowddb::python {
namespace {

// ---------------------------------------------------------------- numpy columns

// A read-only 1-D numpy array over `n` elements at `data`, kept alive by `owner` (no copy).
template <class T>
py::array column(const T* data, std::size_t n, py::handle owner) {
  py::array a(py::dtype::of<T>(), {static_cast<py::ssize_t>(n)},
              {static_cast<py::ssize_t>(sizeof(T))}, data, owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}
template <class T>
py::array column(const std::vector<T>& v, py::handle owner) {
  return column(v.data(), v.size(), owner);
}

// ---------------------------------------------------------------- settings

ArrivalPolicy arrival_of(const std::string& s) {
  if (s == "remove") return ArrivalPolicy::remove;
  if (s == "idle") return ArrivalPolicy::idle;
  if (s == "retarget") return ArrivalPolicy::retarget;
  throw Error(Error::Kind::input, "arrival: '" + s + "' is not one of remove, idle, retarget");
}

py::dict metrics_dict(const TickMetrics& m) {
  return py::dict(
      "tick"_a = m.tick, "time"_a = m.time, "agents"_a = m.agents, "active"_a = m.active,
      "entered"_a = m.entered, "arrived"_a = m.arrived, "frozen"_a = m.frozen,
      "freeze_iterations"_a = m.freeze_iterations, "overlapping_pairs"_a = m.overlapping_pairs,
      "obstacle_overlaps"_a = m.obstacle_overlaps, "gridlocked"_a = m.gridlocked,
      "stalled"_a = m.stalled, "queueing"_a = m.queueing, "nudged"_a = m.nudged,
      "yielding"_a = m.yielding, "sidestepping"_a = m.sidestepping, "making_way"_a = m.making_way,
      "longest_stall"_a = m.longest_stall, "seconds"_a = m.seconds, "state_hash"_a = m.state_hash);
}

// ---------------------------------------------------------------- World (before a run)

// A world being built from Python. Simulation(world) takes its tables; the World is then empty
// and refuses further use (its tables moved).
struct PyWorld {
  std::optional<World> world;
  World& get() {
    if (!world)
      throw Error(Error::Kind::usage, "this World was given to a Simulation: build a new one");
    return *world;
  }
};

uint32_t add_goal(PyWorld& w, const std::string& name, std::optional<double> x,
                  std::optional<double> y, double radius, std::optional<Doubles> polygon,
                  double charge) {
  Goal g;
  g.name = name;
  g.arrival_radius = radius;
  g.charge = charge;
  if (polygon) {
    if (polygon->ndim() != 2 || polygon->shape(1) != 2)
      throw py::value_error("polygon: expected an (n, 2) array of vertices");
    const auto p = polygon->unchecked<2>();
    for (py::ssize_t i = 0; i < p.shape(0); ++i) g.area.push_back({p(i, 0), p(i, 1)});
    if (x || y) {
      if (!x || !y) throw py::value_error("give both x and y, or neither");
      g.x = *x;
      g.y = *y;
    }
  } else {
    if (!x || !y) throw py::value_error("a disc goal needs x and y (or give polygon=)");
    g.x = *x;
    g.y = *y;
  }
  return w.get().add_goal(std::move(g));
}

std::vector<Vec2> vertices_of(const Doubles& v) {
  if (v.ndim() != 2 || v.shape(1) != 2) throw py::value_error("vertices: expected an (n, 2) array");
  const auto p = v.unchecked<2>();
  std::vector<Vec2> out;
  for (py::ssize_t i = 0; i < p.shape(0); ++i) out.push_back({p(i, 0), p(i, 1)});
  return out;
}

uint32_t goal_row(const World& w, const py::handle& goal) {
  if (py::isinstance<py::str>(goal)) {
    const auto name = goal.cast<std::string>();
    const auto row = w.goal_named(name);
    if (!row) throw Error(Error::Kind::input, "goal: no goal named '" + name + "'");
    return *row;
  }
  return goal.cast<uint32_t>();
}

// Inserts agents from arrays (scalars apply to every agent); returns their ids. All rows are
// validated before any is inserted, so a bad row inserts nothing.
py::array_t<uint64_t> insert_agents(World& w, const Doubles& x, const Doubles& y,
                                    const py::object& goal, const Doubles& radius,
                                    const Doubles& pref_speed, std::optional<Doubles> max_speed,
                                    const Doubles& vx, const Doubles& vy) {
  const std::size_t n = length_of(x, "x");
  const Broadcast by(y, n, "y"), br(radius, n, "radius"), bp(pref_speed, n, "pref_speed");
  const Broadcast bvx(vx, n, "vx"), bvy(vy, n, "vy");
  std::optional<Broadcast> bm;
  if (max_speed) bm.emplace(*max_speed, n, "max_speed");
  std::vector<uint32_t> goals;
  if (py::isinstance<py::str>(goal) || py::isinstance<py::int_>(goal)) {
    goals.assign(n, goal_row(w, goal));
  } else {
    const auto g = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(goal);
    if (!g || g.ndim() != 1 || static_cast<std::size_t>(g.size()) != n)
      throw py::value_error("goal: expected a goal name, a goal row or one row per agent");
    for (std::size_t i = 0; i < n; ++i) {
      if (g.data()[i] < 0)
        throw Error(Error::Kind::input, "goal: row " + std::to_string(i) + " is negative");
      goals.push_back(static_cast<uint32_t>(g.data()[i]));
    }
  }
  std::vector<AgentSpec> specs(n);
  for (std::size_t i = 0; i < n; ++i) {
    AgentSpec& s = specs[i];
    s.x = x.data()[i];
    s.y = by[i];
    s.vx = bvx[i];
    s.vy = bvy[i];
    s.radius = br[i];
    s.pref_speed = bp[i];
    s.max_speed = bm ? (*bm)[i] : s.pref_speed;  // as in scenario files
    s.goal = goals[i];
    try {
      World::validate_spec(s, w.goals().size());
    } catch (const InvalidRow& e) {
      throw InvalidRow(e.field(), "agent " + std::to_string(i) + ": " + e.what());
    }
  }
  py::array_t<uint64_t> ids(n);
  for (std::size_t i = 0; i < n; ++i) ids.mutable_data()[i] = w.insert(specs[i]).value();
  return ids;
}

// ---------------------------------------------------------------- Simulation

struct PySimulation;

// sim.agents: the agents table's columns as read-only numpy views of the simulation's own memory.
struct Agents {
  py::object sim;  // the Python Simulation: each view keeps it alive
  const AgentTable& table() const;
};

struct PySimulation {
  std::unique_ptr<Simulation> sim;
  std::optional<Scenario> scenario;  // from a file: its metadata (its world moved into sim)
  std::unique_ptr<io::TrajectoryWriter> writer;
  std::atomic<bool> busy{false};

  Simulation& get() { return *sim; }
  // One call at a time: step() runs without the GIL.
  struct Busy {
    PySimulation& s;
    explicit Busy(PySimulation& p) : s(p) {
      if (s.busy.exchange(true))
        throw Error(Error::Kind::usage, "this Simulation is stepping in another thread");
    }
    ~Busy() { s.busy = false; }
  };
};

SimConfig config_of(double dt, uint64_t seed, const std::string& model, int threads, bool walls,
                    const std::string& arrival, bool backoff) {
  SimConfig c;
  c.dt = dt;
  c.seed = seed;
  c.steering.model = model;
  c.threads = threads;
  c.walls = walls;
  c.arrival = arrival_of(arrival);
  c.backoff = backoff;
  c.validate();
  return c;
}

std::unique_ptr<PySimulation> from_file(const std::filesystem::path& path,
                                        const std::vector<std::string>& overrides,
                                        std::optional<int> threads,
                                        std::optional<std::filesystem::path> behavior) {
  LoadOptions options;
  options.overrides = overrides;
  if (behavior) options.behavior = *behavior;
  auto p = std::make_unique<PySimulation>();
  {
    py::gil_scoped_release release;
    Scenario sc = load_scenario(path, options);
    if (threads) {
      sc.config.threads = *threads;
      sc.config.validate();
    }
    p->sim = std::make_unique<Simulation>(std::move(sc.world), sc.config);
    sc.world = World();
    p->scenario = std::move(sc);
  }
  return p;
}

const TickMetrics& step(PySimulation& p, uint64_t n) {
  PySimulation::Busy busy(p);
  {
    py::gil_scoped_release release;
    for (uint64_t i = 0; i < n; ++i) {
      const TickMetrics& m = p.sim->step();
      if (p.writer) {
        p.writer->frame(m.tick, p.sim->world());
        p.writer->metrics(m);
      }
    }
  }
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  return p.sim->last_metrics();
}

void record(PySimulation& p, const std::filesystem::path& path, uint32_t every) {
  PySimulation::Busy busy(p);  // step() writes through the writer without the GIL
  if (p.writer) throw Error(Error::Kind::usage, "already recording: call close() first");
  if (every == 0) throw Error(Error::Kind::input, "every: must be >= 1");
  Scenario meta;
  if (p.scenario) {
    meta.name = p.scenario->name;
    meta.source = p.scenario->source;
    meta.text = p.scenario->text;
    meta.format = p.scenario->format;
  } else {
    meta.name = "python";
    meta.source = "<python>";
  }
  meta.config = p.sim->config();
  const std::string ext = path.extension().string();
  auto w = ext == ".csv" ? io::make_csv_writer(path, every) : io::make_sqlite_writer(path, every);
  w->begin(meta, p.sim->world());
  w->frame(p.sim->ticks(), p.sim->world());
  p.writer = std::move(w);
}

void close(PySimulation& p) {
  PySimulation::Busy busy(p);
  if (!p.writer) return;
  io::RunInfo info;
  info.threads = p.sim->config().threads;
  info.ticks = p.sim->ticks();
  info.final_hash = p.sim->state_hash();
  auto w = std::move(p.writer);
  py::gil_scoped_release release;  // finishing may wait for a reader of the file (seconds)
  w->finish(info);
}

// The state streamed twice, to count its bytes and then into a bytes object of that size: no
// string of it besides (at 10^6 agents 194 MB, which as a string grows and then copies).
py::bytes save_state(PySimulation& p) {
  PySimulation::Busy busy(p);
  const StreamedRecord state = [&p](const ByteSink& sink) { p.get().save_state(sink); };
  const std::size_t size = streamed_size(state);
  py::object out = py::reinterpret_steal<py::object>(
      PyBytes_FromStringAndSize(nullptr, static_cast<Py_ssize_t>(size)));
  if (!out) throw py::error_already_set();
  char* const room = PyBytes_AS_STRING(out.ptr());
  stream_into(state, size, [room](std::string_view piece, std::size_t at) {
    std::memcpy(room + at, piece.data(), piece.size());
  });
  return py::reinterpret_borrow<py::bytes>(out);
}

const AgentTable& Agents::table() const {
  return sim.cast<PySimulation&>().get().world().agents();
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "crowddb: crowd simulation as an in-memory database (see help(crowddb))";
  register_errors(m);

  py::class_<PyWorld>(m, "World", "A world under construction: bounds, goals, obstacles, agents.")
      .def(py::init([](std::tuple<double, double, double, double> b) {
             auto w = std::make_unique<PyWorld>();
             w->world.emplace();
             w->world->set_bounds({std::get<0>(b), std::get<1>(b), std::get<2>(b), std::get<3>(b)});
             return w;
           }),
           "bounds"_a,
           "bounds: (xmin, ymin, xmax, ymax) in metres; walls unless walls=False later.")
      .def("add_goal", &add_goal, "name"_a, "x"_a = py::none(), "y"_a = py::none(),
           "radius"_a = 1.0, "polygon"_a = py::none(), "charge"_a = 1.0,
           "A goal: a disc (x, y, radius) or a polygon ((n, 2) vertices). Returns its row.")
      .def(
          "add_circle",
          [](PyWorld& w, double x, double y, double radius) {
            return w.get().add_obstacle(CircleObstacle{x, y, radius, 1});
          },
          "x"_a, "y"_a, "radius"_a, "A circular obstacle. Returns its row.")
      .def(
          "add_polygon",
          [](PyWorld& w, const Doubles& vertices) {
            return w.get().add_obstacle(PolygonObstacle{vertices_of(vertices), 1});
          },
          "vertices"_a, "A simple polygon obstacle ((n, 2) vertices). Returns its row.")
      .def(
          "insert_agents",
          [](PyWorld& w, const Doubles& x, const Doubles& y, const py::object& goal,
             const Doubles& radius, const Doubles& pref_speed, std::optional<Doubles> max_speed,
             const Doubles& vx, const Doubles& vy) {
            return insert_agents(w.get(), x, y, goal, radius, pref_speed, std::move(max_speed), vx,
                                 vy);
          },
          "x"_a, "y"_a, "goal"_a, "radius"_a = 0.25, "pref_speed"_a = 1.34,
          "max_speed"_a = py::none(), "vx"_a = 0.0, "vy"_a = 0.0,
          "Agents from arrays (a number applies to all). Returns their ids (uint64).")
      .def_property_readonly("agent_count", [](PyWorld& w) { return w.get().pending_changes(); });

  py::class_<PySimulation>(m, "Simulation")
      .def(py::init([](PyWorld& w, double dt, uint64_t seed, const std::string& model, int threads,
                       bool walls, const std::string& arrival, bool backoff) {
             SimConfig c = config_of(dt, seed, model, threads, walls, arrival, backoff);
             World world = std::move(w.get());
             w.world.reset();
             auto p = std::make_unique<PySimulation>();
             p->sim = std::make_unique<Simulation>(std::move(world), c);
             return p;
           }),
           "world"_a, py::kw_only(), "dt"_a = 0.1, "seed"_a = 1, "model"_a = "orca",
           "threads"_a = 1, "walls"_a = true, "arrival"_a = "remove", "backoff"_a = true,
           "A simulation of `world` (its tables move in: the World is empty afterwards).")
      .def_static("from_file", &from_file, "path"_a, py::kw_only(),
                  "overrides"_a = std::vector<std::string>{}, "threads"_a = py::none(),
                  "behavior"_a = py::none(),
                  "Loads a scenario of any format the CLI reads (crowddb JSON, SteerSuite, Menge, "
                  "Vadere). overrides: 'KEY=VALUE' as crowddb run --set.")
      .def(
          "step", [](PySimulation& p, uint64_t n) { return metrics_dict(step(p, n)); }, "n"_a = 1,
          "Runs n ticks (without the GIL). Returns the last tick's metrics.")
      .def_property_readonly("tick", [](PySimulation& p) { return p.get().ticks(); })
      .def_property_readonly("time", [](PySimulation& p) { return p.get().time(); })
      .def_property_readonly("dt", [](PySimulation& p) { return p.get().config().dt; })
      .def_property_readonly("planned_ticks",
                             [](PySimulation& p) -> std::optional<uint64_t> {
                               if (p.scenario) return p.scenario->ticks;
                               return std::nullopt;
                             })
      .def_property_readonly("arrived_total",
                             [](PySimulation& p) { return p.get().arrived_total(); })
      .def_property_readonly("entered_total",
                             [](PySimulation& p) { return p.get().entered_total(); })
      .def_property_readonly("state_hash", [](PySimulation& p) { return p.get().state_hash(); })
      .def_property_readonly("metrics",
                             [](PySimulation& p) { return metrics_dict(p.get().last_metrics()); })
      .def_property_readonly(
          "agents", [](py::object self) { return Agents{std::move(self)}; },
          "The agents table: .x .y .vx .vy .radius .pref_speed .max_speed .goal .state .id "
          ".target_x .target_y as read-only numpy views (no copy), valid until the next step.")
      .def_property_readonly(
          "goals",
          [](PySimulation& p) {
            py::list out;
            for (const Goal& g : p.get().world().goals())
              out.append(py::dict("name"_a = g.name, "x"_a = g.x, "y"_a = g.y,
                                  "radius"_a = g.arrival_radius, "polygon"_a = g.area.size()));
            return out;
          })
      .def(
          "goal",
          [](PySimulation& p, const std::string& name) {
            return goal_row(p.get().world(), py::str(name));
          },
          "name"_a, "The row of the goal with this name.")
      .def(
          "insert_agents",
          [](PySimulation& p, const Doubles& x, const Doubles& y, const py::object& goal,
             const Doubles& radius, const Doubles& pref_speed, std::optional<Doubles> max_speed,
             const Doubles& vx, const Doubles& vy) {
            PySimulation::Busy busy(p);
            return insert_agents(p.get().world(), x, y, goal, radius, pref_speed,
                                 std::move(max_speed), vx, vy);
          },
          "x"_a, "y"_a, "goal"_a, "radius"_a = 0.25, "pref_speed"_a = 1.34,
          "max_speed"_a = py::none(), "vx"_a = 0.0, "vy"_a = 0.0,
          "Agents to insert at the start of the next step. Returns their ids.")
      .def(
          "erase",
          [](PySimulation& p, uint64_t id) {
            PySimulation::Busy busy(p);
            p.get().world().erase(AgentId::from_value(id));
          },
          "id"_a, "Removes an agent at the start of the next step.")
      .def(
          "retarget",
          [](PySimulation& p, uint64_t id, const py::object& goal) {
            PySimulation::Busy busy(p);
            World& w = p.get().world();
            w.retarget(AgentId::from_value(id), goal_row(w, goal));
          },
          "id"_a, "goal"_a, "Sends an agent to another goal (name or row) from the next step.")
      .def("explain", [](PySimulation& p) { return p.get().explain(); })
      .def("explain_analyze", [](PySimulation& p) { return p.get().explain_analyze(); })
      .def("save_state", &save_state)
      .def("restore_state",
           [](PySimulation& p, const py::bytes& b) {
             PySimulation::Busy busy(p);
             p.get().restore_state(std::string_view(b), "checkpoint");
           })
      .def("record", &record, "path"_a, "every"_a = 1,
           "Writes trajectories from now on: SQLite (JuPedSim's format) or, for a .csv path, "
           "CSV. Every step adds a frame (every n-th). close() finishes the file.")
      .def("close", &close, "Finishes the trajectory file, if recording.")
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](PySimulation& p, py::object, py::object, py::object) { close(p); });

  py::class_<Agents> agents(
      m, "Agents",
      "The agents table of a Simulation, one row per agent. Every column is "
      "a read-only numpy view of the simulation's memory (no copy): valid "
      "until the next step(), insert or erase; copy it to keep it. Rows change "
      "order between steps (arrivals; from 4096 agents the Z-curve order "
      "every 2 s, access.row_order): match agents across steps by id.");
  agents.def("__len__", [](const Agents& a) { return a.table().size(); });
#define CROWDDB_COLUMN(name, doc) \
  agents.def_property_readonly(   \
      #name, [](const Agents& a) { return column(a.table().name, a.sim); }, doc)
  CROWDDB_COLUMN(x, "[m] position x (float64)");
  CROWDDB_COLUMN(y, "[m] position y (float64)");
  CROWDDB_COLUMN(vx, "[m/s] velocity x (float64)");
  CROWDDB_COLUMN(vy, "[m/s] velocity y (float64)");
  CROWDDB_COLUMN(radius, "[m] (float64)");
  CROWDDB_COLUMN(pref_speed, "[m/s] preferred speed (float64)");
  CROWDDB_COLUMN(max_speed, "[m/s] (float64)");
  CROWDDB_COLUMN(target_x, "[m] current waypoint x (float64)");
  CROWDDB_COLUMN(target_y, "[m] current waypoint y (float64)");
  CROWDDB_COLUMN(goal, "goal row (uint32)");
  CROWDDB_COLUMN(id, "agent id (uint64), stable while the agent lives");
#undef CROWDDB_COLUMN
  agents.def_property_readonly(
      "state",
      [](const Agents& a) {
        const auto& s = a.table().state;
        return column(reinterpret_cast<const uint8_t*>(s.data()), s.size(), a.sim);
      },
      "0 active, 1 frozen (put back by the backoff loop), 2 arrived (idling), 3 waiting at a "
      "goal (uint8)");

  bind_queries(m);
  bind_sdf(m);
}

}  // namespace crowddb::python
