// crowddb.sdf: SDF graphs from Python (load, repetitions, static schedule, online run), and the
// module's error classes (both libraries' errors map onto them).
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "crowddb/error.hpp"
#include "sdf/io.hpp"
#include "sdf/online.hpp"
#include "sdf/repetitions.hpp"
#include "sdf/schedule.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace crowddb::python {
namespace {

// The exception classes, created once at import (never freed: the module is never unloaded).
PyObject* g_error = nullptr;
PyObject* g_input = nullptr;
PyObject* g_invalid_row = nullptr;
PyObject* g_io = nullptr;
PyObject* g_usage = nullptr;

PyObject* new_error(py::module_& m, const char* name, py::tuple bases, const char* doc) {
  const std::string qualified = "crowddb." + std::string(name);
  PyObject* e = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (!e) throw py::error_already_set();
  m.attr(name) = py::handle(e);
  return e;
}

PyObject* class_of(bool usage, bool io) {
  return usage ? g_usage : io ? g_io : g_input;
}

std::vector<uint64_t> repetitions_or_throw(const sdf::Graph& g) {
  const sdf::Repetitions r = sdf::compute_repetitions(g);
  if (!r.consistent) {
    const sdf::Channel& c = g.channel(r.channel);
    throw sdf::Error(sdf::Error::Kind::input,
                     "inconsistent: the balance of channel " + g.actor_name(c.src) + " -> " +
                         g.actor_name(c.dst) + " fails (" + std::to_string(r.q_src) + " vs " +
                         std::to_string(r.q_dst) + ")");
  }
  return r.q;
}

py::list runs_of(const sdf::Graph& g, std::span<const sdf::Run> runs) {
  py::list out;
  for (const sdf::Run& r : runs) out.append(py::make_tuple(g.actor_name(r.actor), r.count));
  return out;
}

}  // namespace

void register_errors(py::module_& m) {
  g_error = new_error(m, "Error", py::make_tuple(py::handle(PyExc_Exception)),
                      "Every error crowddb reports: one line naming the file and field or line.");
  g_input =
      new_error(m, "InputError", py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError)),
                "Malformed or invalid input: a file, a row, a parameter.");
  g_invalid_row = new_error(m, "InvalidRow", py::make_tuple(py::handle(g_input)),
                            "An invalid table row; .field names the field.");
  g_io = new_error(m, "IOError", py::make_tuple(py::handle(g_error), py::handle(PyExc_OSError)),
                   "The operating system refused (a missing file, an unwritable path).");
  g_usage =
      new_error(m, "UsageError", py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError)),
                "A call that cannot be made in this state or with these arguments.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InvalidRow& e) {
      py::object ex =
          py::reinterpret_steal<py::object>(PyObject_CallFunction(g_invalid_row, "s", e.what()));
      if (!ex) throw py::error_already_set();
      ex.attr("field") = e.field();
      PyErr_SetObject(g_invalid_row, ex.ptr());
    } catch (const Error& e) {
      PyErr_SetString(class_of(e.kind() == Error::Kind::usage, e.kind() == Error::Kind::io),
                      e.what());
    } catch (const sdf::Error& e) {
      PyErr_SetString(
          class_of(e.kind() == sdf::Error::Kind::usage, e.kind() == sdf::Error::Kind::io),
          e.what());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError, "crowddb: out of memory");
    }
  });
}

void bind_sdf(py::module_& m) {
  py::module_ s = m.def_submodule("_sdf", "Synchronous Data-Flow graphs (docs/sdf.md).");
  py::class_<sdf::Graph>(s, "Graph", "An SDF graph: actors and channels with rates and delays.")
      .def_property_readonly("name", [](const sdf::Graph& g) { return g.name; })
      .def_property_readonly("actors",
                             [](const sdf::Graph& g) {
                               std::vector<std::string> names;
                               for (sdf::ActorId a = 0; a < g.actor_count(); ++a)
                                 names.push_back(g.actor_name(a));
                               return names;
                             })
      .def_property_readonly(
          "channels",
          [](const sdf::Graph& g) {
            py::list out;
            for (const sdf::Channel& c : g.channels())
              out.append(py::dict("src"_a = g.actor_name(c.src), "dst"_a = g.actor_name(c.dst),
                                  "prd"_a = c.prd, "cns"_a = c.cns, "delay"_a = c.delay));
            return out;
          })
      .def("to_json", &sdf::write_json)
      .def("to_sdf3", &sdf::write_sdf3)
      .def("to_dot", &sdf::write_dot)
      .def("__repr__", [](const sdf::Graph& g) {
        return "<sdf.Graph '" + g.name + "': " + std::to_string(g.actor_count()) + " actors, " +
               std::to_string(g.channel_count()) + " channels>";
      });
  s.def("load", &sdf::read_graph_file, "path"_a,
        "Reads an SDF3 XML (.xml) or JSON (.json) graph file.");
  s.def(
      "from_json", [](const std::string& text) { return sdf::read_json(text, "<json>"); },
      "text"_a);
  s.def(
      "repetitions",
      [](const sdf::Graph& g) {
        const std::vector<uint64_t> q = repetitions_or_throw(g);
        py::dict out;
        for (sdf::ActorId a = 0; a < g.actor_count(); ++a) out[py::str(g.actor_name(a))] = q[a];
        return out;
      },
      "graph"_a,
      "The repetitions vector {actor: firings per iteration}; InputError naming the channel "
      "when the graph is inconsistent.");
  s.def(
      "schedule",
      [](const sdf::Graph& g) {
        const std::vector<uint64_t> q = repetitions_or_throw(g);
        const sdf::StaticSchedule st = sdf::static_schedule(g, q);
        py::list stuck;
        for (sdf::ActorId a : st.stuck) stuck.append(g.actor_name(a));
        return py::dict("complete"_a = st.complete, "runs"_a = runs_of(g, st.runs),
                        "firings"_a = sdf::total_firings(st.runs), "stuck"_a = stuck);
      },
      "graph"_a,
      "One period of a static schedule as runs [(actor, count), ...]; when the graph deadlocks, "
      "complete is False, runs the maximal prefix and stuck the actors below their count.");
  s.def(
      "simulate",
      [](const sdf::Graph& g, uint64_t max_decisions) {
        const std::vector<uint64_t> q = repetitions_or_throw(g);
        sdf::OnlineRunOptions o;
        o.max_decisions = max_decisions;
        sdf::OnlineRun r;
        {
          py::gil_scoped_release release;
          r = sdf::run_online(g, q, o);
        }
        return py::dict("outcome"_a = sdf::outcome_name(r.outcome),
                        "transient_firings"_a = r.transient_firings,
                        "cycle_firings"_a = r.cycle_firings, "buffers"_a = r.metrics.buffers);
      },
      "graph"_a, "max_decisions"_a = 100'000'000,
      "The thesis's online rule from the delays: its outcome (returns, periodic, unbounded, "
      "deadlock, limit), firings and the buffer sizes per channel.");
}

}  // namespace crowddb::python
