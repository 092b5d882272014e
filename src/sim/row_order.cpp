#include "sim/row_order.hpp"

#include <algorithm>
#include <cmath>

#include "index/collision_common.hpp"  // radix_sort, bits_for
#include "util/executor.hpp"

namespace crowddb::sim {
namespace {

constexpr std::size_t kOrderGrain = 16384;      // rows per chunk of the passes over the table
constexpr std::size_t kParallelSort = 1 << 15;  // from this many rows, sorted in kPieces pieces
constexpr std::size_t kPieces = 8;

// The bits of v spread to the even positions of the result.
uint64_t spread(uint32_t v) {
  uint64_t x = v;
  x = (x | (x << 16)) & 0x0000ffff0000ffffull;
  x = (x | (x << 8)) & 0x00ff00ff00ff00ffull;
  x = (x | (x << 4)) & 0x0f0f0f0f0f0f0f0full;
  x = (x | (x << 2)) & 0x3333333333333333ull;
  x = (x | (x << 1)) & 0x5555555555555555ull;
  return x;
}

uint32_t cell(double v, double lo) {
  // Coordinates lie within ±10^9 m (kMaxCoordinate): the offset fits 32 bits in metres.
  return static_cast<uint32_t>(std::clamp(std::floor(v - lo), 0.0, 4294967295.0));
}

// body(begin, end) over [0, count) in chunks of `grain` on ex's threads, or in one call.
template <class F>
void each_chunk(Executor* ex, std::size_t count, std::size_t grain, const F& body) {
  if (ex)
    ex->for_each_chunk(count, grain, body);
  else
    body(0, count);
}

// Each row's Z-curve key from the table's lowest corner, into `keys`; key_max: the largest.
void keys_of(const AgentTable& t, Executor* ex, std::vector<uint64_t>& keys, uint64_t& key_max) {
  const std::size_t n = t.size();
  // The lowest corner: a minimum per chunk, then over the chunks (exact, so any split).
  const std::size_t chunks = (n + kOrderGrain - 1) / kOrderGrain;
  std::vector<double> cx(chunks, INFINITY), cy(chunks, INFINITY);
  each_chunk(ex, n, kOrderGrain, [&](std::size_t b, std::size_t e) {
    double xlo = INFINITY, ylo = INFINITY;
    for (std::size_t i = b; i < e; ++i) {
      xlo = std::min(xlo, t.x[i]);
      ylo = std::min(ylo, t.y[i]);
    }
    cx[b / kOrderGrain] = xlo;
    cy[b / kOrderGrain] = ylo;
  });
  double xlo = INFINITY, ylo = INFINITY;
  for (std::size_t c = 0; c < chunks; ++c) {
    xlo = std::min(xlo, cx[c]);
    ylo = std::min(ylo, cy[c]);
  }
  keys.resize(n);  // every entry written below
  std::vector<uint64_t> chunk_max(chunks, 0);
  each_chunk(ex, n, kOrderGrain, [&](std::size_t b, std::size_t e) {
    uint64_t m = 0;  // the chunk's, written once at its end (the entries share cache lines)
    for (std::size_t i = b; i < e; ++i) {
      keys[i] = spread(cell(t.x[i], xlo)) | (spread(cell(t.y[i], ylo)) << 1);
      m = std::max(m, keys[i]);
    }
    chunk_max[b / kOrderGrain] = m;
  });
  key_max = 0;
  for (const uint64_t m : chunk_max) key_max = std::max(key_max, m);
}

// The comparison sort's entries: ordered by key, then id (unique, so the order is total).
struct Keyed {
  uint64_t key, id;
  uint32_t row;
};

bool key_then_id(const Keyed& a, const Keyed& b) {
  return a.key < b.key || (a.key == b.key && a.id < b.id);
}

std::vector<Keyed> keyed(const AgentTable& t, const std::vector<uint64_t>& keys, Executor* ex) {
  std::vector<Keyed> e(keys.size());
  each_chunk(ex, keys.size(), kOrderGrain, [&](std::size_t b, std::size_t end) {
    for (std::size_t i = b; i < end; ++i) e[i] = {keys[i], t.id[i], static_cast<uint32_t>(i)};
  });
  return e;
}

std::vector<uint32_t> rows_of(const std::vector<Keyed>& e, Executor* ex) {
  std::vector<uint32_t> order(e.size());
  each_chunk(ex, e.size(), kOrderGrain, [&](std::size_t b, std::size_t end) {
    for (std::size_t i = b; i < end; ++i) order[i] = e[i].row;
  });
  return order;
}

}  // namespace

std::vector<uint32_t> curve_order(const AgentTable& t, Executor* ex) {
  CurveScratch scratch;
  std::vector<uint32_t> order;
  curve_order(t, ex, scratch, order);
  return order;
}

void curve_order(const AgentTable& t, Executor* ex, CurveScratch& scratch,
                 std::vector<uint32_t>& order) {
  const std::size_t n = t.size();
  order.resize(n);  // every entry written below
  if (n == 0) return;
  uint64_t key_max = 0;
  std::vector<uint64_t>& keys = scratch.keys;
  keys_of(t, ex, keys, key_max);
  if (key_max >> 32 == 0) {
    // Keys of 32 bits at most (a world within 65 km, 2^16 cells of 1 m a side): a radix sort of
    // (key << 32 | row) words by their key bits, stable, so rows of one key stay in row order,
    // then each run of one key in id order. The order (key, id) is total, so this is the
    // comparison sort's result, in a few passes over the words instead of a sort whose
    // comparisons are coin tosses to the predictor. A reorder at airport-20k on two threads took
    // 4.2 ms before, 3.9 now; at 10^6 agents 188 and 180 ms, the rest being the columns'
    // permutation and what the model and the grids keep per row.
    std::vector<uint64_t>& words = scratch.words;
    words.resize(n);  // every entry written below
    each_chunk(ex, n, kOrderGrain, [&](std::size_t b, std::size_t end) {
      for (std::size_t i = b; i < end; ++i) words[i] = keys[i] << 32 | i;
    });
    index::radix_sort(words, scratch.radix, 32, 32 + index::bits_for(key_max + 1),
                      ex && n >= kParallelSort ? ex : nullptr);
    each_chunk(ex, n, kOrderGrain, [&](std::size_t b, std::size_t end) {
      for (std::size_t i = b; i < end; ++i) order[i] = static_cast<uint32_t>(words[i]);
    });
    // Runs of one key (agents sharing a 1 m cell): by id. Short where the crowd is, a few rows a
    // cell; std::sort keeps a run of everyone in one cell O(n log n).
    for (std::size_t s = 0; s < n;) {
      std::size_t f = s + 1;
      while (f < n && words[f] >> 32 == words[s] >> 32) ++f;
      if (f - s > 1)
        std::sort(order.begin() + static_cast<std::ptrdiff_t>(s),
                  order.begin() + static_cast<std::ptrdiff_t>(f),
                  [&](uint32_t a, uint32_t b) { return t.id[a] < t.id[b]; });
      s = f;
    }
    return;
  }
  // Wider keys: a comparison sort. The order is total, so the sorted sequence is one: sorting
  // pieces on every thread and merging them gives what one sort gives.
  std::vector<Keyed> e = keyed(t, keys, ex);
  const std::size_t piece =
      ex && ex->threads() > 1 && n >= kParallelSort ? (n + kPieces - 1) / kPieces : n;
  each_chunk(ex, n, std::max<std::size_t>(piece, 1), [&](std::size_t b, std::size_t end) {
    std::sort(e.begin() + static_cast<std::ptrdiff_t>(b),
              e.begin() + static_cast<std::ptrdiff_t>(end), key_then_id);
  });
  for (std::size_t width = piece; width < n; width *= 2) {
    const std::size_t pairs = (n + 2 * width - 1) / (2 * width);
    each_chunk(ex, pairs, 1, [&](std::size_t pb, std::size_t pe) {
      for (std::size_t p = pb; p < pe; ++p) {
        const std::size_t lo = p * 2 * width, mid = std::min(n, lo + width),
                          hi = std::min(n, lo + 2 * width);
        std::inplace_merge(e.begin() + static_cast<std::ptrdiff_t>(lo),
                           e.begin() + static_cast<std::ptrdiff_t>(mid),
                           e.begin() + static_cast<std::ptrdiff_t>(hi), key_then_id);
      }
    });
  }
  order = rows_of(e, ex);
}

std::vector<uint32_t> curve_order_naive(const AgentTable& t) {
  uint64_t key_max = 0;
  std::vector<uint64_t> keys;
  keys_of(t, nullptr, keys, key_max);
  std::vector<Keyed> e = keyed(t, keys, nullptr);
  std::sort(e.begin(), e.end(), key_then_id);
  return rows_of(e, nullptr);
}

}  // namespace crowddb::sim
