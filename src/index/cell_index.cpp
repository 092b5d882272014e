#include "index/cell_index.hpp"

#include <algorithm>
#include <cmath>

#include "world/geometry.hpp"

namespace crowddb::index {
namespace {

// Rows per chunk of a parallel build's own passes (keys, unpacking, copies), from two chunks on:
// 2 * 10^4 rows are built in three. (The radix sort's chunks are larger: kRadixChunk.)
constexpr std::size_t kChunk = 8192;

}  // namespace

int64_t CellIndex::cell_of(double u) const {
  const double c = std::floor(u / cell_);
  if (!(c > 0)) return 0;
  if (c >= static_cast<double>(W_ - 1)) return W_ - 1;
  return static_cast<int64_t>(c);
}

int64_t CellIndex::row_of(double v) const {
  const double c = std::floor(v / cell_);
  if (!(c > 0)) return 0;
  if (c >= static_cast<double>(H_ - 1)) return H_ - 1;
  return static_cast<int64_t>(c);
}

void CellIndex::build(const DiscView& d, std::span<const uint32_t> rows, const Frame& frame,
                      double R, Executor* ex) {
  frame_ = frame;
  R_ = R;
  const std::size_t n = rows.empty() ? d.n : rows.size();
  auto row_at = [&](std::size_t k) { return rows.empty() ? static_cast<uint32_t>(k) : rows[k]; };

  // Cell side: the padded reach of the widest pair, widened so that each axis has <= 2^30 cells.
  cell_ = std::max(2 * frame.reach(R), frame.extent * 0x1p-30);
  if (!(cell_ > 0)) cell_ = 1;
  auto cells = [&](double len) {
    const double c = std::floor(len / cell_) + 1;
    return c >= 0x1p30 ? (int64_t{1} << 30) + 1 : static_cast<int64_t>(c);
  };
  W_ = cells(frame.width);
  H_ = cells(frame.height);

  key_.resize(n);
  row_.resize(n);
  // Chunked passes pay from a few chunks per thread on.
  Executor* const par = ex && ex->threads() > 1 && n >= 2 * kChunk ? ex : nullptr;
  auto each = [&](auto&& body) {
    if (par)
      par->for_each_chunk(n, kChunk, body);
    else
      body(std::size_t{0}, n);
  };
  const auto space = static_cast<uint64_t>(W_) * static_cast<uint64_t>(H_);
  const int key_bits = bits_for(space);
  if (key_bits <= 32) {
    // key in the high word, the position in `rows` in the low word: one radix sort over the key.
    auto& packed = packed_;
    packed.resize(n);
    each([&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const uint32_t i = row_at(k);
        const auto key =
            static_cast<uint64_t>(row_of(d.y[i] - frame.y0) * W_ + cell_of(d.x[i] - frame.x0));
        packed[k] = key << 32 | k;
      }
    });
    radix_sort(packed, radix_, 32, 32 + key_bits, n >= CellIndex::kParallelRadix ? par : nullptr);
    each([&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        key_[k] = packed[k] >> 32;
        row_[k] = row_at(packed[k] & 0xffffffffu);
      }
    });
  } else {
    std::vector<std::pair<uint64_t, uint32_t>> kv(n);
    for (std::size_t k = 0; k < n; ++k) {
      const uint32_t i = row_at(k);
      kv[k] = {static_cast<uint64_t>(row_of(d.y[i] - frame.y0) * W_ + cell_of(d.x[i] - frame.x0)),
               i};
    }
    std::sort(kv.begin(), kv.end());
    for (std::size_t k = 0; k < n; ++k) {
      key_[k] = kv[k].first;
      row_[k] = kv[k].second;
    }
  }
  x_.resize(n);
  y_.resize(n);
  r_.resize(n);
  each([&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const uint32_t i = row_[k];
      x_[k] = d.x[i];
      y_[k] = d.y[i];
      r_[k] = d.radius[i];
    }
  });
}

void CellIndex::pairs(PairList& out, uint64_t& tests) const {
  tests += for_each_candidate([&](std::size_t a, std::size_t b) {
    if (discs_overlap(x_[b] - x_[a], y_[b] - y_[a], r_[a] + r_[b]))
      out.push_back(ordered(row_[a], row_[b]));
  });
}

}  // namespace crowddb::index
