// crowddb.ftc, crowddb.field and crowddb.collisions on numpy arrays: the queries of
// include/crowddb/query.hpp (every method exact, "auto" lets the planner choose).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "crowddb/error.hpp"
#include "crowddb/query.hpp"
#include "crowddb/world.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace crowddb::python {
namespace {

// A one-element array (Doubles(v) would be an array of v elements).
Doubles scalar(double v) {
  Doubles a(1);
  a.mutable_data()[0] = v;
  return a;
}

// Disc columns from arrays; scalars (or 1-element arrays) apply to every disc.
DiscTable discs_of(const Doubles& x, const Doubles& y, const Doubles& vx, const Doubles& vy,
                   const Doubles& radius, const Doubles& charge) {
  const std::size_t n = length_of(x, "x");
  const Broadcast fy(y, n, "y"), fvx(vx, n, "vx"), fvy(vy, n, "vy"), fr(radius, n, "radius"),
      fc(charge, n, "charge");
  DiscTable t;
  for (std::size_t i = 0; i < n; ++i)
    t.push_back(i, x.data()[i], fy[i], fvx[i], fvy[i], fr[i], fc[i]);
  return t;
}

using Circles = std::vector<std::tuple<double, double, double>>;
using Polygons = std::vector<Doubles>;

// Obstacles: circles (x, y, r) and simple polygons ((n, 2) vertices), validated as the World
// validates them (errors name the obstacle).
StaticScene scene_of(const Circles& circles, const Polygons& polygons) {
  World w;
  for (std::size_t k = 0; k < circles.size(); ++k) try {
      const auto& [x, y, r] = circles[k];
      w.add_obstacle(CircleObstacle{x, y, r, 1});
    } catch (const InvalidRow& e) {
      throw InvalidRow(e.field(), "circles[" + std::to_string(k) + "]: " + e.what());
    }
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    const Doubles& v = polygons[k];
    if (v.ndim() != 2 || v.shape(1) != 2)
      throw py::value_error("polygons[" + std::to_string(k) + "]: expected an (n, 2) array");
    PolygonObstacle p;
    for (py::ssize_t i = 0; i < v.shape(0); ++i) p.vertices.push_back({v.at(i, 0), v.at(i, 1)});
    try {
      w.add_obstacle(std::move(p));
    } catch (const InvalidRow& e) {
      throw InvalidRow(e.field(), "polygons[" + std::to_string(k) + "]: " + e.what());
    }
  }
  return StaticScene({w.circles().begin(), w.circles().end()},
                     {w.polygons().begin(), w.polygons().end()}, 1.0, ObstacleCharges::centres);
}

}  // namespace

void bind_queries(py::module_& m) {
  m.def(
      "ftc",
      [](const Doubles& x, const Doubles& y, const Doubles& vx, const Doubles& vy,
         const Doubles& radius, double horizon, const Circles& circles, const Polygons& polygons,
         const std::string& method, int threads) {
        const DiscTable t = discs_of(x, y, vx, vy, radius, scalar(1.0));
        const StaticScene scene = scene_of(circles, polygons);
        std::vector<FtcHit> hits;
        {
          py::gil_scoped_release release;
          hits = first_to_collide(t.view(), scene, horizon, method, threads);
        }
        py::array_t<int64_t> with(hits.size());
        py::array_t<double> time(hits.size());
        py::array_t<uint8_t> kind(hits.size());
        for (std::size_t i = 0; i < hits.size(); ++i) {
          kind.mutable_data()[i] = static_cast<uint8_t>(hits[i].with.kind);
          with.mutable_data()[i] =
              hits[i].with.kind == Collider::Kind::none ? -1 : int64_t{hits[i].with.row};
          time.mutable_data()[i] = hits[i].time;
        }
        return py::dict("kind"_a = kind, "row"_a = with, "time"_a = time);
      },
      "x"_a, "y"_a, "vx"_a, "vy"_a, "radius"_a, "horizon"_a, py::kw_only(), "circles"_a = Circles{},
      "polygons"_a = Polygons{}, "method"_a = "auto", "threads"_a = 1,
      "First-to-collide: for each disc moving on p + v t, the first disc or obstacle (circles "
      "(x, y, r), polygons (n, 2)) it meets within `horizon` (time in the velocities' unit). "
      "Returns {'kind': 0 none / 1 agent / 2 circle / 3 polygon, 'row': the other's row or -1, "
      "'time': inf when none}.");

  m.def(
      "field",
      [](const Doubles& x, const Doubles& y, const Doubles& charge, const std::string& kernel,
         const std::string& metric, const std::string& method, int threads) {
        const DiscTable t = discs_of(x, y, scalar(0.0), scalar(0.0), scalar(1.0), charge);
        PotentialSpec spec;
        if (kernel == "inv")
          spec.kernel = Kernel::inv;
        else if (kernel != "exp")
          throw Error(Error::Kind::input, "kernel: 'exp' or 'inv'");
        if (metric == "l2")
          spec.metric = Metric::l2;
        else if (metric == "radial")
          spec.metric = Metric::radial;
        else if (metric != "l1")
          throw Error(Error::Kind::input, "metric: 'l1', 'l2' or 'radial'");
        FieldColumns f;
        {
          py::gil_scoped_release release;
          f = potential_field(t.view(), StaticScene(), spec, method, threads);
        }
        return py::dict("potential"_a = py::array_t<double>(f.potential.size(), f.potential.data()),
                        "grad_x"_a = py::array_t<double>(f.grad_x.size(), f.grad_x.data()),
                        "grad_y"_a = py::array_t<double>(f.grad_y.size(), f.grad_y.data()));
      },
      "x"_a, "y"_a, py::kw_only(), "charge"_a = 1.0, "kernel"_a = "exp", "metric"_a = "l1",
      "method"_a = "auto", "threads"_a = 1,
      "The thesis's potential field at every point from all the others: {'potential', "
      "'grad_x', 'grad_y'} arrays.");

  m.def(
      "collisions",
      [](const Doubles& x, const Doubles& y, const Doubles& radius, const Circles& circles,
         const Polygons& polygons, const std::string& method, int threads) {
        const DiscTable t = discs_of(x, y, scalar(0.0), scalar(0.0), radius, scalar(1.0));
        const StaticScene scene = scene_of(circles, polygons);
        std::vector<uint32_t> rows;
        {
          py::gil_scoped_release release;
          rows = collision_set(t.view(), scene, method, threads);
        }
        return py::array_t<uint32_t>(rows.size(), rows.data());
      },
      "x"_a, "y"_a, "radius"_a, py::kw_only(), "circles"_a = Circles{}, "polygons"_a = Polygons{},
      "method"_a = "auto", "threads"_a = 1,
      "The rows of discs that overlap another disc or an obstacle, sorted (uint32).");

  m.def(
      "methods",
      [] {
        return py::dict("ftc"_a = ftc_methods(), "field"_a = field_methods(),
                        "collisions"_a = collision_methods());
      },
      "The access paths each query has (the first is the naive oracle).");
}

}  // namespace crowddb::python
