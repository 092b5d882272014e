#include "steer/streams.hpp"

#include <algorithm>
#include <cmath>

#include "index/collision_common.hpp"
#include "util/executor.hpp"

namespace crowddb::steer {
namespace {

constexpr std::size_t kStreamGrain = 1024;  // rows per chunk of the marking
constexpr std::size_t kRadixEdges = 256;    // fewer edges are sorted by comparisons
// With at least one "follows" edge per this many rows, the search looks followers up in a table
// of the rows (O(rows + edges)) rather than by binary searches (O(reached log edges)).
constexpr std::size_t kEdgesPerRowForTable = 16;

}  // namespace

// A neighbour bound for another goal wants to go more than 60 degrees away from i's wish
// (dot < cos 60 |w_i| |w_j|, in squares).
bool at_meeting(const StreamView& v, std::size_t i) {
  const NeighbourLists& nb = *v.nb;
  const double wix = v.wish_x[i], wiy = v.wish_y[i];
  const double wi2 = wix * wix + wiy * wiy;
  if (wi2 == 0) return false;
  // Every neighbour asked, without branches (which one answers is a coin toss to the predictor);
  // the tests as ints: & and | on them is meant.
  int meets = 0;
  for (uint32_t a = nb.offset[i]; a < nb.offset[i + 1]; ++a) {
    const uint32_t j = nb.row[a];
    const double wjx = v.wish_x[j], wjy = v.wish_y[j];
    const double wj2 = wjx * wjx + wjy * wjy;
    const double dot = wix * wjx + wiy * wjy;
    meets |= int{v.goal[j] != v.goal[i]} &  // another stream
             int{!(wj2 == 0)} &             // walking (standing: no stream)
             (int{dot < 0} | int{dot * dot < kSameWay * kSameWay * wi2 * wj2});
  }
  return meets != 0;
}

namespace {

// Row i's unit wish, or false when it has none.
bool unit_wish(const StreamView& v, std::size_t i, double& ux, double& uy) {
  const double w = std::sqrt(v.wish_x[i] * v.wish_x[i] + v.wish_y[i] * v.wish_y[i]);
  if (w == 0) return false;
  ux = v.wish_x[i] / w;
  uy = v.wish_y[i] / w;
  return true;
}

}  // namespace

void mark_meetings(const StreamView& v, StreamMarks& out, Executor& ex) {
  const NeighbourLists& nb = *v.nb;
  const std::size_t n = nb.queries();
  std::vector<uint8_t>& marked = out.marked;
  marked.resize(n);                   // every row written below
  out.follows.resize(nb.row.size());  // every entry written below
  // Per row, in parallel (each chunk writes its own rows and list entries): the meetings, whom
  // the others follow, and per chunk the "follows" edges (followed << 32 | follower, in row
  // order) and the meetings counted.
  const std::size_t chunks = (n + kStreamGrain - 1) / kStreamGrain;
  out.chunk_edges.resize(chunks);
  out.chunk_meetings.resize(chunks);  // every chunk writes its own
  ex.for_each_chunk(n, kStreamGrain, [&](std::size_t b, std::size_t e) {
    std::vector<uint64_t> edges = std::move(out.chunk_edges[b / kStreamGrain]);
    edges.clear();
    std::size_t meetings = 0;
    for (std::size_t i = b; i < e; ++i) {
      marked[i] = at_meeting(v, i);
      meetings += marked[i];
      double ux, uy;
      if (marked[i] || !unit_wish(v, i, ux, uy)) {
        std::fill(out.follows.begin() + nb.offset[i], out.follows.begin() + nb.offset[i + 1], 0);
        continue;
      }
      for (uint32_t a = nb.offset[i]; a < nb.offset[i + 1]; ++a) {
        out.follows[a] = follows(v, i, nb.row[a], ux, uy);
        if (out.follows[a]) edges.push_back(uint64_t{nb.row[a]} << 32 | i);
      }
    }
    out.chunk_edges[b / kStreamGrain] = std::move(edges);
    out.chunk_meetings[b / kStreamGrain] = meetings;
  });
  std::size_t meetings = 0;
  for (std::size_t m : out.chunk_meetings) meetings += m;
  out.edges.clear();
  for (const std::vector<uint64_t>& c : out.chunk_edges)
    out.edges.insert(out.edges.end(), c.begin(), c.end());
  // Breadth first from the meetings, over the edges reversed: the set reached does not depend on
  // the order. The edges sorted by the row followed (a radix sort: O(E)) give each row's
  // followers as a run. Where nearly everyone is at a meeting, as in an airport's first minutes,
  // there are few edges, found by binary searches without a per-row array; many edges (a jam)
  // are looked up in a table of the rows (below).
  std::vector<uint64_t>& edges = out.edges;
  out.queue.clear();
  out.by_table = false;
  if (meetings > 0 && !edges.empty()) {
    index::radix_sort(edges, out.radix, 32, 32 + index::bits_for(n));
    // A row's followers: by two binary searches over the edges while they are few; once there
    // are many (a crowd jammed round its goals: most rows behind a meeting, queues long), by a
    // table of where each row's run begins, one pass over the rows and the edges. The searches,
    // one pair per row reached, each a chain of cache misses, were the stage's serial half there
    // (airport-20k's last 900 of 1,000 ticks).
    const bool table = edges.size() >= n / kEdgesPerRowForTable;
    out.by_table = table;
    if (table) {
      out.start.resize(n + 1);
      std::size_t k = 0;
      for (std::size_t j = 0; j <= n; ++j) {
        while (k < edges.size() && (edges[k] >> 32) < j) ++k;
        out.start[j] = static_cast<uint32_t>(k);
      }
    }
    const auto followers = [&](uint32_t j) {
      if (table) return std::pair{edges.begin() + out.start[j], edges.begin() + out.start[j + 1]};
      const auto lo = std::lower_bound(edges.begin(), edges.end(), uint64_t{j} << 32);
      const auto hi = std::lower_bound(lo, edges.end(), (uint64_t{j} + 1) << 32);
      return std::pair{lo, hi};
    };
    for (std::size_t k = 0; k < edges.size();) {  // the meetings somebody follows
      const auto j = static_cast<uint32_t>(edges[k] >> 32);
      if (marked[j]) out.queue.push_back(j);
      while (k < edges.size() && edges[k] >> 32 == j) ++k;
    }
    for (std::size_t q = 0; q < out.queue.size(); ++q) {
      const auto [lo, hi] = followers(out.queue[q]);
      for (auto it = lo; it != hi; ++it) {
        const auto i = static_cast<uint32_t>(*it & 0xffffffffu);
        if (marked[i]) continue;
        marked[i] = 1;
        out.queue.push_back(i);
        ++meetings;  // now counts every row marked
      }
    }
  }
  out.count = meetings;
}

void mark_meetings_naive(const StreamView& v, std::vector<uint8_t>& marked) {
  const NeighbourLists& nb = *v.nb;
  const std::size_t n = nb.queries();
  marked.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) marked[i] = at_meeting(v, i);
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t i = 0; i < n; ++i) {
      double ux, uy;
      if (marked[i] || !unit_wish(v, i, ux, uy)) continue;
      for (uint32_t a = nb.offset[i]; a < nb.offset[i + 1]; ++a) {
        if (marked[nb.row[a]] && follows(v, i, nb.row[a], ux, uy)) {
          marked[i] = 1;
          changed = true;
          break;
        }
      }
    }
  }
}

}  // namespace crowddb::steer
