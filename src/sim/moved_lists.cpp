#include "sim/moved_lists.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "index/neighbour_lanes.hpp"
#include "query/naive_paths.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::sim {
namespace {

constexpr std::size_t kListsGrain = 256;  // queries per chunk of lists_after_move
constexpr std::size_t kMoveGrain = 4096;  // rows per chunk of largest_move

}  // namespace

RowRenumbering::RowRenumbering(std::size_t n_before, std::vector<std::size_t> removed)
    : n_before_(n_before) {
  // World::remove_rows: from the highest row down, the last row moves into the removed one's
  // place. `at` holds the rows now in another place than before (place -> row before).
  std::sort(removed.begin(), removed.end(), std::greater<>());
  removed.erase(std::unique(removed.begin(), removed.end()), removed.end());
  std::map<std::size_t, uint32_t> at;
  std::size_t size = n_before;
  auto row_at = [&](std::size_t place) {
    const auto it = at.find(place);
    return it != at.end() ? it->second : static_cast<uint32_t>(place);
  };
  for (std::size_t r : removed) {
    if (r >= size) continue;  // not a row (remove_rows would not be given it)
    removed_.push_back(row_at(r));
    const std::size_t last = size - 1;
    const uint32_t moving = row_at(last);
    at.erase(last);
    if (r != last)
      at[r] = moving;
    else
      at.erase(r);
    --size;
  }
  n_now_ = size;
  std::sort(removed_.begin(), removed_.end());
  for (const auto& [place, row] : at) {
    if (place == row) continue;
    by_now_.emplace_back(static_cast<uint32_t>(place), row);
    by_before_.emplace_back(row, static_cast<uint32_t>(place));
  }
  std::sort(by_before_.begin(), by_before_.end());  // (by_now_ is in place order already)
}

uint32_t RowRenumbering::now_of(uint32_t before) const {
  const auto it = std::lower_bound(by_before_.begin(), by_before_.end(),
                                   std::pair<uint32_t, uint32_t>{before, 0});
  if (it != by_before_.end() && it->first == before) return it->second;
  if (std::binary_search(removed_.begin(), removed_.end(), before)) return kGone;
  return before;
}

uint32_t RowRenumbering::before_of(uint32_t now) const {
  const auto it =
      std::lower_bound(by_now_.begin(), by_now_.end(), std::pair<uint32_t, uint32_t>{now, 0});
  return it != by_now_.end() && it->first == now ? it->second : now;
}

void lists_after_move(const AgentTable& t, const TickMove& move, std::span<const uint32_t> queries,
                      double range, uint32_t k, NeighbourLists& out, std::vector<uint32_t>& unsure,
                      Executor& ex) {
  const std::size_t q = queries.size();
  out.offset.assign(q + 1, 0);
  out.row.clear();
  out.dist2.clear();
  unsure.clear();
  const NeighbourLists* lists = move.lists.lists;
  const std::size_t before = move.rows.before();
  const bool usable = lists && lists->queries() == before && move.x.size() == before &&
                      move.y.size() == before && move.rows.now() == t.size() &&
                      std::isfinite(move.move_max) && move.move_max >= 0 && range >= 0 && k > 0;
  if (!usable) {
    for (std::size_t a = 0; a < q; ++a) unsure.push_back(static_cast<uint32_t>(a));
    return;
  }
  const double range2 = move.lists.range * move.lists.range, r2 = range * range;
  const uint32_t lists_k = move.lists.k;
  // On every thread, each chunk's lists gathered in query order (ListChunks, as every neighbour
  // method does); an unsure query gets an empty list here.
  const bool d2_too = out.with_dist2;
  std::vector<uint8_t> sure(q);
  ListChunks chunks;
  chunks.reset((q + kListsGrain - 1) / kListsGrain);
  ex.for_each_chunk(q, kListsGrain, [&](std::size_t begin, std::size_t end) {
    ListChunks::Chunk mine;
    NearestK best;
    for (std::size_t a = begin; a < end; ++a) {
      const uint32_t i = queries[a];
      const uint32_t b = move.rows.before_of(i);
      const std::span<const uint32_t> listed = lists->rows_of(b);
      auto dist2_before = [&](uint32_t j) {  // as the lists rank them (steer::dist2_of)
        const double dx = move.x[j] - move.x[b], dy = move.y[j] - move.y[b];
        return dx * dx + dy * dy;
      };
      // Someone not in row i's list was at least its bound away and is now at least
      // bound - m_i - m, m_i its own move and m the farthest anyone moved.
      const double mx = t.x[i] - move.x[b], my = t.y[i] - move.y[b];
      const double moved = std::sqrt(mx * mx + my * my) + move.move_max;
      const double need = (range + moved) * (1 + 1e-9);
      // Everyone strictly closer than the list's bound is in it (NearLists).
      const double bound2 =
          lists_k > 0 && listed.size() >= lists_k ? dist2_before(listed.back()) : range2;
      const bool reaches = bound2 >= need * need;
      // Where the list does not reach the whole range (a jam: its k'-th is nearer than range
      // plus the moves), the k nearest listed can still be the answer: when the k-th of them is
      // now nearer than anyone unlisted can be, strictly (a tie would go by id), they are. In
      // the ring's knot the model's 10 nearest reach ~0.9 m and the stalemate stage asks for 6
      // within 1.1 m: every such row went to the neighbour query.
      if (!reaches && listed.size() < k) {
        mine.counts.push_back(0);
        continue;
      }
      best.reset(k);
      for (uint32_t jb : listed) {
        const uint32_t j = move.rows.now_of(jb);
        if (j == RowRenumbering::kGone) continue;
        // The neighbour methods' expression (query/neighbours_naive.cpp), on the rows now.
        const double dx = t.x[j] - t.x[i], dy = t.y[j] - t.y[i];
        const double d2 = dx * dx + dy * dy;
        if (d2 < r2) best.offer(j, t.id[j], d2);
      }
      best.finish();
      if (!reaches) {
        const double kth = best.full() ? std::sqrt(best.dist2().back()) : INFINITY;
        const double need_k = (kth + moved) * (1 + 1e-9);
        if (!(bound2 > need_k * need_k)) {
          mine.counts.push_back(0);
          continue;
        }
      }
      sure[a] = 1;
      mine.counts.push_back(static_cast<uint32_t>(best.size()));
      mine.items.insert(mine.items.end(), best.rows().begin(), best.rows().end());
      if (d2_too) mine.d2.insert(mine.d2.end(), best.dist2().begin(), best.dist2().end());
    }
    chunks.put(begin / kListsGrain, std::move(mine));
  });
  chunks.gather(out, &NeighbourLists::row, &ex);
  for (std::size_t a = 0; a < q; ++a)
    if (!sure[a]) unsure.push_back(static_cast<uint32_t>(a));
}

void scan_rows(const AgentTable& t, std::span<const uint32_t> rows, double range, uint32_t k,
               NeighbourLists& out, Executor& ex) {
  const std::size_t q = rows.size();
  const auto n = static_cast<uint32_t>(t.size());
  // d2 <= bound is d2 < range^2 (the neighbour methods' test) for every double d2.
  const double bound = std::nextafter(range * range, -INFINITY);
  // Blocks of rows, so the buffers stay small at any n; whole vectors of four but the last block.
  constexpr uint32_t kBlock = 4096;
  ListChunks lists;  // one chunk a query
  lists.reset(q);
  ex.for_each_chunk(q, 1, [&](std::size_t b, std::size_t e) {
    std::vector<uint32_t> at(kBlock + index::kNeighbourPad);
    std::vector<double> dist(kBlock + index::kNeighbourPad);
    NearestK best;
    for (std::size_t a = b; a < e; ++a) {
      const uint32_t i = rows[a];
      const double px = t.x[i], py = t.y[i];
      best.reset(k);
      for (uint32_t lo = 0; lo < n; lo += kBlock) {
        const uint32_t hi = std::min(n, lo + kBlock);
        const uint32_t whole = lo + ((hi - lo) & ~3u);  // the lanes read no further than this
        uint32_t m = index::gather_within_lanes(t.x.data(), t.y.data(), lo, whole, px, py, bound, i,
                                                at.data(), dist.data());
        m += index::gather_within(t.x.data(), t.y.data(), whole, hi, px, py, bound, i,
                                  at.data() + m, dist.data() + m);
        for (uint32_t u = 0; u < m; ++u) best.offer(at[u], t.id[at[u]], dist[u]);
      }
      best.finish();
      ListChunks::Chunk mine;
      mine.counts.push_back(static_cast<uint32_t>(best.size()));
      mine.items.assign(best.rows().begin(), best.rows().end());
      if (out.with_dist2) mine.d2.assign(best.dist2().begin(), best.dist2().end());
      lists.put(a, std::move(mine));
    }
  });
  lists.gather(out, &NeighbourLists::row, &ex);
}

double largest_move(std::span<const double> x0, std::span<const double> y0,
                    std::span<const double> x1, std::span<const double> y1, Executor& ex) {
  const std::size_t n = x0.size();
  const std::size_t chunks = (n + kMoveGrain - 1) / kMoveGrain;
  std::vector<double> part(chunks, 0);
  // A maximum in which a NaN, once met, stays: the same in any order of rows and chunks.
  const auto fold = [](double m, double d2) { return !std::isnan(m) && !(d2 <= m) ? d2 : m; };
  ex.for_each_chunk(n, kMoveGrain, [&](std::size_t b, std::size_t e) {
    double m = 0;  // written once (neighbouring chunks' entries share cache lines)
    for (std::size_t i = b; i < e; ++i) {
      const double dx = x1[i] - x0[i], dy = y1[i] - y0[i];
      m = fold(m, dx * dx + dy * dy);
    }
    part[b / kMoveGrain] = m;
  });
  double m = 0;
  for (double p : part) m = fold(m, p);
  return std::sqrt(m);
}

AnsweredBy neighbours_after_move(const AgentTable& t, const TickMove* move,
                                 std::span<const uint32_t> queries, double range, uint32_t k,
                                 NeighbourPath& path, NeighbourLists& out, Executor& ex,
                                 QueryStats& stats) {
  AnsweredBy by;
  if (!move) {
    path.run(DiscView::of(t), queries, range, k, out, ex, stats);
    by.query = queries.size();
    return by;
  }
  std::vector<uint32_t> unsure;
  Stopwatch sw;  // booked as the query's probes
  lists_after_move(t, *move, queries, range, k, out, unsure, ex);
  stats.query_seconds += sw.seconds();
  by.lists = queries.size() - unsure.size();
  if (unsure.empty()) return by;
  std::vector<uint32_t> rows;
  for (uint32_t a : unsure) rows.push_back(queries[a]);
  NeighbourLists answers;
  answers.with_dist2 = out.with_dist2;
  if (rows.size() <= kScanMost) {
    // A few left (the densest spots): a scan of every row each costs less than a grid.
    sw.restart();
    scan_rows(t, rows, range, k, answers, ex);
    stats.query_seconds += sw.seconds();
    stats.pair_tests += rows.size() * t.size();
    stats.rows += rows.size();
    by.scan = rows.size();
  } else {
    path.run(DiscView::of(t), rows, range, k, answers, ex, stats);
    by.query = rows.size();
  }
  fill_unsure(out, unsure, answers);
  return by;
}

void fill_unsure(NeighbourLists& out, std::span<const uint32_t> unsure,
                 const NeighbourLists& answers) {
  if (unsure.empty()) return;
  const std::size_t q = out.queries();
  const bool d2 = out.with_dist2 && answers.with_dist2;
  NeighbourLists all;
  all.with_dist2 = d2;
  all.offset.assign(q + 1, 0);
  all.row.reserve(out.row.size() + answers.row.size());
  std::size_t u = 0;
  for (std::size_t a = 0; a < q; ++a) {
    const bool from_answers = u < unsure.size() && unsure[u] == a;
    const NeighbourLists& from = from_answers ? answers : out;
    const std::size_t at = from_answers ? u++ : a;
    const uint32_t lo = from.offset[at], hi = from.offset[at + 1];
    all.row.insert(all.row.end(), from.row.begin() + lo, from.row.begin() + hi);
    if (d2) all.dist2.insert(all.dist2.end(), from.dist2.begin() + lo, from.dist2.begin() + hi);
    all.offset[a + 1] = static_cast<uint32_t>(all.row.size());
  }
  out = std::move(all);
}

}  // namespace crowddb::sim
