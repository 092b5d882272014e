// Pieces shared by the collision-set indices (grid, sweep, nn, delaunay): the coordinate frame
// with its rounding margins, an LSD radix sort, and the canonical output order.
//
// Exactness. Every method decides a pair with the same call as the naive oracle,
// discs_overlap(x_j - x_i, y_j - y_i, r_i + r_j) on the original doubles, so only the candidate
// filters must be conservative. Filters work in frame coordinates u = x - x0, v = y - y0, whose
// rounding error is at most extent * 2^-53 (|x - x0| <= extent). A pair the exact test accepts
// lies at most (r_i + r_j)(1 + 2^-49) apart in real arithmetic. So a filter that treats discs
// as reaching `reach(r)` = r (1 + 2^-30) + slack, with slack = (extent + |query| + r) 2^-40,
// never rejects a pair the exact test would accept: the margins exceed the rounding errors by
// factors of 2^10 and more, and they cost nothing measurable (a few ulps of extra reach).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "crowddb/query.hpp"
#include "util/executor.hpp"

namespace crowddb::index {

using PairList = std::vector<std::pair<uint32_t, uint32_t>>;

// The origin and size of the discs' bounding box. finite == false when a coordinate or radius
// is NaN or infinite: methods then fall back to the naive loop (tables never hold such rows; the
// fallback only keeps a bad caller from hanging or crashing an index).
struct Frame {
  double x0 = 0, y0 = 0;
  double width = 0, height = 0;  // of the centres' bounding box
  double extent = 0;             // max(width, height)
  double rmin = 0, rmax = 0;
  std::size_t count = 0;  // discs
  bool finite = true;

  static Frame of(const DiscView& d) {
    Frame f;
    f.count = d.n;
    if (d.n == 0) return f;
    double xmin = INFINITY, ymin = INFINITY, xmax = -INFINITY, ymax = -INFINITY;
    double rlo = INFINITY, rhi = -INFINITY;
    bool nan = false;  // min and max pass over NaN: it is looked for on its own
    for (std::size_t i = 0; i < d.n; ++i) {
      // (As ints: | on them is meant, without a branch per row.)
      const int bad =
          int{std::isnan(d.x[i])} | int{std::isnan(d.y[i])} | int{std::isnan(d.radius[i])};
      nan |= bad != 0;
      xmin = std::min(xmin, d.x[i]);
      xmax = std::max(xmax, d.x[i]);
      ymin = std::min(ymin, d.y[i]);
      ymax = std::max(ymax, d.y[i]);
      rlo = std::min(rlo, d.radius[i]);
      rhi = std::max(rhi, d.radius[i]);
    }
    f.x0 = xmin;
    f.y0 = ymin;
    f.width = xmax - xmin;
    f.height = ymax - ymin;
    f.extent = std::max(f.width, f.height);
    f.rmin = rlo;
    f.rmax = rhi;
    f.finite = !nan && std::isfinite(f.extent) && std::isfinite(rhi) && rlo > 0;
    return f;
  }

  // Conservative reach of a disc of radius r at frame coordinates of magnitude <= mag.
  double reach(double r, double mag = 0) const {
    return r * (1 + 0x1p-30) + (extent + mag + r) * 0x1p-40;
  }
};

// Sorts 64-bit words by their bits [lo_bit, hi_bit) (stable, least significant digit first).
// Used with the key in the high word and a row in the low word. The digits are as few as keys
// of up to 12 bits a pass allow, of equal width: a 23-bit key takes two passes of 12 bits, not
// three of 11 (the counts, 16 KB, stay in the first-level cache).
// With an executor the passes run in chunks of kRadixChunk on its threads: each chunk counts its
// digits, the chunks' places follow in (digit, chunk) order and each chunk scatters its words in
// order, so the result is the one-thread sort's. Chunks of 8,192 words scattered into each
// other's cache lines on two threads and made a sort of 10^6 words slower than one thread.
inline constexpr std::size_t kRadixChunk = 65536;
struct RadixScratch {
  std::vector<uint64_t> tmp;     // the words between passes
  std::vector<uint32_t> place;   // per chunk and digit: its count, then its next place
  std::vector<uint32_t> digits;  // per digit: the words of every chunk, then the running place
};
inline void radix_sort(std::vector<uint64_t>& a, RadixScratch& s, int lo_bit, int hi_bit,
                       Executor* ex = nullptr) {
  constexpr int kMaxDigit = 12;
  const int bits = std::max(hi_bit - lo_bit, 1);
  const int passes = (bits + kMaxDigit - 1) / kMaxDigit;
  const int digit = (bits + passes - 1) / passes;
  const std::size_t buckets = std::size_t{1} << digit;
  const std::size_t n = a.size();
  const std::size_t chunk = ex ? kRadixChunk : std::max<std::size_t>(n, 1);
  const std::size_t chunks = std::max<std::size_t>((n + chunk - 1) / chunk, 1);
  auto each = [&](auto&& body) {
    if (ex)
      ex->for_each_chunk(n, chunk, body);
    else
      body(std::size_t{0}, n);
  };
  s.tmp.resize(n);
  s.place.resize(chunks * buckets);
  s.digits.resize(buckets);
  for (int shift = lo_bit; shift < hi_bit; shift += digit) {
    // The last pass may be narrower: bits at and above hi_bit are not read.
    const uint64_t mask = (uint64_t{1} << std::min(digit, hi_bit - shift)) - 1;
    each([&](std::size_t b, std::size_t e) {
      uint32_t* count = s.place.data() + b / chunk * buckets;
      std::fill(count, count + buckets, 0u);
      for (std::size_t k = b; k < e; ++k) ++count[(a[k] >> shift) & mask];
    });
    // Places in (digit, chunk) order, each chunk's row of counts read in memory order.
    uint32_t* const total = s.digits.data();
    std::fill(total, total + buckets, 0u);
    for (std::size_t c = 0; c < chunks; ++c)
      for (std::size_t d = 0; d < buckets; ++d) total[d] += s.place[c * buckets + d];
    uint32_t sum = 0;
    for (std::size_t d = 0; d < buckets; ++d) {
      const uint32_t k = total[d];
      total[d] = sum;
      sum += k;
    }
    for (std::size_t c = 0; c < chunks; ++c)
      for (std::size_t d = 0; d < buckets; ++d) {
        const uint32_t k = s.place[c * buckets + d];
        s.place[c * buckets + d] = total[d];
        total[d] += k;
      }
    each([&](std::size_t b, std::size_t e) {
      uint32_t* at = s.place.data() + b / chunk * buckets;
      for (std::size_t k = b; k < e; ++k) s.tmp[at[(a[k] >> shift) & mask]++] = a[k];
    });
    a.swap(s.tmp);
  }
}

// Number of bits needed to hold values < n (n >= 1).
inline int bits_for(uint64_t n) {
  int b = 0;
  while (b < 64 && (n - 1) >> b) ++b;
  return b;
}

// The canonical pair order every method returns: (i, j), i < j, sorted, no duplicates.
inline void finish_pairs(PairList& pairs) {
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
}

inline std::pair<uint32_t, uint32_t> ordered(uint32_t a, uint32_t b) {
  return a < b ? std::pair{a, b} : std::pair{b, a};
}

}  // namespace crowddb::index
