#include "index/collisions_sweep.hpp"

#include <algorithm>
#include <cmath>

#include "query/naive_paths.hpp"
#include "util/stopwatch.hpp"
#include "world/geometry.hpp"

namespace crowddb::index {
namespace {

constexpr int kKeyBits = 24;  // left edges quantised to 2^24 buckets over their span

}  // namespace

void CollisionSweep::run(const DiscView& d, const StaticScene& scene, CollisionPairs& out,
                         Executor& ex, QueryStats& stats) {
  out.clear();
  const std::size_t n = d.n;
  if (n == 0) return;
  const Frame frame = Frame::of(d);
  if (!frame.finite) {
    CollisionNaive().run(d, scene, out, ex, stats);
    return;
  }
  Stopwatch sw;
  // Boxes in frame coordinates, grown by the rounding margins (Frame::reach).
  double xlo_min = INFINITY, xlo_max = -INFINITY, ylo_min = INFINITY, yhi_max = -INFINITY,
         reach_sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double reach = frame.reach(d.radius[i]);
    const double u = d.x[i] - frame.x0, v = d.y[i] - frame.y0;
    xlo_min = std::min(xlo_min, u - reach);
    xlo_max = std::max(xlo_max, u - reach);
    ylo_min = std::min(ylo_min, v - reach);
    yhi_max = std::max(yhi_max, v + reach);
    reach_sum += reach;
  }
  // Sort order: quantised left edge in the high word, the row in the low word. The quantum is
  // kept well above the rounding of the edges, which the expiry bound below relies on.
  const double quantum =
      std::max((xlo_max - xlo_min) * 0x1p-24, (std::abs(xlo_min) + std::abs(xlo_max)) * 0x1p-40);
  auto bucket = [&](double xlo) -> uint64_t {
    if (!(quantum > 0)) return 0;
    const double q = std::floor((xlo - xlo_min) / quantum);
    return q <= 0 ? 0 : (q >= 0x1p24 ? (uint64_t{1} << kKeyBits) : static_cast<uint64_t>(q));
  };
  order_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    order_[i] = bucket(d.x[i] - frame.x0 - frame.reach(d.radius[i])) << 32 | i;
  radix_sort(order_, radix_, 32, 32 + kKeyBits + 1);

  // Slabs: height twice the mean reach, at most max(1024, 2n) of them.
  const double span_y = yhi_max - ylo_min;
  const double cap = static_cast<double>(std::max<std::size_t>(1024, 2 * n));
  double hs = std::max(2 * reach_sum / static_cast<double>(n), span_y / cap);
  if (!(hs > 0)) hs = 1;
  const auto slabs = static_cast<std::size_t>(std::min(cap, std::floor(span_y / hs) + 1));
  auto slab_of = [&](double v) -> uint32_t {
    const double s = std::floor((v - ylo_min) / hs);
    if (!(s > 0)) return 0;
    return s >= static_cast<double>(slabs - 1) ? static_cast<uint32_t>(slabs - 1)
                                               : static_cast<uint32_t>(s);
  };
  if (slabs_.size() < slabs) slabs_.resize(slabs);
  for (std::size_t s = 0; s < slabs; ++s) slabs_[s].clear();

  // Rows packed in row order (a sequential pass), so the sweep reads one cache line per disc.
  packed_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    packed_[i] = {d.x[i], d.y[i], d.radius[i], static_cast<uint32_t>(i)};
  stats.build_seconds += sw.seconds();
  sw.restart();

  uint64_t tests = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (k + 16 < n) __builtin_prefetch(&packed_[order_[k + 16] & 0xffffffffu]);
    const uint64_t key = order_[k] >> 32;
    const Disc& a = packed_[order_[k] & 0xffffffffu];
    // Every box still to come lies in this bucket or later; one quantum of slack for rounding.
    const double expire = key == 0 ? -INFINITY : xlo_min + (static_cast<double>(key) - 1) * quantum;
    const double reach = frame.reach(a.r);
    const double u = a.x - frame.x0, v = a.y - frame.y0;
    const double xlo = u - reach;
    const uint32_t s0 = slab_of(v - reach), s1 = slab_of(v + reach);
    for (uint32_t s = s0; s <= s1; ++s) {
      std::vector<Active>& slab = slabs_[s];
      std::size_t keep = 0;
      for (std::size_t e = 0; e < slab.size(); ++e) {
        const Active& b = slab[e];
        if (b.xhi < expire) continue;  // the sweep line has passed it for good
        if (keep != e) slab[keep] = b;
        ++keep;
        // Boxes meet in y iff the centres are at most the two reaches apart (the reaches carry
        // the rounding margins, so this never drops a pair the exact test accepts).
        if (b.xhi < xlo || std::abs(b.y - a.y) > b.reach + reach || std::max(b.slab0, s0) != s)
          continue;
        ++tests;
        if (discs_overlap(b.x - a.x, b.y - a.y, b.r + a.r))
          out.agents.push_back(ordered(b.row, a.row));
      }
      slab.resize(keep);
    }
    const Active me{u + reach, reach, a.x, a.y, a.r, a.row, s0};
    for (uint32_t s = s0; s <= s1; ++s) slabs_[s].push_back(me);
  }
  finish_pairs(out.agents);
  if (!scene.empty()) {
    obstacles_.build(scene, frame);
    obstacles_.overlaps(d, 0, d.n, out.obstacles, tests);
  }
  stats.pair_tests += tests;
  stats.rows += n;
  stats.query_seconds += sw.seconds();
}

}  // namespace crowddb::index
