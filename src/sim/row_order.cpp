#include "sim/row_order.hpp"

#include <algorithm>
#include <cmath>

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

}  // namespace

std::vector<uint32_t> curve_order(const AgentTable& t, Executor* ex) {
  const std::size_t n = t.size();
  if (n == 0) return {};
  const auto run = [&](std::size_t count, std::size_t grain, const auto& body) {
    if (ex)
      ex->for_each_chunk(count, grain, body);
    else
      body(0, count);
  };
  // The lowest corner: a minimum per chunk, then over the chunks (exact, so any split).
  const std::size_t chunks = (n + kOrderGrain - 1) / kOrderGrain;
  std::vector<double> cx(chunks, INFINITY), cy(chunks, INFINITY);
  run(n, kOrderGrain, [&](std::size_t b, std::size_t e) {
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
  struct Entry {
    uint64_t key, id;
    uint32_t row;
  };
  std::vector<Entry> e(n);
  run(n, kOrderGrain, [&](std::size_t b, std::size_t end) {
    for (std::size_t i = b; i < end; ++i)
      e[i] = {spread(cell(t.x[i], xlo)) | (spread(cell(t.y[i], ylo)) << 1), t.id[i],
              static_cast<uint32_t>(i)};
  });
  // Ids are unique, so the order is total and the sorted sequence one: sorting pieces on every
  // thread and merging them gives what one sort gives.
  const auto less = [](const Entry& a, const Entry& b) {
    return a.key < b.key || (a.key == b.key && a.id < b.id);
  };
  const std::size_t piece =
      ex && ex->threads() > 1 && n >= kParallelSort ? (n + kPieces - 1) / kPieces : n;
  run(n, std::max<std::size_t>(piece, 1), [&](std::size_t b, std::size_t end) {
    std::sort(e.begin() + static_cast<std::ptrdiff_t>(b),
              e.begin() + static_cast<std::ptrdiff_t>(end), less);
  });
  for (std::size_t width = piece; width < n; width *= 2) {
    const std::size_t pairs = (n + 2 * width - 1) / (2 * width);
    run(pairs, 1, [&](std::size_t pb, std::size_t pe) {
      for (std::size_t p = pb; p < pe; ++p) {
        const std::size_t lo = p * 2 * width, mid = std::min(n, lo + width),
                          hi = std::min(n, lo + 2 * width);
        std::inplace_merge(e.begin() + static_cast<std::ptrdiff_t>(lo),
                           e.begin() + static_cast<std::ptrdiff_t>(mid),
                           e.begin() + static_cast<std::ptrdiff_t>(hi), less);
      }
    });
  }
  std::vector<uint32_t> order(n);
  run(n, kOrderGrain, [&](std::size_t b, std::size_t end) {
    for (std::size_t i = b; i < end; ++i) order[i] = e[i].row;
  });
  return order;
}

}  // namespace crowddb::sim
