// Potential field by nested loop over all other discs and charged points. O(n (n + m)).
#include "crowddb/error.hpp"
#include "query/field_kernels.hpp"
#include "query/naive_paths.hpp"

namespace crowddb {
namespace {

// Sum at (px, py) over the discs other than row `skip` and the scene's charged points of
// c_q K(d) (times `ac`), with the analytic gradient.
struct Sum {
  double pot = 0, gx = 0, gy = 0;
};
Sum sum_at(double px, double py, double ac, std::size_t skip, const DiscView& d,
           const StaticScene& scene, const PairKernel& kernel) {
  Sum s;
  const auto qx = scene.point_x(), qy = scene.point_y(), qc = scene.point_charge();
  for (std::size_t q = 0; q < d.n; ++q) {
    if (q == skip) continue;
    kernel.add(px - d.x[q], py - d.y[q], ac * d.charge[q], s.pot, s.gx, s.gy);
  }
  for (std::size_t q = 0; q < qx.size(); ++q)
    kernel.add(px - qx[q], py - qy[q], ac * qc[q], s.pot, s.gx, s.gy);
  return s;
}

constexpr std::size_t kNone = static_cast<std::size_t>(-1);

// Potential and gradient (analytic, or forward differences when spec.finite_difference) at one
// point; `skip` is the disc the probe is (kNone for a free probe).
void evaluate(double px, double py, double ac, std::size_t skip, const DiscView& d,
              const StaticScene& scene, const PotentialSpec& spec, const PairKernel& kernel,
              double& pot, double& gx, double& gy) {
  const Sum s = sum_at(px, py, ac, skip, d, scene, kernel);
  pot = s.pot;
  if (!spec.finite_difference) {
    gx = s.gx;
    gy = s.gy;
    return;
  }
  const double h = spec.fd_step;
  gx = (sum_at(px + h, py, ac, skip, d, scene, kernel).pot - s.pot) / h;
  gy = (sum_at(px, py + h, ac, skip, d, scene, kernel).pot - s.pot) / h;
}

}  // namespace

void FieldPath::probe(std::span<const Vec2>, const DiscView&, const StaticScene&,
                      const PotentialSpec&, FieldColumns&, Executor&, QueryStats&) {
  throw Error(Error::Kind::usage,
              "this field method cannot evaluate the field at arbitrary points");
}

void FieldNaive::run(const DiscView& d, const StaticScene& scene, const PotentialSpec& spec,
                     FieldColumns& out, Executor& ex, QueryStats& stats) {
  out.resize(d.n);
  const PairKernel kernel(spec);
  ex.for_each_chunk(d.n, 32, [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p)
      evaluate(d.x[p], d.y[p], spec.A * d.charge[p], p, d, scene, spec, kernel, out.potential[p],
               out.grad_x[p], out.grad_y[p]);
  });
  const std::size_t evals = spec.finite_difference ? 3 : 1;
  stats.rows += d.n;
  stats.pair_tests += evals * (d.n * (d.n ? d.n - 1 : 0) + d.n * scene.point_count());
}

void FieldNaive::probe(std::span<const Vec2> points, const DiscView& sources,
                       const StaticScene& scene, const PotentialSpec& spec, FieldColumns& out,
                       Executor& ex, QueryStats& stats) {
  out.resize(points.size());
  const PairKernel kernel(spec);
  ex.for_each_chunk(points.size(), 32, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      evaluate(points[i].x, points[i].y, spec.A, kNone, sources, scene, spec, kernel,
               out.potential[i], out.grad_x[i], out.grad_y[i]);
  });
  const std::size_t evals = spec.finite_difference ? 3 : 1;
  stats.rows += points.size();
  stats.pair_tests += evals * points.size() * (sources.n + scene.point_count());
}

}  // namespace crowddb
