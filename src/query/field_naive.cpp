// Potential field by nested loop over all other discs and charged points. O(n (n + m)).
#include "query/field_kernels.hpp"
#include "query/naive_paths.hpp"

namespace crowddb {

void FieldNaive::run(const DiscView& d, const StaticScene& scene, const PotentialSpec& spec,
                     FieldColumns& out, Executor& ex, QueryStats& stats) {
  out.resize(d.n);
  const PairKernel kernel(spec);
  const auto qx = scene.point_x(), qy = scene.point_y(), qc = scene.point_charge();
  ex.for_each_chunk(d.n, 32, [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p) {
      double pot = 0, gx = 0, gy = 0;
      const double px = d.x[p], py = d.y[p], ac = spec.A * d.charge[p];
      for (std::size_t q = 0; q < d.n; ++q) {
        if (q == p) continue;
        kernel.add(px - d.x[q], py - d.y[q], ac * d.charge[q], pot, gx, gy);
      }
      for (std::size_t q = 0; q < qx.size(); ++q)
        kernel.add(px - qx[q], py - qy[q], ac * qc[q], pot, gx, gy);
      out.potential[p] = pot;
      out.grad_x[p] = gx;
      out.grad_y[p] = gy;
    }
  });
  stats.rows += d.n;
  stats.pair_tests += d.n * (d.n ? d.n - 1 : 0) + d.n * qx.size();
}

}  // namespace crowddb
