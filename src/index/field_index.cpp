// The potential-field aggregate index: exact separable exponential sums for every probe at once.
//
// WHAT IS SUMMED. For each probe p: S(p) = sum over sources q other than p itself of
// w_q e^{-k d(p, q)}, with its gradient with respect to p (DESIGN.md §4). With the L1 metric the
// kernel separates by quadrant (thesis §2.2): for the sources q left of and below p,
//     e^{-k(dx + dy)} = e^{-k x_p} e^{-k y_p} * e^{k x_q} e^{k y_q},     dx = x_p - x_q, dy = ...
// so the quadrant sum is a 2-D dominance aggregate of the source weights w_q e^{k x_q + k y_q}.
// The radial metric with m = 2 frames (θ = 0, π/4) is d = (π/8)(|dx| + |dy| + √2 max(|dx|,|dy|)):
// the lines x = 0, y = 0, y = x and y = -x cut the plane around p into 8 wedges, inside each of
// which every |.| has a fixed sign, so the kernel is e^{-(α Δa + β Δb)} for two linear keys a, b
// (e.g. a = y, b = x - y in the wedge 0 < dy < dx, α = (2+√2)kπ/8, β = (1+√2)kπ/8) and the
// wedge is the dominance region Δa > 0, Δb > 0 in those sheared coordinates. m = 1 is L1 scaled
// by π/4. So every supported metric is a list of "combos" (keys a, b; rates α, β): each combo's
// forward sweep gives the wedge Δa > 0, Δb > 0 and its backward sweep the opposite wedge
// Δa < 0, Δb < 0 (L1: 2 combos, (x, y) and (x, -y); radial m = 2: 4 combos).
//
// TIES, EXACTLY AS THE NAIVE DEFINITION. Keys are exact: a single coordinate, or the exact sum
// x ± y held unevaluated as hi + lo (TwoSum), so every comparison is the exact comparison of the
// real coordinates. A source on a wedge's boundary ray (Δa = 0 < Δb or Δb = 0 < Δa) belongs to
// the two wedges that share the ray; each counts it with weight 1/2. The potential is continuous
// across the ray, and the gradient there is the mean of the two wedges' gradients, which is what
// the naive rule sign(0) = 0 gives (only the |.| term of that line changes sign across it).
// Coincident sources (Δa = Δb = 0 in every combo) are summed separately with weight e^0 and zero
// gradient, excluding the probe's own entry by identity: coincident distinct points count.
// (Radial keys x ± y are compared exactly; the naive path compares its rounded differences, so a
// pair whose rounded differences tie on a diagonal while the exact coordinates do not — possible
// only when coordinate differences round, never on lattices or small integers/dyadics — may get
// an adjacent wedge's gradient. L1 classification is always exact: sign(x_p - x_q) is exact.)
//
// SWEEP. Per combo the tile's entries are sorted by (a, b) and b is ranked (for the L1 combos
// both come from the tile's (x, y, id) order and y ranks, without sorting again; that order and
// the y ranks come from radix sorts of the coordinates' bits, the rare runs of equal x then
// sorted by (y, id)). The forward sweep visits runs of equal a in increasing a; probes of a run
// query a Fenwick tree over
// b-ranks (prefix: sources with smaller a and smaller b: the wedge interior), an array of
// per-rank sums (smaller a, equal b: one ray) and a running sum inside the run (equal a,
// smaller b: the other ray); then the run's sources are inserted. The backward sweep mirrors it.
//
// NUMERICS: ANY COORDINATE RANGE. e^{k x} overflows a double near k x ≈ 709, so weights are
// computed in tile-local coordinates. If the whole table's bounding box keeps every combo's
// exponent α|a_local| + β|b_local| <= B = 650 (local origin at the box centre), it is one tile.
// Otherwise probes are covered greedily by x-slabs and, inside a slab, by y-tiles of side T;
// each tile sees the sources within a halo H of it and uses the origin (x0 + T/2, y0 + T/2), so
// |local coordinate| <= R = T/2 + H with the exponent bound at R equal to B (L1: k R = 325,
// T ≈ 2 (325 - 50) / k, e.g. 2,000 units for the thesis's k). H is chosen so that a source
// farther than H in x or y (hence k d >= decay H) weighs at most
// e^{-decay H} = e^{-36} / (n_sources + 1): all dropped terms of a probe together are below
// 2.4e-16 · A c_max^2, four orders below the absolute tolerance (swept tiles drop only sources
// outside their window, direct tiles every source beyond H in x or y: the bound holds for both).
// Weights are normalised by c_max, so stored sums stay below
// n e^{650} < 10^300 for n < 2^31, and probe factors e^{-650} ≈ 10^-282 are normal numbers.
//
// SPARSE TILES. A tile with at most 16 probe x source pairs per entry (sparse worlds: the E5
// board holds ~5 entries per tile) is summed pair by pair with the naive path's own PairKernel
// (same halo cut): cheaper than sorting, and term for term the naive path's arithmetic.
// The "cutoff" method (any exp metric: exp-l2, radial with m > 2) sums every tile this way,
// with tiles of side 2H; its cost is O(n x sources within the halo), O(n^2) when the whole
// table fits in one tile.
//
// ERROR BOUND (relative to S_abs, the sum of |contributions|, unit roundoff u = 1.1e-16):
//  - each weight or probe factor e^{±α l}: the argument is rounded (|arg| <= 650, so
//    <= 650u absolute), exp itself < 1 ulp: <= ~4 (650 + 2) u ≈ 2.9e-13 relative per term;
//  - summation: Fenwick partial sums hold only terms of the probe's own wedge, at most
//    2 log2(n) + 4 additions deep: <= 50u for n <= 10^6;
//  - halo: <= 2.4e-16 A c_max^2 absolute; underflow of tiny weights: < 1e-250 A c_max^2.
// So |S_idx - S_exact| <= 3e-13 S_abs + 3e-16 A c_max^2, far inside DESIGN.md's
// 1e-9 S_abs + 1e-12 A c_max^2 (the naive sum itself is off by up to n u S_abs). Gradient
// components are sums of the same terms times wedge coefficients of size <= k: the same bound
// times k. Measured (tests, E5): |S_idx - S_naive| <= ~1e-4 of the tolerance.
//
// COMPLEXITY. One global sort by x, O(n log n) (not for a world of one swept tile, which needs
// no order but its own); every source lies in at most 4 tiles (2H < T); per swept tile of m
// entries: a radix sort by x (O(m) passes of 11 bits over the varying bits) and, per combo, at
// most two sorts and two sweeps, O(m log m); a direct tile costs O(pairs) <= 16 m. Total
// O(n log n) time, O(n) memory (a world of one tile on T threads: min(T, combos) sweeps'
// scratch at once). Exponentials: 2 per entry per combo in swept tiles, 1 per pair in direct
// tiles.
//
// DETERMINISM. Entries are ordered by (x, id) (direct tiles add their terms in that order) and
// inside swept tiles by (x, y, id); tiles are cut
// by a deterministic greedy rule; each probe is computed in exactly one tile, and slabs are
// independent, one thread each. A world that fits one tile (2 * 10^4 agents on 200 m at the
// thesis's k) would leave every thread but one idle: its combos run on every thread instead, each
// sweep's sums kept apart and added in the order one thread adds them. The output does not depend
// on the thread count (tests: FieldIndex.ThreadCountDoesNotChangeBits, OneLargeTileOnEveryThread).
#include "index/field_index.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include "crowddb/error.hpp"
#include "query/field_kernels.hpp"
#include "util/executor.hpp"
#include "util/stopwatch.hpp"

namespace crowddb {
namespace {

constexpr double kExponentBudget = 650;  // max |exponent| of a stored weight (e^709 overflows)
constexpr double kHaloMargin = 36;       // e^{-36} = 2.3e-16: per-table budget for dropped terms
// A tile with at most this many probe x source pairs per entry is summed pair by pair.
constexpr std::size_t kDirectPairsPerEntry = 16;

// Is a tile of m entries summed pair by pair (direct) rather than swept? The one-tile path asks
// before the tile does, to put the entries in the order a direct tile adds its terms in.
bool sums_directly(bool cutoff, std::size_t probes, std::size_t sources, std::size_t m) {
  return cutoff || probes * sources <= kDirectPairsPerEntry * m;
}
// From this many entries a tile runs its combos on every thread (a one-tile world: the slabs
// of a tiled one already run on every thread).
constexpr std::size_t kParallelCombos = 4096;

// A linear form cx x + cy y with cx, cy in {-1, 0, 1}.
struct Form {
  int cx, cy;
};

// The exact value of a form as an unevaluated sum hi + lo (Knuth's TwoSum): comparing keys
// lexicographically compares the exact real values.
struct Key {
  double hi, lo;
  friend bool operator==(const Key& a, const Key& b) { return a.hi == b.hi && a.lo == b.lo; }
  friend bool operator<(const Key& a, const Key& b) {
    return a.hi < b.hi || (a.hi == b.hi && a.lo < b.lo);
  }
};

Key key_of(Form f, double x, double y) {
  const double a = f.cx < 0 ? -x : x, b = f.cy < 0 ? -y : y;
  if (f.cy == 0) return {a, 0.0};
  if (f.cx == 0) return {b, 0.0};
  const double s = a + b;
  const double bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}

double value_of(Form f, double lx, double ly) {
  double v = 0;
  if (f.cx) v = f.cx < 0 ? -lx : lx;
  if (f.cy) v += f.cy < 0 ? -ly : ly;
  return v;
}

// One pair of opposite wedges: forward (Δa > 0, Δb > 0) with gradient coefficients gpp and
// backward (Δa < 0, Δb < 0) with gmm; the kernel in both is e^{-(α |Δa| + β |Δb|)}.
struct Combo {
  Form a, b;
  double alpha, beta;
  double gpp_x, gpp_y, gmm_x, gmm_y;
};

struct Separable {
  int combos = 0;
  Combo c[4];
  double decay = 0;  // k d >= decay * max(|dx|, |dy|)

  // Largest exponent of a stored weight when |local x| <= rx and |local y| <= ry.
  double bound(double rx, double ry) const {
    double m = 0;
    for (int i = 0; i < combos; ++i) {
      const Combo& q = c[i];
      const double e = q.alpha * (std::abs(q.a.cx) * rx + std::abs(q.a.cy) * ry) +
                       q.beta * (std::abs(q.b.cx) * rx + std::abs(q.b.cy) * ry);
      m = std::max(m, e);
    }
    return m;
  }
};

Separable separable_of(const PotentialSpec& s) {
  Separable sep;
  if (s.metric == Metric::l1 || (s.metric == Metric::radial && s.radial_frames == 1)) {
    const double k = s.metric == Metric::l1 ? s.k : s.k * (std::numbers::pi / 4);
    sep.combos = 2;
    sep.c[0] = {{1, 0}, {0, 1}, k, k, -k, -k, k, k};   // q left-below / right-above
    sep.c[1] = {{1, 0}, {0, -1}, k, k, -k, k, k, -k};  // q left-above / right-below
    sep.decay = k;
    return sep;
  }
  // Radial, m = 2: d = (π/8)((1+√2) max(|dx|,|dy|) + min(|dx|,|dy|)).
  const double kp = s.k * (std::numbers::pi / 8);
  const double al = (2 + std::numbers::sqrt2) * kp, be = (1 + std::numbers::sqrt2) * kp, g = be;
  sep.combos = 4;
  sep.c[0] = {{0, 1}, {1, -1}, al, be, -g, -kp, g, kp};   // 0 < dy < dx      | dx < dy < 0
  sep.c[1] = {{1, 0}, {-1, 1}, al, be, -kp, -g, kp, g};   // 0 < dx < dy      | dy < dx < 0
  sep.c[2] = {{-1, 0}, {1, 1}, al, be, kp, -g, -kp, g};   // 0 < -dx < dy     | 0 < dx < -dy
  sep.c[3] = {{0, 1}, {-1, -1}, al, be, g, -kp, -g, kp};  // 0 < dy < -dx     | 0 < -dy < dx
  sep.decay = g;
  return sep;
}

// The order of finite doubles as unsigned words (-0 and +0 as one: they compare equal).
inline uint64_t order_bits(double v) {
  const auto b = std::bit_cast<uint64_t>(v + 0.0);  // -0 + 0 = +0
  return b >> 63 ? ~b : b | (uint64_t{1} << 63);
}

struct KeyedIndex {
  uint64_t key;
  uint32_t at;
};

// Sorts v by key, stably: least significant digit first, 11 bits at a time, skipping the digits
// on which every key agrees (coordinates of one sign within a few powers of two share their top
// bits; a region around 0 shares none). Six passes for 2 * 10^4 positions on 200 m: a fifth of
// std::sort's time on (x, y, id).
void radix_by_key(std::vector<KeyedIndex>& v, std::vector<KeyedIndex>& tmp) {
  constexpr int kDigit = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigit;
  const std::size_t n = v.size();
  if (n < 2) return;
  uint64_t any = 0, all = ~uint64_t{0};
  for (const KeyedIndex& e : v) {
    any |= e.key;
    all &= e.key;
  }
  const uint64_t varying = any ^ all;
  tmp.resize(n);
  std::array<uint32_t, kBuckets> place;
  for (int shift = 0; shift < 64; shift += kDigit) {
    if (((varying >> shift) & (kBuckets - 1)) == 0) continue;
    place.fill(0);
    for (const KeyedIndex& e : v) ++place[(e.key >> shift) & (kBuckets - 1)];
    uint32_t sum = 0;
    for (uint32_t& c : place) {
      const uint32_t k = c;
      c = sum;
      sum += k;
    }
    for (const KeyedIndex& e : v) tmp[place[(e.key >> shift) & (kBuckets - 1)]++] = e;
    v.swap(tmp);
  }
}

// Sum over [0, i) of a Fenwick tree stored 1-based in t.
inline double fen_prefix(const std::vector<double>& t, std::size_t i) {
  double s = 0;
  for (; i > 0; i &= i - 1) s += t[i];
  return s;
}
inline void fen_add(std::vector<double>& t, std::size_t i, double v) {
  for (++i; i < t.size(); i += i & (~i + 1)) t[i] += v;
}

// One combo's working storage.
struct ComboScratch {
  std::vector<Key> ka, kb;
  std::vector<double> ea, iea, eb, ieb, fen, eq;
  std::vector<uint32_t> order, rank;
  std::vector<std::pair<Key, uint32_t>> bsort;
};

// Per-thread working storage, reused across tiles.
struct Scratch {
  uint64_t pairs = 0;  // direct pair evaluations (QueryStats::pair_tests)
  // Tile entries in (x, y, id) order.
  std::vector<double> x, y, lx, ly, w, pot, gx, gy;
  std::vector<uint32_t> slot;
  std::vector<uint32_t> yrank;
  std::size_t yrank_count = 0;
  ComboScratch combo;  // the combos one after the other
  // Or on several threads: a scratch per chunk of combos, and per combo each probe's sums over
  // its two wedges, added to the tile's sums afterwards in the order one thread adds them.
  std::vector<ComboScratch> chunk_combo;
  std::vector<std::vector<double>> fwd, bwd;
  std::vector<KeyedIndex> keyed, keyed_tmp;  // radix_by_key
  std::vector<uint64_t> sorted_items;
  // Slab and tile cutting.
  struct SlabItem {
    double y;
    uint32_t gpos;
    uint32_t probe;
  };
  std::vector<SlabItem> slab;
  std::vector<uint64_t> items;  // gpos << 1 | is-probe-of-this-tile
};

struct Outputs {
  std::span<double> pot, gx, gy;
};

}  // namespace

struct FieldSumScratch {
  std::vector<std::pair<double, uint32_t>> order;  // the entries' (x, id) order
  std::vector<FieldEntry> sorted;
  Scratch one;                  // a world of one tile
  std::vector<Scratch> chunks;  // per chunk of slabs
};

void FieldSumScratchDeleter::operator()(FieldSumScratch* s) const {
  delete s;
}
FieldSumScratchPtr make_field_sum_scratch() {
  return FieldSumScratchPtr(new FieldSumScratch);
}

namespace {

// One combo's forward and backward sweeps over the tile's entries (read only). Each probe's sum
// over the forward wedge goes to fwd(e, res), over the backward wedge to bwd(e, res), once each.
template <class Fwd, class Bwd>
void run_combo(const Scratch& s, ComboScratch& cs, const Combo& c, Fwd&& fwd, Bwd&& bwd) {
  const std::size_t m = s.x.size();
  cs.ka.resize(m);
  cs.kb.resize(m);
  cs.ea.resize(m);
  cs.iea.resize(m);
  cs.eb.resize(m);
  cs.ieb.resize(m);
  for (std::size_t i = 0; i < m; ++i) {
    cs.ka[i] = key_of(c.a, s.x[i], s.y[i]);
    cs.kb[i] = key_of(c.b, s.x[i], s.y[i]);
    cs.ea[i] = std::exp(c.alpha * value_of(c.a, s.lx[i], s.ly[i]));
    cs.eb[i] = std::exp(c.beta * value_of(c.b, s.lx[i], s.ly[i]));
    cs.iea[i] = 1 / cs.ea[i];
    cs.ieb[i] = 1 / cs.eb[i];
  }
  cs.order.resize(m);
  cs.rank.resize(m);
  std::size_t r = 0;
  if (c.a.cx == 1 && c.a.cy == 0 && c.b.cx == 0) {
    // L1 combos: entries are stored in (x, y, id) order with y ranked (process_tile).
    r = s.yrank_count;
    if (c.b.cy > 0) {
      std::iota(cs.order.begin(), cs.order.end(), 0u);
      std::copy(s.yrank.begin(), s.yrank.begin() + static_cast<std::ptrdiff_t>(m), cs.rank.begin());
    } else {
      // (x, -y, id) order: inside each run of equal x, the groups of equal y reversed.
      std::size_t out = 0;
      for (std::size_t run = 0; run < m;) {
        std::size_t run_end = run + 1;
        while (run_end < m && s.x[run_end] == s.x[run]) ++run_end;
        for (std::size_t g_end = run_end; g_end > run;) {
          std::size_t g = g_end - 1;
          while (g > run && s.y[g - 1] == s.y[g]) --g;
          for (std::size_t i = g; i < g_end; ++i) cs.order[out++] = static_cast<uint32_t>(i);
          g_end = g;
        }
        run = run_end;
      }
      for (std::size_t i = 0; i < m; ++i) cs.rank[i] = static_cast<uint32_t>(r - 1 - s.yrank[i]);
    }
  } else {
    std::iota(cs.order.begin(), cs.order.end(), 0u);
    std::sort(cs.order.begin(), cs.order.end(), [&](uint32_t i, uint32_t j) {
      if (cs.ka[i] < cs.ka[j]) return true;
      if (cs.ka[j] < cs.ka[i]) return false;
      if (cs.kb[i] < cs.kb[j]) return true;
      if (cs.kb[j] < cs.kb[i]) return false;
      return i < j;
    });
    cs.bsort.resize(m);
    for (uint32_t i = 0; i < m; ++i) cs.bsort[i] = {cs.kb[i], i};
    std::sort(cs.bsort.begin(), cs.bsort.end(),
              [](const auto& p, const auto& q) { return p.first < q.first; });
    for (std::size_t i = 0; i < m; ++i) {
      if (i > 0 && !(cs.bsort[i].first == cs.bsort[i - 1].first)) ++r;
      cs.rank[cs.bsort[i].second] = static_cast<uint32_t>(r);
    }
    r = m ? r + 1 : 0;
  }

  // Forward: wedge Δa > 0, Δb > 0 and its rays.
  cs.fen.assign(r + 1, 0.0);
  cs.eq.assign(r, 0.0);
  for (std::size_t pos = 0; pos < m;) {
    std::size_t run_end = pos + 1;
    while (run_end < m && cs.ka[cs.order[run_end]] == cs.ka[cs.order[pos]]) ++run_end;
    double pre = 0;  // same a, smaller b: sum of w e^{β b}
    for (std::size_t g = pos; g < run_end;) {
      std::size_t g_end = g + 1;
      while (g_end < run_end && cs.kb[cs.order[g_end]] == cs.kb[cs.order[g]]) ++g_end;
      for (std::size_t i = g; i < g_end; ++i) {
        const uint32_t e = cs.order[i];
        if (s.slot[e] == FieldEntry::kNoSlot) continue;
        const uint32_t rk = cs.rank[e];
        const double inter = fen_prefix(cs.fen, rk) * cs.iea[e] * cs.ieb[e];
        const double res = inter + 0.5 * (cs.eq[rk] * cs.iea[e] + pre * cs.ieb[e]);
        fwd(e, res);
      }
      for (std::size_t i = g; i < g_end; ++i) pre += s.w[cs.order[i]] * cs.eb[cs.order[i]];
      g = g_end;
    }
    for (std::size_t i = pos; i < run_end; ++i) {
      const uint32_t e = cs.order[i];
      if (s.w[e] == 0) continue;
      fen_add(cs.fen, cs.rank[e], s.w[e] * cs.ea[e] * cs.eb[e]);
      cs.eq[cs.rank[e]] += s.w[e] * cs.ea[e];
    }
    pos = run_end;
  }

  // Backward: wedge Δa < 0, Δb < 0; the tree is indexed by reversed rank (prefix = larger b).
  cs.fen.assign(r + 1, 0.0);
  cs.eq.assign(r, 0.0);
  for (std::size_t end = m; end > 0;) {
    std::size_t run_begin = end - 1;
    while (run_begin > 0 && cs.ka[cs.order[run_begin - 1]] == cs.ka[cs.order[end - 1]]) --run_begin;
    double suf = 0;  // same a, larger b: sum of w e^{-β b}
    for (std::size_t g_end = end; g_end > run_begin;) {
      std::size_t g = g_end - 1;
      while (g > run_begin && cs.kb[cs.order[g - 1]] == cs.kb[cs.order[g_end - 1]]) --g;
      for (std::size_t i = g; i < g_end; ++i) {
        const uint32_t e = cs.order[i];
        if (s.slot[e] == FieldEntry::kNoSlot) continue;
        const uint32_t rk = cs.rank[e];
        const double inter = fen_prefix(cs.fen, r - 1 - rk) * cs.ea[e] * cs.eb[e];
        const double res = inter + 0.5 * (cs.eq[rk] * cs.ea[e] + suf * cs.eb[e]);
        bwd(e, res);
      }
      for (std::size_t i = g; i < g_end; ++i) suf += s.w[cs.order[i]] * cs.ieb[cs.order[i]];
      g_end = g;
    }
    for (std::size_t i = run_begin; i < end; ++i) {
      const uint32_t e = cs.order[i];
      if (s.w[e] == 0) continue;
      fen_add(cs.fen, r - 1 - cs.rank[e], s.w[e] * cs.iea[e] * cs.ieb[e]);
      cs.eq[cs.rank[e]] += s.w[e] * cs.iea[e];
    }
    end = run_begin;
  }
}

// Sums for the probes among `items` (low bit = probe of this tile; the rest, gpos, indexes E)
// over the sources among them; local coordinates (x - ox) - half. Sparse tiles (few probe x
// source pairs) are summed pair by pair with the naive path's own kernel; the others by sweeps.
void process_tile(const std::vector<FieldEntry>& E, std::span<uint64_t> items, double ox, double oy,
                  double half, double halo, bool direct_only, const Separable& sep,
                  const PairKernel& kernel, Scratch& s, const Outputs& out, Executor* ex) {
  const std::size_t m = items.size();
  std::size_t probes = 0, sources = 0;
  for (uint64_t it : items) {
    probes += it & 1;
    sources += E[it >> 1].w != 0;
  }
  if (probes == 0) return;
  if (sums_directly(direct_only, probes, sources, m)) {
    for (std::size_t i = 0; i < m; ++i) {
      if (!(items[i] & 1)) continue;
      const FieldEntry& p = E[items[i] >> 1];
      double pot = 0, gx = 0, gy = 0;
      for (std::size_t j = 0; j < m; ++j) {
        const FieldEntry& q = E[items[j] >> 1];
        const double dx = p.x - q.x, dy = p.y - q.y;
        // Beyond the halo in x or y a term is below the dropped-term bound (see above).
        if (j == i || q.w == 0 || std::abs(dx) > halo || std::abs(dy) > halo) continue;
        kernel.add(dx, dy, q.w, pot, gx, gy);
        ++s.pairs;
      }
      out.pot[p.slot] = pot;
      out.gx[p.slot] = gx;
      out.gy[p.slot] = gy;
    }
    return;
  }

  // Sweeps: entries in (x, y, id) order (ids are unique: one order, whatever the items' order):
  // by x with a radix sort, then the runs of equal x (rare) by (y, id).
  s.keyed.resize(m);
  for (std::size_t i = 0; i < m; ++i)
    s.keyed[i] = {order_bits(E[items[i] >> 1].x), static_cast<uint32_t>(i)};
  radix_by_key(s.keyed, s.keyed_tmp);
  s.sorted_items.resize(m);
  for (std::size_t i = 0; i < m; ++i) s.sorted_items[i] = items[s.keyed[i].at];
  for (std::size_t g = 0; g < m;) {
    std::size_t g_end = g + 1;
    while (g_end < m && s.keyed[g_end].key == s.keyed[g].key) ++g_end;
    if (g_end - g > 1)
      std::sort(s.sorted_items.begin() + static_cast<std::ptrdiff_t>(g),
                s.sorted_items.begin() + static_cast<std::ptrdiff_t>(g_end),
                [&](uint64_t a, uint64_t b) {
                  const FieldEntry &p = E[a >> 1], &q = E[b >> 1];
                  return p.y < q.y || (p.y == q.y && p.id < q.id);
                });
    g = g_end;
  }
  std::copy(s.sorted_items.begin(), s.sorted_items.end(), items.begin());
  for (auto* v : {&s.x, &s.y, &s.lx, &s.ly, &s.w}) v->resize(m);
  s.slot.resize(m);
  s.pot.assign(m, 0.0);
  s.gx.assign(m, 0.0);
  s.gy.assign(m, 0.0);
  for (std::size_t i = 0; i < m; ++i) {
    const FieldEntry& e = E[items[i] >> 1];
    s.x[i] = e.x;
    s.y[i] = e.y;
    s.lx[i] = (e.x - ox) - half;
    s.ly[i] = (e.y - oy) - half;
    s.w[i] = e.w;
    s.slot[i] = (items[i] & 1) ? e.slot : FieldEntry::kNoSlot;
    s.keyed[i] = {order_bits(e.y), static_cast<uint32_t>(i)};
  }
  // y ranks: equal y, equal rank.
  radix_by_key(s.keyed, s.keyed_tmp);
  s.yrank.resize(m);
  std::size_t r = 0;
  for (std::size_t i = 0; i < m; ++i) {
    if (i > 0 && s.keyed[i].key != s.keyed[i - 1].key) ++r;
    s.yrank[s.keyed[i].at] = static_cast<uint32_t>(r);
  }
  s.yrank_count = r + 1;

  // Coincident sources: weight e^0, no gradient, never the probe itself.
  for (std::size_t g = 0; g < m;) {
    std::size_t g_end = g + 1;
    while (g_end < m && s.x[g_end] == s.x[g] && s.y[g_end] == s.y[g]) ++g_end;
    if (g_end - g > 1) {
      double pre = 0;
      for (std::size_t i = g; i < g_end; ++i) {
        s.pot[i] += pre;
        pre += s.w[i];
      }
      double suf = 0;
      for (std::size_t i = g_end; i > g; --i) {
        s.pot[i - 1] += suf;
        suf += s.w[i - 1];
      }
    }
    g = g_end;
  }
  if (ex && ex->threads() > 1 && m >= kParallelCombos) {
    // The combos on every thread, each with its own storage; their sums are added in the order
    // one thread adds them (forward, backward, combo by combo), so the same bits.
    const auto combos = static_cast<std::size_t>(sep.combos);
    // As many chunks as threads, at most: a sweep's scratch is about 100 bytes an entry.
    const auto threads = static_cast<std::size_t>(ex->threads());
    const std::size_t grain = (combos + threads - 1) / threads;
    s.chunk_combo.resize((combos + grain - 1) / grain);
    s.fwd.resize(combos);
    s.bwd.resize(combos);
    ex->for_each_chunk(combos, grain, [&](std::size_t b, std::size_t e) {
      for (std::size_t c = b; c < e; ++c) {
        std::vector<double>& fwd = s.fwd[c];
        std::vector<double>& bwd = s.bwd[c];
        fwd.resize(m);
        bwd.resize(m);
        run_combo(
            s, s.chunk_combo[b / grain], sep.c[c], [&](uint32_t i, double res) { fwd[i] = res; },
            [&](uint32_t i, double res) { bwd[i] = res; });
      }
    });
    for (std::size_t c = 0; c < combos; ++c) {
      const Combo& q = sep.c[c];
      const std::vector<double>& fwd = s.fwd[c];
      const std::vector<double>& bwd = s.bwd[c];
      for (std::size_t i = 0; i < m; ++i) {
        if (s.slot[i] == FieldEntry::kNoSlot) continue;
        s.pot[i] += fwd[i];
        s.gx[i] += q.gpp_x * fwd[i];
        s.gy[i] += q.gpp_y * fwd[i];
        s.pot[i] += bwd[i];
        s.gx[i] += q.gmm_x * bwd[i];
        s.gy[i] += q.gmm_y * bwd[i];
      }
    }
  } else {
    for (int c = 0; c < sep.combos; ++c) {
      const Combo& q = sep.c[c];
      run_combo(
          s, s.combo, q,
          [&](uint32_t i, double res) {
            s.pot[i] += res;
            s.gx[i] += q.gpp_x * res;
            s.gy[i] += q.gpp_y * res;
          },
          [&](uint32_t i, double res) {
            s.pot[i] += res;
            s.gx[i] += q.gmm_x * res;
            s.gy[i] += q.gmm_y * res;
          });
    }
  }
  for (std::size_t i = 0; i < m; ++i) {
    if (s.slot[i] == FieldEntry::kNoSlot) continue;
    out.pot[s.slot[i]] = s.pot[i];
    out.gx[s.slot[i]] = s.gx[i];
    out.gy[s.slot[i]] = s.gy[i];
  }
}

}  // namespace

bool field_index_supports(const PotentialSpec& spec) {
  return field_cutoff_supports(spec) &&
         (spec.metric == Metric::l1 ||
          (spec.metric == Metric::radial && (spec.radial_frames == 1 || spec.radial_frames == 2)));
}

bool field_cutoff_supports(const PotentialSpec& spec) {
  if (spec.kernel != Kernel::exp) return false;
  if (!std::isfinite(spec.A) || !std::isfinite(spec.k) || spec.k < 0) return false;
  if (spec.radial_frames < 1 || spec.radial_frames > PairKernel::kMaxFrames) return false;
  return !spec.finite_difference || (spec.fd_step > 0 && std::isfinite(spec.fd_step));
}

namespace {

// Both modes: `cutoff` sums every tile pair by pair (any exp metric); otherwise swept tiles.
void tiled_field_sums(std::vector<FieldEntry>& E, const PotentialSpec& spec, bool cutoff,
                      std::span<double> out_pot, std::span<double> out_gx, std::span<double> out_gy,
                      Executor& ex, QueryStats& stats, FieldSumScratch& fs) {
  Separable sep;
  if (cutoff) {
    // k d >= decay max(|dx|, |dy|): l1 and l2 >= L∞; radial >= (π/4) L2 (each frame's L1 >= L2).
    sep.decay = spec.metric == Metric::radial ? spec.k * (std::numbers::pi / 4) : spec.k;
  } else {
    sep = separable_of(spec);
  }
  const PairKernel kernel(spec);
  const Outputs out{out_pot, out_gx, out_gy};
  const std::size_t n = E.size();
  if (n == 0) return;
  if (n >= (std::size_t{1} << 31)) throw Error(Error::Kind::input, "field index: too many points");
  std::size_t sources = 0, probes = 0;
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  for (const FieldEntry& e : E) {
    if (!std::isfinite(e.x) || !std::isfinite(e.y) || !std::isfinite(e.w))
      throw Error(Error::Kind::input, "field index: a point or charge is not finite");
    sources += e.w != 0;
    probes += e.slot != FieldEntry::kNoSlot;
    xmin = std::min(xmin, e.x);
    xmax = std::max(xmax, e.x);
    ymin = std::min(ymin, e.y);
    ymax = std::max(ymax, e.y);
  }
  Stopwatch clock;
  const double hx = (xmax - xmin) / 2, hy = (ymax - ymin) / 2;
  const double halo = (std::log(static_cast<double>(sources) + 1) + kHaloMargin) / sep.decay;
  // Tile side T: swept tiles are as large as the exponent budget allows; direct tiles 2H, so a
  // window of (T + 2H)^2 = 16 H^2 serves a tile of 4 H^2.
  const double side = cutoff ? 2 * halo : 2 * (kExponentBudget / sep.bound(1, 1) - halo);
  const bool one_tile =
      cutoff ? !(2 * std::max(hx, hy) > side) : sep.bound(hx, hy) <= kExponentBudget;
  // A tile summed pair by pair adds each probe's terms in the entries' order, so the entries go
  // in (x, id) order first, as the slabs need them anyway. A swept tile sorts its own entries by
  // (x, y, id): for a world of one such tile the order of the input does not matter.
  if (!one_tile || sums_directly(cutoff, probes, sources, n)) {
    auto& order = fs.order;
    order.resize(n);
    for (std::size_t i = 0; i < n; ++i) order[i] = {E[i].x, static_cast<uint32_t>(i)};
    std::sort(order.begin(), order.end(), [&](const auto& a, const auto& b) {
      return a.first < b.first || (a.first == b.first && E[a.second].id < E[b.second].id);
    });
    auto& sorted = fs.sorted;
    sorted.resize(n);
    for (std::size_t i = 0; i < n; ++i) sorted[i] = E[order[i].second];
    E.swap(sorted);  // (the caller's old buffer stays here for the next call)
    stats.build_seconds += clock.seconds();
    clock.restart();
  }
  if (one_tile) {
    // One tile, origin at the centre of the bounding box, nothing dropped.
    Scratch& s = fs.one;
    s.pairs = 0;
    s.items.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      s.items[i] = (uint64_t{i} << 1) | (E[i].slot != FieldEntry::kNoSlot);
    process_tile(E, s.items, xmin + hx, ymin + hy, 0.0, INFINITY, cutoff, sep, kernel, s, out, &ex);
    stats.pair_tests += s.pairs;
    stats.nodes_visited += 1;
    stats.query_seconds += clock.seconds();
    return;
  }

  if (!(side > 0) || !std::isfinite(side))
    throw Error(Error::Kind::input, "field index: kernel rate out of range for tiling");
  const double half = side / 2;
  const auto is_probe = [&](std::size_t i) { return E[i].slot != FieldEntry::kNoSlot; };

  // X-slabs: greedy from the first probe not yet covered.
  struct Slab {
    double s0;
    std::size_t wl, wr;  // window of entries with x - s0 in [-halo, side + halo)
  };
  std::vector<Slab> slabs;
  {
    std::size_t i = 0, wl = 0, wr = 0;
    while (i < n && !is_probe(i)) ++i;
    while (i < n) {
      const double s0 = E[i].x;
      while (wl < n && E[wl].x - s0 < -halo) ++wl;
      wr = std::max(wr, wl);
      while (wr < n && E[wr].x - s0 < side + halo) ++wr;
      slabs.push_back({s0, wl, wr});
      while (i < n && (!is_probe(i) || E[i].x - s0 < side)) ++i;
    }
  }
  stats.build_seconds += clock.seconds();
  clock.restart();

  std::vector<uint64_t> tiles_per_slab(slabs.size(), 0), pairs_per_slab(slabs.size(), 0);
  constexpr std::size_t kSlabGrain = 4;
  if (fs.chunks.size() < (slabs.size() + kSlabGrain - 1) / kSlabGrain)
    fs.chunks.resize((slabs.size() + kSlabGrain - 1) / kSlabGrain);
  ex.for_each_chunk(slabs.size(), kSlabGrain, [&](std::size_t begin, std::size_t end) {
    Scratch& s = fs.chunks[begin / kSlabGrain];
    s.pairs = 0;
    for (std::size_t si = begin; si < end; ++si) {
      const Slab& sl = slabs[si];
      s.slab.clear();
      for (std::size_t j = sl.wl; j < sl.wr; ++j) {
        const double rel = E[j].x - sl.s0;
        const bool probe = is_probe(j) && rel >= 0 && rel < side;
        if (probe || E[j].w != 0)
          s.slab.push_back({E[j].y, static_cast<uint32_t>(j), probe ? 1u : 0u});
      }
      std::sort(s.slab.begin(), s.slab.end(),
                [](const auto& a, const auto& b) { return a.y < b.y; });
      const std::size_t m = s.slab.size();
      std::size_t i = 0, wl = 0, wr = 0;
      while (i < m && !s.slab[i].probe) ++i;
      while (i < m) {
        const double t0 = s.slab[i].y;
        while (wl < m && s.slab[wl].y - t0 < -halo) ++wl;
        wr = std::max(wr, wl);
        while (wr < m && s.slab[wr].y - t0 < side + halo) ++wr;
        s.items.clear();
        for (std::size_t j = wl; j < wr; ++j) {
          const auto& it = s.slab[j];
          const double rel = it.y - t0;
          const bool probe = it.probe && rel >= 0 && rel < side;
          if (probe || E[it.gpos].w != 0)
            s.items.push_back((uint64_t{it.gpos} << 1) | (probe ? 1u : 0u));
        }
        std::sort(s.items.begin(), s.items.end());
        process_tile(E, s.items, sl.s0, t0, half, halo, cutoff, sep, kernel, s, out, nullptr);
        ++tiles_per_slab[si];
        pairs_per_slab[si] += s.pairs;
        s.pairs = 0;
        while (i < m && (!s.slab[i].probe || s.slab[i].y - t0 < side)) ++i;
      }
    }
  });
  for (uint64_t t : tiles_per_slab) stats.nodes_visited += t;
  for (uint64_t p : pairs_per_slab) stats.pair_tests += p;
  stats.query_seconds += clock.seconds();
}

}  // namespace

void separable_field_sums(std::vector<FieldEntry>& E, const PotentialSpec& spec,
                          std::span<double> out_pot, std::span<double> out_gx,
                          std::span<double> out_gy, Executor& ex, QueryStats& stats,
                          FieldSumScratch* scratch) {
  if (!field_index_supports(spec))
    throw Error(Error::Kind::usage, "field index: unsupported kernel or metric");
  FieldSumScratch own;
  tiled_field_sums(E, spec, false, out_pot, out_gx, out_gy, ex, stats, scratch ? *scratch : own);
}

void cutoff_field_sums(std::vector<FieldEntry>& E, const PotentialSpec& spec,
                       std::span<double> out_pot, std::span<double> out_gx,
                       std::span<double> out_gy, Executor& ex, QueryStats& stats,
                       FieldSumScratch* scratch) {
  if (!field_cutoff_supports(spec))
    throw Error(Error::Kind::usage, "field cutoff: unsupported kernel");
  FieldSumScratch own;
  tiled_field_sums(E, spec, true, out_pot, out_gx, out_gy, ex, stats, scratch ? *scratch : own);
}

namespace {

// Fills `entries` with the sources: discs (weight c/c_max; probes of their own row when
// `discs_probe`) and the scene's charged points. Returns c_max (0 when every charge is 0).
double add_sources(std::vector<FieldEntry>& entries, const DiscView& d, const StaticScene& scene,
                   bool discs_probe) {
  double cmax = 0;
  for (std::size_t i = 0; i < d.n; ++i) cmax = std::max(cmax, std::abs(d.charge[i]));
  for (double c : scene.point_charge()) cmax = std::max(cmax, std::abs(c));
  if (!std::isfinite(cmax)) throw Error(Error::Kind::input, "field index: a charge is not finite");
  const double inv = cmax > 0 ? 1 / cmax : 0;
  entries.clear();
  entries.reserve(d.n + scene.point_count());
  for (std::size_t i = 0; i < d.n; ++i) {
    const double w = d.charge[i] * inv;
    if (w == 0 && !discs_probe) continue;
    entries.push_back({d.x[i], d.y[i], w,
                       discs_probe ? static_cast<uint32_t>(i) : FieldEntry::kNoSlot,
                       static_cast<uint32_t>(entries.size())});
  }
  const auto px = scene.point_x(), py = scene.point_y(), pc = scene.point_charge();
  for (std::size_t j = 0; j < px.size(); ++j) {
    if (pc[j] == 0) continue;
    entries.push_back(
        {px[j], py[j], pc[j] * inv, FieldEntry::kNoSlot, static_cast<uint32_t>(entries.size())});
  }
  return cmax;
}

void add_probe(std::vector<FieldEntry>& entries, double x, double y, std::size_t slot) {
  entries.push_back(
      {x, y, 0.0, static_cast<uint32_t>(slot), static_cast<uint32_t>(entries.size())});
}

}  // namespace

void FieldIndex::run(const DiscView& d, const StaticScene& scene, const PotentialSpec& spec,
                     FieldColumns& out, Executor& ex, QueryStats& stats) {
  const std::size_t n = d.n;
  out.resize(n);
  stats.rows += n;
  if (n == 0) return;
  const double cmax = add_sources(entries_, d, scene, true);
  const bool fd = spec.finite_difference;
  if (fd)
    for (std::size_t i = 0; i < n; ++i) {
      add_probe(entries_, d.x[i] + spec.fd_step, d.y[i], n + i);
      add_probe(entries_, d.x[i], d.y[i] + spec.fd_step, 2 * n + i);
    }
  const std::size_t slots = fd ? 3 * n : n;
  std::vector<double>&pot = pot_, &gx = gx_, &gy = gy_;
  pot.assign(slots, 0.0);
  gx.assign(slots, 0.0);
  gy.assign(slots, 0.0);
  sums(entries_, spec, pot, gx, gy, ex, stats);
  if (!fd) {
    for (std::size_t i = 0; i < n; ++i) {
      const double scale = spec.A * d.charge[i] * cmax;
      out.potential[i] = scale * pot[i];
      out.grad_x[i] = scale * gx[i];
      out.grad_y[i] = scale * gy[i];
    }
    return;
  }
  // Forward differences; the shifted probes saw their own disc at distance h: remove that term
  // (a subtraction of ~A c_p^2: it adds ~1e-16 A c_p^2 / h to the gradient, h = 1e-3: 1e-13).
  const PairKernel kernel(spec);
  double kx = 0, ky = 0, unused = 0;
  kernel.add(spec.fd_step, 0, 1, kx, unused, unused);
  kernel.add(0, spec.fd_step, 1, ky, unused, unused);
  for (std::size_t i = 0; i < n; ++i) {
    const double ac = spec.A * d.charge[i];
    const double p0 = ac * cmax * pot[i];
    const double px = ac * (cmax * pot[n + i] - d.charge[i] * kx);
    const double py = ac * (cmax * pot[2 * n + i] - d.charge[i] * ky);
    out.potential[i] = p0;
    out.grad_x[i] = (px - p0) / spec.fd_step;
    out.grad_y[i] = (py - p0) / spec.fd_step;
  }
}

void FieldIndex::probe(std::span<const Vec2> points, const DiscView& sources,
                       const StaticScene& scene, const PotentialSpec& spec, FieldColumns& out,
                       Executor& ex, QueryStats& stats) {
  const std::size_t n = points.size();
  out.resize(n);
  stats.rows += n;
  if (n == 0) return;
  const double cmax = add_sources(entries_, sources, scene, false);
  const bool fd = spec.finite_difference;
  for (std::size_t i = 0; i < n; ++i) {
    add_probe(entries_, points[i].x, points[i].y, i);
    if (fd) {
      add_probe(entries_, points[i].x + spec.fd_step, points[i].y, n + i);
      add_probe(entries_, points[i].x, points[i].y + spec.fd_step, 2 * n + i);
    }
  }
  const std::size_t slots = fd ? 3 * n : n;
  std::vector<double>&pot = pot_, &gx = gx_, &gy = gy_;
  pot.assign(slots, 0.0);
  gx.assign(slots, 0.0);
  gy.assign(slots, 0.0);
  sums(entries_, spec, pot, gx, gy, ex, stats);
  const double scale = spec.A * cmax;
  for (std::size_t i = 0; i < n; ++i) {
    out.potential[i] = scale * pot[i];
    if (!fd) {
      out.grad_x[i] = scale * gx[i];
      out.grad_y[i] = scale * gy[i];
    } else {
      out.grad_x[i] = (scale * pot[n + i] - out.potential[i]) / spec.fd_step;
      out.grad_y[i] = (scale * pot[2 * n + i] - out.potential[i]) / spec.fd_step;
    }
  }
}

}  // namespace crowddb
