// The naive (nested-loop) access paths: the oracles every index is tested against.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "plan/access_path.hpp"
#include "util/executor.hpp"
#include "world/geometry.hpp"

namespace crowddb {

class FtcNaive final : public FtcPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, double horizon, std::span<FtcHit> out,
           Executor& ex, QueryStats& stats) override;
};

class FieldNaive final : public FieldPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, const PotentialSpec& spec,
           FieldColumns& out, Executor& ex, QueryStats& stats) override;
  void probe(std::span<const Vec2> points, const DiscView& sources, const StaticScene& scene,
             const PotentialSpec& spec, FieldColumns& out, Executor& ex,
             QueryStats& stats) override;
};

class CollisionNaive final : public CollisionPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, CollisionPairs& out, Executor& ex,
           QueryStats& stats) override;
};

class NeighbourNaive final : public NeighbourPath {
 public:
  void run(const DiscView& discs, std::span<const uint32_t> queries, double range, uint32_t k,
           NeighbourLists& out, Executor& ex, QueryStats& stats) override;
};

class FeatureNaive final : public FeaturePath {
 public:
  void run(const DiscView& points, std::span<const double> reach, const StaticScene& scene,
           FeatureLists& out, Executor& ex, QueryStats& stats) override;
};

// How many of dist[0, m) are nearer than d, counted two at a time in a 16-byte vector (SSE2 on
// x86-64), without a branch per entry (which of two is nearer is a coin toss to the predictor).
// For odd m, dist[m] must be readable and never nearer (INFINITY). The ranking of neighbour
// lists: NearestK's unbounded lists and the neighbour grid's hinted rows.
inline uint32_t count_nearer(const double* dist, uint32_t m, double d) {
  typedef double V2d __attribute__((vector_size(16)));
  typedef int64_t V2l __attribute__((vector_size(16)));
  V2l nearer = {0, 0};  // -1 per lane for each one nearer
  const V2d dv = {d, d};
  for (uint32_t f = 0; f < m; f += 2) {
    V2d v;
    __builtin_memcpy(&v, dist + f, sizeof v);
    nearer += v < dv;
  }
  return static_cast<uint32_t>(-(nearer[0] + nearer[1]));
}

// The k-nearest selection every neighbour method uses, so that all agree bit for bit: candidates
// are offered one at a time; the list keeps the best k by (dist2, id), or with k = 0 every
// candidate, sorted the same way by finish(). Up to kInline entries live in the object itself
// (the usual k of a steering query), so the hot loop touches no heap.
class NearestK {
 public:
  static constexpr uint32_t kInline = 32;

  void reset(uint32_t k) {
    k_ = k;
    n_ = 0;
    small_ = k != 0 && k <= kInline;
    rows_.clear();
    d2_.clear();
    ids_.clear();
  }
  // Room for n candidates in an unbounded (k = 0) or long (k > kInline) list, kept over resets.
  void reserve(std::size_t n) {
    rows_.reserve(n);
    d2_.reserve(n);
    ids_.reserve(n);
  }
  std::size_t size() const { return small_ ? n_ : rows_.size(); }
  bool full() const { return k_ && size() == k_; }
  // Every candidate strictly farther than this is rejected (k = 0: none is).
  double bound() const {
    if (!full()) return INFINITY;
    return small_ ? sd2_[n_ - 1] : d2_.back();
  }
  [[gnu::always_inline]] void offer(uint32_t row, uint64_t id, double d2) {
    if (small_) {
      offer_into(srows_, sd2_, sids_, n_, row, id, d2);
      return;
    }
    if (k_ == 0) {
      rows_.push_back(row);
      d2_.push_back(d2);
      ids_.push_back(id);
      return;
    }
    const bool was_full = full();
    if (was_full && !better(d2, id, d2_.back(), ids_.back())) return;
    if (!was_full) {  // room for one more: offer_into fills the new slot
      rows_.push_back(0);
      d2_.push_back(0);
      ids_.push_back(0);
    }
    std::size_t n = rows_.size() - (was_full ? 0 : 1);
    offer_into(rows_.data(), d2_.data(), ids_.data(), n, row, id, d2);
  }
  // Sorts an unbounded (k = 0) list; a bounded one is kept sorted already.
  void finish() {
    if (k_ != 0 || rows_.size() < 2) return;
    sort_unbounded();
  }
  std::span<const uint32_t> rows() const {
    return small_ ? std::span<const uint32_t>(srows_, n_) : std::span<const uint32_t>(rows_);
  }
  std::span<const double> dist2() const {
    return small_ ? std::span<const double>(sd2_, n_) : std::span<const double>(d2_);
  }

 private:
  // Out of line (query/neighbours_naive.cpp): the bounded queries' hot loops inline finish()
  // and never come here.
  void sort_unbounded();
  // Unbounded lists up to this long are sorted by counting each entry's rank.
  static constexpr std::size_t kRankSort = 64;

  static bool better(double d2, uint64_t id, double d2b, uint64_t idb) {
    return d2 < d2b || (d2 == d2b && id < idb);
  }
  // Sorts rows_ and d2_ (m <= kRankSort) by rank: the number of entries nearer than each,
  // counted two at a time in a 16-byte vector (SSE2 on x86-64), and the ids where distances tie.
  // Which of two is nearer is a coin toss to the branch predictor, and std::sort's comparisons took
  // a mispredicted jump each (the cfsm model's range query sorts every row's list, every tick). The
  // same order as std::sort's when the keys (dist2, id) are distinct; false (nothing moved) when
  // two are not, and the caller sorts the usual way.
  bool rank_sort();
  // Inserts into the sorted arrays holding n entries (capacity k_), dropping the worst when full.
  void offer_into(uint32_t* rows, double* d2s, uint64_t* ids, std::size_t& n, uint32_t row,
                  uint64_t id, double d2) const {
    if (n == k_) {
      if (!better(d2, id, d2s[n - 1], ids[n - 1])) return;
      --n;
    }
    std::size_t i = n++;
    for (; i > 0 && better(d2, id, d2s[i - 1], ids[i - 1]); --i) {
      rows[i] = rows[i - 1];
      d2s[i] = d2s[i - 1];
      ids[i] = ids[i - 1];
    }
    rows[i] = row;
    d2s[i] = d2;
    ids[i] = id;
  }

  uint32_t k_ = 0;
  bool small_ = false;
  std::size_t n_ = 0;
  uint32_t srows_[kInline];
  double sd2_[kInline];
  uint64_t sids_[kInline];
  std::vector<uint32_t> rows_;
  std::vector<double> d2_;
  std::vector<uint64_t> ids_;
  std::vector<uint32_t> order_, scratch_rows_;
  std::vector<double> scratch_d2_;
};

// Gathers per-chunk lists into one CSR table in query order (every method shares it).
struct ListChunks {
  std::vector<std::vector<uint32_t>> counts, items;
  std::vector<std::vector<double>> d2;
  void reset(std::size_t chunks) {
    counts.assign(chunks, {});
    items.assign(chunks, {});
    d2.assign(chunks, {});
  }
  // One chunk's lists, built by its body in a local and put in place once at its end: appended
  // to per row in place, neighbouring chunks' vector headers share cache lines between threads.
  struct Chunk {
    std::vector<uint32_t> counts, items;
    std::vector<double> d2;
  };
  void put(std::size_t c, Chunk&& chunk) {
    counts[c] = std::move(chunk.counts);
    items[c] = std::move(chunk.items);
    d2[c] = std::move(chunk.d2);
  }
  // Concatenates the chunks' lists into out's CSR in chunk order. With an executor, and from
  // kParallelGather rows, the chunks are copied on its threads (each into its own place; the same
  // result; fewer rows cost more to hand out than to copy).
  static constexpr std::size_t kParallelGather = 8192;
  template <class Lists>
  void gather(Lists& out, std::vector<uint32_t> Lists::*items_member,
              Executor* ex = nullptr) const {
    const std::size_t chunks = counts.size();
    // Where each chunk's rows, items and distances (none when the caller asked for none) begin.
    std::vector<std::size_t> row0(chunks + 1, 0), item0(chunks + 1, 0), d20(chunks + 1, 0);
    for (std::size_t c = 0; c < chunks; ++c) {
      row0[c + 1] = row0[c] + counts[c].size();
      item0[c + 1] = item0[c] + items[c].size();
      d20[c + 1] = d20[c] + d2[c].size();
    }
    std::vector<uint32_t>& all = out.*items_member;
    out.offset.resize(row0[chunks] + 1);
    out.offset[0] = 0;
    all.resize(item0[chunks]);
    out.dist2.resize(d20[chunks]);
    auto copy = [&](std::size_t b, std::size_t e) {
      for (std::size_t c = b; c < e; ++c) {
        auto at = static_cast<uint32_t>(item0[c]);
        uint32_t* const offsets = out.offset.data() + row0[c] + 1;
        for (std::size_t k = 0; k < counts[c].size(); ++k) offsets[k] = at += counts[c][k];
        std::copy(items[c].begin(), items[c].end(),
                  all.begin() + static_cast<std::ptrdiff_t>(item0[c]));
        std::copy(d2[c].begin(), d2[c].end(),
                  out.dist2.begin() + static_cast<std::ptrdiff_t>(d20[c]));
      }
    };
    if (ex && row0[chunks] >= kParallelGather)
      ex->for_each_chunk(chunks, 1, copy);
    else
      copy(0, chunks);
  }
};

// The exact disc-against-obstacle tests of a collision query. Every method calls these for
// every (disc, obstacle) candidate it keeps, so that all methods agree bit for bit.
inline bool disc_hits_circle(const CircleObstacle& c, double x, double y, double r) {
  return discs_overlap(c.x - x, c.y - y, r + c.radius);
}
// The bounding-box rejection is part of the definition (as the naive loop applies it), so an
// index that pre-filters more loosely must still call this, not disc_overlaps_polygon directly.
inline bool disc_misses_box(const StaticScene::Box& b, double x, double y, double r) {
  return x + r <= b.xmin || x - r >= b.xmax || y + r <= b.ymin || y - r >= b.ymax;
}
inline bool disc_hits_polygon(const PolygonObstacle& p, const StaticScene::Box& b, double x,
                              double y, double r) {
  return !disc_misses_box(b, x, y, r) && disc_overlaps_polygon(p.vertices, x, y, r);
}

// The obstacle half of a collision query (disc against circles and polygons), shared by every
// collision method: obstacles are few and static, so methods differ only in the disc-disc part.
// Appends (row, obstacle) for rows [begin, end) in row order.
void disc_obstacle_overlaps(const DiscView& discs, const StaticScene& scene, std::size_t begin,
                            std::size_t end, std::vector<std::pair<uint32_t, Collider>>& out);

}  // namespace crowddb
