// The naive neighbour and obstacle-feature queries: a scan of every row (every feature) per
// query. The oracles of the indexed methods in src/index/neighbour_grid.cpp and feature_grid.cpp.
#include <algorithm>
#include <cmath>
#include <cstdint>

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

// ---------------------------------------------------------- NearestK, unbounded lists

void NearestK::sort_unbounded() {
  if (rows_.size() <= kRankSort && rank_sort()) return;
  order_.resize(rows_.size());
  for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<uint32_t>(i);
  std::sort(order_.begin(), order_.end(),
            [&](uint32_t a, uint32_t b) { return better(d2_[a], ids_[a], d2_[b], ids_[b]); });
  scratch_rows_.resize(order_.size());
  scratch_d2_.resize(order_.size());
  for (std::size_t i = 0; i < order_.size(); ++i) {
    scratch_rows_[i] = rows_[order_[i]];
    scratch_d2_[i] = d2_[order_[i]];
  }
  rows_.swap(scratch_rows_);
  d2_.swap(scratch_d2_);
}

bool NearestK::rank_sort() {
  const std::size_t m = rows_.size();
  alignas(16) double dist[kRankSort];
  std::copy_n(d2_.data(), m, dist);
  if (m % 2) dist[m] = INFINITY;  // whole vectors; never nearer
  uint32_t rows[kRankSort];
  double d2s[kRankSort];
  const uint64_t all = m == 64 ? ~uint64_t{0} : (uint64_t{1} << m) - 1;
  for (const bool by_id : {false, true}) {
    uint64_t filled = 0;
    for (std::size_t a = 0; a < m; ++a) {
      const double da = dist[a];
      std::size_t rank = 0;
      if (!by_id) {
        rank = count_nearer(dist, static_cast<uint32_t>(m), da);
      } else {  // equal distances share a rank above: the ids settle them
        const uint64_t ia = ids_[a];
        for (std::size_t b = 0; b < m; ++b)
          rank += static_cast<std::size_t>(int{dist[b] < da} |
                                           (int{dist[b] == da} & int{ids_[b] < ia}));
      }
      rows[rank] = rows_[a];
      d2s[rank] = da;
      filled |= uint64_t{1} << rank;
    }
    if (filled == all) {
      std::copy_n(rows, m, rows_.data());
      std::copy_n(d2s, m, d2_.data());
      return true;
    }
  }
  return false;
}

}  // namespace crowddb
