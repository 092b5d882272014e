// The naive neighbour and obstacle-feature queries: a scan of every row (every feature) per
// query. The oracles of the indexed methods in src/index/neighbour_grid.cpp and feature_grid.cpp.
#include <algorithm>

#include "query/naive_paths.hpp"

namespace crowddb {
namespace {

constexpr std::size_t kGrain = 64;

}  // namespace

void NeighbourNaive::run(const DiscView& d, std::span<const uint32_t> queries, double range,
                         uint32_t k, NeighbourLists& out, Executor& ex, QueryStats& stats) {
  const std::size_t q = queries.empty() ? d.n : queries.size();
  const double r2 = range * range;
  const std::size_t chunks = (q + kGrain - 1) / kGrain;
  ListChunks lists;
  lists.reset(chunks);
  std::vector<uint64_t> tests(chunks, 0);
  ex.for_each_chunk(q, kGrain, [&](std::size_t b, std::size_t e) {
    const std::size_t c = b / kGrain;
    NearestK best;
    for (std::size_t qi = b; qi < e; ++qi) {
      const std::size_t i = queries.empty() ? qi : queries[qi];
      best.reset(k);
      for (std::size_t j = 0; j < d.n; ++j) {
        if (j == i) continue;
        const double dx = d.x[j] - d.x[i], dy = d.y[j] - d.y[i];
        const double d2 = dx * dx + dy * dy;
        if (d2 < r2) best.offer(static_cast<uint32_t>(j), d.id[j], d2);
      }
      best.finish();
      tests[c] += d.n;
      lists.counts[c].push_back(static_cast<uint32_t>(best.size()));
      lists.items[c].insert(lists.items[c].end(), best.rows().begin(), best.rows().end());
      if (out.with_dist2)
        lists.d2[c].insert(lists.d2[c].end(), best.dist2().begin(), best.dist2().end());
    }
  });
  lists.gather(out, &NeighbourLists::row, &ex);
  stats.rows += q;
  for (uint64_t t : tests) stats.pair_tests += t;
}

void FeatureNaive::run(const DiscView& p, std::span<const double> reach, const StaticScene& scene,
                       FeatureLists& out, Executor& ex, QueryStats& stats) {
  const std::size_t features = scene.feature_count();
  const std::size_t chunks = (p.n + kGrain - 1) / kGrain;
  ListChunks lists;
  lists.reset(chunks);
  ex.for_each_chunk(p.n, kGrain, [&](std::size_t b, std::size_t e) {
    const std::size_t c = b / kGrain;
    for (std::size_t i = b; i < e; ++i) {
      const double r2 = reach[i] * reach[i];
      uint32_t count = 0;
      for (std::size_t f = 0; f < features; ++f) {
        const double d2 = feature_dist2(scene, f, p.x[i], p.y[i]);
        if (d2 < r2) {
          lists.items[c].push_back(static_cast<uint32_t>(f));
          lists.d2[c].push_back(d2);
          ++count;
        }
      }
      lists.counts[c].push_back(count);
    }
  });
  lists.gather(out, &FeatureLists::feature, &ex);
  stats.rows += p.n;
  stats.pair_tests += p.n * features;
}

}  // namespace crowddb
