#include "index/neighbour_grid.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

#include "index/neighbour_lanes.hpp"
#include "index/row_buckets.hpp"
#include "query/naive_paths.hpp"
#include "util/cpu.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::index {
namespace {

constexpr std::size_t kGrain = 64;
constexpr uint32_t kBatch = 32;  // candidates filtered at once before any is offered
// Cell side for k nearest: about kBlockFill * k discs per 3 x 3 block at the table's mean density.
// Measured on the RVO2-style airport (2 * 10^4 agents, k = 10, 100 ticks; the neighbour stage's
// ms per tick, min of 5 interleaved runs): 2 -> 9.5, 4 -> 9.0, 6 -> 8.8, 8 -> 8.6 (2 without
// the hints: 11.3). With the hints most queries gather the rows of cells meeting a small square
// (then its disc's chords: 2026-11-29), and fewer, longer runs of cells beat fewer candidates:
// the filter is branch-free, each run is not. 6 rather than 8: the two
// are within the host's noise, and the larger cells also serve the queries without hints (the
// first tick, rows new to a query, a k above NearestK::kInline), unmeasured.
constexpr double kBlockFill = 6;
constexpr double kChordReach = 1.5;  // hinted bounds up to this many cells: gathered and ranked
// A row without hints: the bound's disc is expected to hold this many times k others at the
// density around the row (a Poisson count of mean 2 k falls below k about once in 200 at k = 10).
constexpr double kDensityFill = 2;
constexpr uint32_t kNoRow = ~0u;  // pads the hints (no table has 2^32 rows)
// Four rows and their comparison masks (GCC's and clang's vector extensions; SSE2 on x86-64).
typedef uint32_t V4u __attribute__((vector_size(16)));
constexpr std::size_t kCopyGrain = 4096;   // rows per chunk of the lists' compaction
constexpr std::size_t kBuildGrain = 8192;  // rows per chunk of the grid's build

}  // namespace

#if (CROWDDB_NEIGHBOUR_AVX2 && !defined(__AVX2__)) || \
    (CROWDDB_NEIGHBOUR_AVX2_NATIVE && defined(__AVX2__))
#define CROWDDB_NEIGHBOUR_DISPATCH 1
// neighbour_lanes_avx2.cpp: whole vectors of four (see kNeighbourPad).
uint32_t gather_within_avx2(const double* X, const double* Y, uint32_t lo, uint32_t hi, double px,
                            double py, double bound, uint32_t self_at, uint32_t* at, double* dist);
void count_all_nearer_avx2(const double* dist, uint32_t m, uint32_t* before);
#endif

bool gather_lanes_avx2() {
#if CROWDDB_NEIGHBOUR_DISPATCH
  return cpu_has_avx2();
#else
  return false;
#endif
}

uint32_t gather_within_lanes(const double* X, const double* Y, uint32_t lo, uint32_t hi, double px,
                             double py, double bound, uint32_t self_at, uint32_t* at, double* dist,
                             GatherLanes lanes) {
#if CROWDDB_NEIGHBOUR_DISPATCH
  if (lanes == GatherLanes::widest && gather_lanes_avx2())
    return gather_within_avx2(X, Y, lo, hi, px, py, bound, self_at, at, dist);
#else
  (void)lanes;
#endif
  return gather_within(X, Y, lo, hi, px, py, bound, self_at, at, dist);
}

void count_all_nearer_lanes(const double* dist, uint32_t m, uint32_t* before, GatherLanes lanes) {
#if CROWDDB_NEIGHBOUR_DISPATCH
  if (lanes == GatherLanes::widest && gather_lanes_avx2())
    return count_all_nearer_avx2(dist, m, before);
#else
  (void)lanes;
#endif
  // (count_nearer: two at a time in SSE2's lanes, dist[m] padded)
  for (uint32_t u = 0; u < m; ++u) before[u] = count_nearer(dist, m, dist[u]);
}

// Monotone in x (a product by a positive constant, then truncation, which is the floor for c >= 0;
// below 0 clamps to 0): all the probes need, with the slack that covers rounding. A division here
// was a quarter of the probes' time.
inline int64_t NeighbourGrid::col(double x) const {
  return cell_by_product(x - x0_, inv_cell_, W_);
}

inline int64_t NeighbourGrid::row(double y) const {
  return cell_by_product(y - y0_, inv_cell_, H_);
}

// Row cy's cells [cx0, cx1] meeting the disc of squared radius `bound` round (px, py), widened
// by `slack` against rounding; false when the row's band misses the disc.
inline bool NeighbourGrid::chord_cells(double px, double py, double bound, double slack, int64_t cy,
                                       int64_t& cx0, int64_t& cx1) const {
  const double ly = y0_ + static_cast<double>(cy) * cell_;
  const double ddy = std::max({ly - py - slack, py - (ly + cell_) - slack, 0.0});
  const double room = bound - ddy * ddy;
  if (room < 0) return false;
  const double w = std::sqrt(room) + slack;
  cx0 = col(px - w);
  cx1 = col(px + w);
  return true;
}

// A counting sort (index/row_buckets.hpp): the bounding box, each row's cell and the copies in
// cell order in chunks on every thread, the placement in one pass (the layout of one thread).
void NeighbourGrid::build(const DiscView& d, double range, uint32_t k, Executor& ex) {
  const auto [xmin, ymin, xmax, ymax] = bounding_box({d.x, d.n}, {d.y, d.n}, ex);
  const double w = std::max(xmax - xmin, 1e-9), h = std::max(ymax - ymin, 1e-9);
  const auto n = static_cast<double>(std::max<std::size_t>(d.n, 1));
  const double density = n / (w * h);
  double cell = k ? std::sqrt(kBlockFill * k / (9.0 * density)) : range / 2;
  cell = std::min(cell, range);
  cell = std::max(cell, std::sqrt(w * h / (4 * n)));  // at most ~4 cells per disc
  if (!(cell > 0) || !std::isfinite(cell)) cell = std::max(w, h);
  x0_ = xmin;
  y0_ = ymin;
  cell_ = cell;
  inv_cell_ = 1 / cell;
  W_ = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(w / cell)) + 1);
  H_ = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(h / cell)) + 1);
  // Rounding of the cell coordinates (x0 + c * cell) is relative to the grid's origin and
  // extent, whatever the query's own coordinates: part of every cell test's slack.
  slack_ = 1e-9 * (cell_ + std::abs(x0_) + std::abs(y0_) + static_cast<double>(W_ + H_) * cell_);
  const auto cells = static_cast<std::size_t>(W_ * H_);
  cell_of_.resize(d.n);
  ex.for_each_chunk(d.n, kBuildGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) cell_of_[i] = row(d.y[i]) * W_ + col(d.x[i]);
  });
  bucket_rows(cell_of_, cells, start_, rows_);
  // (+ 3: the gathering's lanes read whole vectors past a run's end, kNeighbourPad)
  x_.resize(d.n + kNeighbourPad);
  y_.resize(d.n + kNeighbourPad);
  id_.resize(d.n);
  ex.for_each_chunk(d.n, kBuildGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t a = b; a < e; ++a) {
      const uint32_t i = rows_[a];
      x_[a] = d.x[i];
      y_[a] = d.y[i];
      id_[a] = d.id[i];
    }
  });
}

void NeighbourGrid::rows_permuted(std::span<const uint32_t> order, Executor* ex) {
  const uint32_t k = hint_k_;
  // A subset's hints (the stalemate stage's rows looked at, a few in a hundred) are dropped, not
  // carried: carrying them takes lists in the new order for every row of the table (spare lists,
  // counts and renaming: 32 MB kept at 10^6 rows and k = 6) for one call's worth of hints per
  // reorder. The next call searches without hints: the same answer.
  if (k == 0 || hints_of_subset_) {
    hint_k_ = 0;
    return;
  }
  // Rows removed or added since the last call (arrivals, sources) do not stop this: the hints of
  // the rows they touched name the wrong discs, which costs time, never exactness.
  const std::size_t n = order.size(), last_n = slot_count_.size();
  // Hints must be distinct rows (each is offered once): only a permutation keeps them so.
  constexpr uint32_t kUnset = ~0u;
  std::vector<uint32_t>& new_of = new_of_;
  new_of.assign(n, kUnset);
  for (std::size_t r = 0; r < n; ++r) {
    if (order[r] >= n || new_of[order[r]] != kUnset) {
      hint_k_ = 0;
      return;
    }
    new_of[order[r]] = static_cast<uint32_t>(r);
  }
  std::vector<uint32_t>& count = spare_count_;
  std::vector<uint32_t>& rows = spare_row_;
  count.assign(n, 0);
  rows.resize(n * k);  // (entries past a row's count are never read)
  const auto move = [&](std::size_t b, std::size_t end) {
    // (Locals: the stores into `rows` could alias the vectors' elements read here.)
    const uint32_t* const last_count = slot_count_.data();
    const uint32_t* const last_row = slot_row_.data();
    const uint32_t* const renamed = new_of.data();
    uint32_t* const out = rows.data();
    for (std::size_t r = b; r < end; ++r) {
      const std::size_t old = order[r];
      if (old >= last_n) continue;
      uint32_t c = 0;
      for (uint32_t u = 0, m = last_count[old]; u < m; ++u) {
        const uint32_t e = last_row[old * k + u];
        if (e < n) out[r * k + c++] = renamed[e];
      }
      count[r] = c;
    }
  };
  if (ex)
    ex->for_each_chunk(n, kCopyGrain, move);
  else
    move(0, n);
  slot_count_.swap(count);
  slot_row_.swap(rows);
}

void NeighbourGrid::run(const DiscView& d, std::span<const uint32_t> queries, double range,
                        uint32_t k, NeighbourLists& out, Executor& ex, QueryStats& stats) {
  Stopwatch sw;
  build(d, range, k, ex);
  stats.build_seconds += sw.seconds();
  sw.restart();
  const std::size_t q = queries.empty() ? d.n : queries.size();
  const double r2 = range * range;
  const std::size_t chunks = (q + kGrain - 1) / kGrain;
  ListChunks lists;
  lists.reset(chunks);
  std::vector<uint64_t> tests(chunks, 0), rings(chunks, 0);
  // Raw pointers into the grid, hoisted: writes to the per-query lists could otherwise alias
  // them and force a reload of every vector's data pointer per candidate.
  const double* const X = x_.data();
  const double* const Y = y_.data();
  const uint32_t* const R = rows_.data();
  const uint64_t* const I = id_.data();
  const uint32_t* const S = start_.data();
  // Every row with a bounded k: walk the rows in order and write each list into its row's own
  // slot of k; the slots are compacted into the CSR afterwards. The table keeps its rows in
  // space-filling-curve order, so neighbouring queries still read the same cells, and the row's
  // own columns and hints are read in memory order (walking in the grid's cell order instead,
  // row-major, jumped through them: the stage 376 -> 369 ms per 100 ticks at 2 * 10^4 agents,
  // one thread, A B B A). Otherwise: query order, lists gathered per chunk.
  const bool spatial = queries.empty() && k > 0;
  // Last call's lists seed this call's (see the header): only when they were made with the same
  // k. A call for a subset of rows (the stalemate stage's: mostly the same rows tick after tick)
  // keeps its rows' lists in the slots too; the other rows' slots keep older lists, which are
  // still distinct rows.
  // The subset must name each row once (ascending, as the callers give it): two queries of one
  // row would write its slot while reading it.
  const bool hintable = k > 0 && k <= NearestK::kInline &&
                        std::adjacent_find(queries.begin(), queries.end(),
                                           std::greater_equal<uint32_t>()) == queries.end();
  const bool hints = hintable && k == hint_k_;
  // Each row's list in its slot of k: every row's (spatial, compacted into the output after), or
  // the asked rows' kept as hints.
  const bool slots = spatial || hintable;
  if (slots) {
    if (!hints) slot_count_.assign(d.n, 0);
    slot_count_.resize(d.n, 0);  // rows new since the last call have no hints
    slot_row_.resize(d.n * k);
  }
  // The distances go straight into the output's slots (a second array of n k doubles was the
  // largest item of memory at 10^6 agents), compacted in place afterwards.
  if (spatial && out.with_dist2) out.dist2.resize(d.n * k);
  hint_k_ = hintable ? k : 0;
  hints_of_subset_ = !queries.empty();
  if (spatial) {  // each row's place in the grid (the ranked search skips the query's own)
    at_.resize(d.n);
    uint32_t* const at = at_.data();
    ex.for_each_chunk(d.n, kCopyGrain, [&](std::size_t b, std::size_t e) {
      for (std::size_t a = b; a < e; ++a) at[R[a]] = static_cast<uint32_t>(a);
    });
  }
  const uint32_t* const At = at_.data();
  const GatherLanes lanes = gather_lanes_avx2() ? GatherLanes::widest : GatherLanes::scalar;
  ex.for_each_chunk(q, kGrain, [&](std::size_t b, std::size_t e) {
    const std::size_t c = b / kGrain;
    // The chunk's counters and lists are its own until the end (util/executor.hpp).
    uint64_t tests_c = 0, rings_c = 0;
    ListChunks::Chunk mine;
    NearestK best;
    if (!spatial) {  // room for the lists at the last call's mean length (else grown by doubling)
      const auto rows = static_cast<double>(e - b);
      const auto entries = static_cast<std::size_t>(rows * (list_mean_ * 1.25 + 1));
      mine.counts.reserve(e - b);
      mine.items.reserve(entries);
      if (out.with_dist2) mine.d2.reserve(entries);
      if (k == 0 || k > NearestK::kInline)
        best.reserve(k ? k : static_cast<std::size_t>(list_mean_ * 2) + 16);
    }
    // Every disc other than `self` (at `self_at` in the grid) within `bound` (< the range) of
    // (px, py), from the cells of the bound's square, ranked by (distance, id): the best k are the
    // answer when at least k were found, as the selection would give them (the same squared
    // distances). The rank of each is the number of those that precede it, counted without branches
    // (which of two is nearer is a coin toss to the predictor, and inserting them one by one
    // mispredicted most of it); ids settle equal distances. False (nothing written) when more were
    // found than kCollect or fewer than k, or the ranks do not fill 0..k-1 (ids not distinct): then
    // the row's search goes the usual way.
    const auto ranked = [&](std::size_t self, uint32_t self_at, double px, double py, double bound,
                            double slack, uint64_t& tested) {
      // Room for what the cells hold where the crowd is several times denser than the mean the
      // cells are sized for (round a goal late in a run): with 64, those rows fell back to the
      // one-by-one selection (airport-20k over 1,000 ticks, one thread: the stage 3,693 ->
      // 3,391 ms with 256; 1,024 no better). Only the ones within the bound are ranked.
      constexpr uint32_t kCollect = 256;
      // (+ kNeighbourPad: the lanes write and read whole vectors)
      uint32_t at[kCollect + kNeighbourPad];
      double dist[kCollect + kNeighbourPad];
      uint32_t m = 0;
      // The square's rows of cells, each as one run: the chords of the disc (a square root per row
      // of cells) left out 6 % of the candidates and cost more than those (airport-20k, one
      // thread: the stage 346 -> 287 ms per 100 ticks, min of 10).
      const double reach = std::sqrt(bound) + slack;
      const int64_t cy0 = row(py - reach), cy1 = row(py + reach);
      const auto cx0 = static_cast<std::size_t>(col(px - reach));
      const auto cx1 = static_cast<std::size_t>(col(px + reach));
      for (int64_t cy = cy0; cy <= cy1; ++cy) {
        const auto base = static_cast<std::size_t>(cy * W_);
        const uint32_t lo = S[base + cx0];
        const uint32_t hi = S[base + cx1 + 1];
        if (hi - lo > kCollect - m) return false;
        tested += hi - lo;
        // (Within the range: the bound is a hint's distance, which is.)
        m += gather_within_lanes(X, Y, lo, hi, px, py, bound, self_at, at + m, dist + m, lanes);
      }
      if (self_at == kNoRow)  // (a subset's query: its place was not looked up) drop its own
        for (uint32_t u = 0; u < m; ++u)
          if (R[at[u]] == self) {
            at[u] = at[--m];
            dist[u] = dist[m];
            break;
          }
      if (m < k) return false;
      for (uint32_t u = m; u < m + kNeighbourPad; ++u) dist[u] = INFINITY;  // never nearer
      // Each one's rank by distance: how many are nearer.
      uint32_t nearer[kCollect];
      count_all_nearer_lanes(dist, m, nearer, lanes);
      // Ranks by distance alone, each written to its place (past k: a spare slot); equal
      // distances share a rank, so among the first k they show as a place written twice or
      // left empty, and then the ids rank them.
      uint32_t place_row[NearestK::kInline + 1];
      double place_d2[NearestK::kInline + 1];
      const auto place = [&](bool by_id) {
        uint64_t filled = 0;
        uint32_t writes = 0;
        for (uint32_t u = 0; u < m; ++u) {
          const double du = dist[u];
          uint32_t before = 0;
          if (!by_id) {
            before = nearer[u];
          } else {
            const uint64_t id = I[at[u]];
            for (uint32_t f = 0; f < m; ++f)
              before += static_cast<uint32_t>((dist[f] < du) | ((dist[f] == du) & (I[at[f]] < id)));
          }
          const uint32_t slot = std::min(before, k);
          filled |= uint64_t{1} << slot;
          writes += static_cast<uint32_t>(before < k);
          place_row[slot] = R[at[u]];
          place_d2[slot] = du;
        }
        return writes == k &&
               (filled & ((uint64_t{2} << (k - 1)) - 1)) == (uint64_t{2} << (k - 1)) - 1;
      };
      if (!place(false) && !place(true)) return false;
      std::copy_n(place_row, k, slot_row_.data() + self * k);
      slot_count_[self] = k;
      if (spatial) {
        if (out.with_dist2) std::copy_n(place_d2, k, out.dist2.data() + self * k);
      } else {
        mine.counts.push_back(k);
        mine.items.insert(mine.items.end(), place_row, place_row + k);
        if (out.with_dist2) mine.d2.insert(mine.d2.end(), place_d2, place_d2 + k);
      }
      return true;
    };
    for (std::size_t qi = b; qi < e; ++qi) {
      const std::size_t i = queries.empty() ? qi : queries[qi];
      const double px = d.x[i], py = d.y[i];
      best.reset(k);
      // The hints: this row's list of the last call, offered first and in their old order (the
      // list hardly changes between ticks, so they arrive nearly sorted and fill it with a tight
      // bound). Any rows would do: the answer is the best k of all candidates however they come,
      // so a stale hint (rows reordered, removed) costs time, never exactness. The scans below
      // skip the hinted rows, so that no candidate is offered twice.
      uint32_t hint[NearestK::kInline + 3];  // padded to whole vectors of 4 with kNoRow
      uint32_t nh = 0;
      const double slack = slack_ + 1e-9 * (std::abs(px) + std::abs(py));
      // (A list of fewer than k last time: too few within range to bound anything, and the
      // scans then look at every cell within range anyway. So no hints, and nothing to skip.)
      if (hints && slot_count_[i] == k) {
        const uint32_t* const last = slot_row_.data() + i * k;
        const uint32_t count = k;
        double hint_d2[NearestK::kInline];
        double hint_bound = 0;
        for (uint32_t u = 0; u < count; ++u) {
          const uint32_t j = last[u];
          if (j >= d.n || j == i) continue;
          const double dx = d.x[j] - px, dy = d.y[j] - py;
          const double d2 = dx * dx + dy * dy;
          if (!(d2 < r2)) continue;  // the scans' range test
          hint[nh] = j;
          hint_d2[nh++] = d2;
          hint_bound = std::max(hint_bound, d2);
        }
        tests_c += count;
        // k hints within range bound the answer: its k-th distance is at most theirs. Every
        // disc within that bound (the hints among them) is gathered from the cells of the
        // bound's square and ranked at once (below); otherwise the hints are offered to the
        // selection first.
        if (nh == k && hint_bound < kChordReach * kChordReach * cell_ * cell_ &&
            ranked(i, spatial ? At[i] : kNoRow, px, py, hint_bound, slack, tests_c)) {
          ++rings_c;
          continue;
        }
        for (uint32_t u = 0; u < nh; ++u) best.offer(hint[u], d.id[hint[u]], hint_d2[u]);
        for (uint32_t u = nh; u < ((nh + 3) & ~3u); ++u) hint[u] = kNoRow;
      } else if (hintable) {
        // No full list of the last call (the first tick, rows new to the query, a short list): a
        // bound from the
        // density of the 3 x 3 block around the row instead, a disc expected to hold kDensityFill
        // times k others, gathered and ranked the same way. Exact whatever the bound: when fewer
        // than k lie within it, nothing is written and the search below goes the usual way.
        const int64_t cx = col(px), cy = row(py);
        const int64_t bx0 = std::max<int64_t>(0, cx - 1), bx1 = std::min(W_ - 1, cx + 1);
        const int64_t by0 = std::max<int64_t>(0, cy - 1), by1 = std::min(H_ - 1, cy + 1);
        uint32_t around = 0;  // the row itself among them
        for (int64_t y = by0; y <= by1; ++y) {
          const auto base = static_cast<std::size_t>(y * W_);
          around +=
              S[base + static_cast<std::size_t>(bx1) + 1] - S[base + static_cast<std::size_t>(bx0)];
        }
        if (around > k) {
          const auto cells = static_cast<double>((bx1 - bx0 + 1) * (by1 - by0 + 1));
          const double bound = kDensityFill * k * cells * cell_ * cell_ /
                               (std::numbers::pi * static_cast<double>(around - 1));
          if (bound < r2 && bound < kChordReach * kChordReach * cell_ * cell_ &&
              ranked(i, spatial ? At[i] : kNoRow, px, py, bound, slack, tests_c)) {
            ++rings_c;
            continue;
          }
        }
      }
      auto scan = [&](int64_t cy, int64_t cx0, int64_t cx1) {
        const auto base = static_cast<std::size_t>(cy * W_);
        const uint32_t lo = S[base + static_cast<std::size_t>(cx0)];
        const uint32_t hi = S[base + static_cast<std::size_t>(cx1) + 1];
        // The captured values are copied into locals: offer() stores doubles, which could alias
        // them and force a reload of each one per candidate.
        const double x = px, y = py, rr = r2;
        const double* const xs = X;
        const double* const ys = Y;
        const uint32_t* const rs = R;
        const uint64_t* const is = I;
        const std::size_t self = i;
        if (k == 0) {  // every candidate within range: nothing to filter by
          for (uint32_t a = lo; a < hi; ++a) {
            const double dx = xs[a] - x, dy = ys[a] - y;
            const double d2 = dx * dx + dy * dy;
            if (d2 < rr && rs[a] != self) best.offer(rs[a], is[a], d2);
          }
          tests_c += hi - lo;
          return;
        }
        double limit = std::min(rr, best.bound());
        // In batches: the candidates within the bound are picked without a branch (whether one
        // passes is a coin toss to the predictor), then offered one by one. Candidates beyond
        // the k-th best (ties may still win on id) never reach offer().
        for (uint32_t a0 = lo; a0 < hi; a0 += kBatch) {
          const uint32_t a1 = std::min(hi, a0 + kBatch);
          uint32_t pass[kBatch];
          double pass_d2[kBatch];
          uint32_t m = 0;
          for (uint32_t a = a0; a < a1; ++a) {
            const double dx = xs[a] - x, dy = ys[a] - y;
            const double d2 = dx * dx + dy * dy;
            pass[m] = a;
            pass_d2[m] = d2;
            m += static_cast<uint32_t>((d2 < rr) & (d2 <= limit));
          }
          for (uint32_t u = 0; u < m; ++u) {
            const uint32_t a = pass[u];
            const uint32_t r = rs[a];
            V4u seen = {r == self, 0, 0, 0};
            const V4u want = {r, r, r, r};
            for (uint32_t h = 0; h < nh; h += 4) {
              V4u v;
              __builtin_memcpy(&v, hint + h, sizeof v);
              seen |= v == want;
            }
            if ((seen[0] | seen[1] | seen[2] | seen[3]) || pass_d2[u] > limit) continue;
            best.offer(r, is[a], pass_d2[u]);
            limit = std::min(rr, best.bound());
          }
        }
        tests_c += hi - lo;
      };
      const int64_t qx = col(px), qy = row(py);
      // A list filled by the hints bounds the answer: whatever can still enter lies within the
      // k-th best distance (an equal one may win on id). When that disc is small, its cells are
      // scanned row by row, each row's chord of it as one run, and nothing else: no ring needs
      // visiting. col() and row() are monotone, so an entry within the chord (widened by
      // `slack` against rounding) lies in a cell of the run.
      if (k > 0 && best.full() && best.bound() < kChordReach * kChordReach * cell_ * cell_) {
        const double reach = std::sqrt(best.bound()) + slack;
        const int64_t cy0 = row(py - reach), cy1 = row(py + reach);
        auto chord = [&](int64_t cy) {
          int64_t cx0, cx1;
          if (chord_cells(px, py, best.bound(), slack, cy, cx0, cx1)) scan(cy, cx0, cx1);
        };
        chord(qy);  // the query's own row first: the likeliest nearest
        for (int64_t cy = cy0; cy <= cy1; ++cy)
          if (cy != qy) chord(cy);
        ++rings_c;
      } else if (k == 0) {
        // Every cell the range box touches (one cell of slack against rounding).
        const int64_t cx0 = std::max<int64_t>(0, col(px - range) - 1);
        const int64_t cx1 = std::min<int64_t>(W_ - 1, col(px + range) + 1);
        const int64_t cy0 = std::max<int64_t>(0, row(py - range) - 1);
        const int64_t cy1 = std::min<int64_t>(H_ - 1, row(py + range) + 1);
        for (int64_t cy = cy0; cy <= cy1; ++cy) scan(cy, cx0, cx1);
      } else {
        // Cells are skipped when even their nearest point is farther than the k-th best so
        // far (and than the range); `slack` keeps the test conservative under rounding of the
        // cell coordinates (an entry may sit a rounding error outside its cell's rectangle).
        auto cell_far = [&](int64_t cx, int64_t cy) {
          const double lx = x0_ + static_cast<double>(cx) * cell_;
          const double ly = y0_ + static_cast<double>(cy) * cell_;
          const double ddx = std::max({lx - px - slack, px - (lx + cell_) - slack, 0.0});
          const double ddy = std::max({ly - py - slack, py - (ly + cell_) - slack, 0.0});
          const double near2 = ddx * ddx + ddy * ddy;
          return near2 >= r2 || (best.full() && near2 > best.bound());
        };
        auto scan_cell = [&](int64_t cx, int64_t cy) {
          if (!cell_far(cx, cy)) scan(cy, cx, cx);
        };
        // Rings 0 and 1 first, as three runs of adjacent cells (contiguous in the arrays).
        const int64_t bx0 = std::max<int64_t>(0, qx - 1), bx1 = std::min(W_ - 1, qx + 1);
        const int64_t by0 = std::max<int64_t>(0, qy - 1), by1 = std::min(H_ - 1, qy + 1);
        // The query's own row of cells first: its candidates are the likeliest nearest, so the
        // k-th best bound tightens early and more of the other rows' candidates are cut at once.
        scan(qy, bx0, bx1);
        if (by0 < qy) scan(by0, bx0, bx1);
        if (by1 > qy) scan(by1, bx0, bx1);
        rings_c += 2;
        // Every disc outside the block is at least `gap` away (a side on the grid's edge has
        // nothing beyond it); done when the k-th best, or the range, is strictly nearer.
        double gap = INFINITY;
        if (bx0 > 0) gap = std::min(gap, px - (x0_ + static_cast<double>(bx0) * cell_));
        if (bx1 < W_ - 1) gap = std::min(gap, x0_ + static_cast<double>(bx1 + 1) * cell_ - px);
        if (by0 > 0) gap = std::min(gap, py - (y0_ + static_cast<double>(by0) * cell_));
        if (by1 < H_ - 1) gap = std::min(gap, y0_ + static_cast<double>(by1 + 1) * cell_ - py);
        gap -= slack;
        const bool done = gap > 0 && (gap * gap >= r2 || (best.full() && best.bound() < gap * gap));
        const int64_t max_ring = done ? 1 : std::max({qx, W_ - 1 - qx, qy, H_ - 1 - qy});
        for (int64_t rho = 2; rho <= max_ring; ++rho) {
          const double reach = static_cast<double>(rho - 1) * cell_ * (1 - 1e-9);
          if (reach >= range || (best.full() && best.bound() < reach * reach)) break;
          ++rings_c;
          const int64_t cx0 = std::max<int64_t>(0, qx - rho), cx1 = std::min(W_ - 1, qx + rho);
          for (int64_t cx = cx0; cx <= cx1; ++cx) {
            if (qy - rho >= 0) scan_cell(cx, qy - rho);  // bottom row of the ring
            if (qy + rho < H_) scan_cell(cx, qy + rho);  // top row
          }
          const int64_t cy0 = std::max<int64_t>(0, qy - rho + 1),
                        cy1 = std::min(H_ - 1, qy + rho - 1);
          for (int64_t cy = cy0; cy <= cy1; ++cy) {  // the two side columns
            if (qx - rho >= 0) scan_cell(qx - rho, cy);
            if (qx + rho < W_) scan_cell(qx + rho, cy);
          }
        }
      }
      best.finish();
      if (slots) {
        slot_count_[i] = static_cast<uint32_t>(best.size());
        std::copy(best.rows().begin(), best.rows().end(),
                  slot_row_.begin() + static_cast<std::ptrdiff_t>(i * k));
      }
      if (spatial) {
        if (out.with_dist2)
          std::copy(best.dist2().begin(), best.dist2().end(),
                    out.dist2.begin() + static_cast<std::ptrdiff_t>(i * k));
        continue;
      }
      mine.counts.push_back(static_cast<uint32_t>(best.size()));
      mine.items.insert(mine.items.end(), best.rows().begin(), best.rows().end());
      if (out.with_dist2) mine.d2.insert(mine.d2.end(), best.dist2().begin(), best.dist2().end());
    }
    tests[c] = tests_c;
    rings[c] = rings_c;
    lists.put(c, std::move(mine));
  });
  if (spatial) {
    // The offsets in chunks on every thread (a pass on one thread was a millisecond a tick at
    // 10^6 rows): each chunk's total, their sums in chunk order, then each chunk's offsets and
    // lists from its start.
    const std::size_t copy_chunks = (d.n + kCopyGrain - 1) / kCopyGrain;
    std::vector<uint32_t> chunk_start(copy_chunks + 1, 0);
    ex.for_each_chunk(d.n, kCopyGrain, [&](std::size_t b, std::size_t e) {
      uint32_t sum = 0;
      for (std::size_t i = b; i < e; ++i) sum += slot_count_[i];
      chunk_start[b / kCopyGrain + 1] = sum;
    });
    for (std::size_t c = 0; c < copy_chunks; ++c) chunk_start[c + 1] += chunk_start[c];
    out.offset.resize(d.n + 1);
    out.row.resize(chunk_start[copy_chunks]);
    ex.for_each_chunk(d.n, kCopyGrain, [&](std::size_t b, std::size_t e) {
      uint32_t at = chunk_start[b / kCopyGrain];
      for (std::size_t i = b; i < e; ++i) {
        out.offset[i] = at;
        std::copy_n(slot_row_.begin() + static_cast<std::ptrdiff_t>(i * k), slot_count_[i],
                    out.row.begin() + at);
        at += slot_count_[i];
      }
    });
    out.offset[d.n] = chunk_start[copy_chunks];
    // In place, forwards from the first short list (each list moves to an earlier place, after
    // the lists before it have moved): one pass on one thread.
    if (out.with_dist2) {
      double* const d2 = out.dist2.data();
      for (std::size_t i = 0; i < d.n; ++i)
        if (out.offset[i] != i * k) std::copy_n(d2 + i * k, slot_count_[i], d2 + out.offset[i]);
      out.dist2.resize(out.offset[d.n]);
    } else {
      out.dist2.clear();
    }
  } else {
    lists.gather(out, &NeighbourLists::row, &ex);
    list_mean_ = q ? static_cast<double>(out.row.size()) / static_cast<double>(q) : 0;
  }
  stats.rows += q;
  for (std::size_t c = 0; c < chunks; ++c) {
    stats.pair_tests += tests[c];
    stats.nodes_visited += rings[c];
  }
  stats.query_seconds += sw.seconds();
}

}  // namespace crowddb::index
