#include "steer/streams.hpp"

#include <algorithm>
#include <cmath>

#include "util/executor.hpp"

namespace crowddb::steer {
namespace {

constexpr std::size_t kStreamGrain = 1024;  // rows per chunk of the marking

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
  // Per row, in parallel (each chunk writes its own rows and list entries): the meetings, and
  // whom the others follow.
  ex.for_each_chunk(n, kStreamGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      marked[i] = at_meeting(v, i);
      double ux, uy;
      if (marked[i] || !unit_wish(v, i, ux, uy)) {
        std::fill(out.follows.begin() + nb.offset[i], out.follows.begin() + nb.offset[i + 1], 0);
        continue;
      }
      for (uint32_t a = nb.offset[i]; a < nb.offset[i + 1]; ++a)
        out.follows[a] = follows(v, i, nb.row[a], ux, uy);
    }
  });
  // The followers of each row (the "follows" edges reversed), by counting. Rows at a meeting
  // have no edges (their follows stay 0), and where nearly everyone is at one, as in an
  // airport, skipping them saves most of the pass.
  std::vector<uint32_t>& offset = out.follower_offset;
  offset.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (!marked[i])
      for (uint32_t a = nb.offset[i]; a < nb.offset[i + 1]; ++a)
        offset[nb.row[a] + 1] += out.follows[a];
  for (std::size_t j = 0; j < n; ++j) offset[j + 1] += offset[j];
  out.follower.resize(offset[n]);
  out.cursor.assign(offset.begin(), offset.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    if (!marked[i])
      for (uint32_t a = nb.offset[i]; a < nb.offset[i + 1]; ++a)
        if (out.follows[a]) out.follower[out.cursor[nb.row[a]]++] = static_cast<uint32_t>(i);
  // Breadth first from the meetings: the set reached does not depend on the order. Meetings
  // nobody follows are counted, not queued (where nearly everyone is at a meeting, queueing
  // them all was most of this pass).
  out.queue.clear();
  std::size_t idle_meetings = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!marked[i]) continue;
    if (offset[i] < offset[i + 1])
      out.queue.push_back(static_cast<uint32_t>(i));
    else
      ++idle_meetings;
  }
  for (std::size_t q = 0; q < out.queue.size(); ++q) {
    const uint32_t j = out.queue[q];
    for (uint32_t f = offset[j]; f < offset[j + 1]; ++f) {
      const uint32_t i = out.follower[f];
      if (marked[i]) continue;
      marked[i] = 1;
      out.queue.push_back(i);
    }
  }
  out.count = idle_meetings + out.queue.size();
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
