// Lists of items per bucket in one array (compressed sparse rows): bucket b's items are
// ids[start[b] .. start[b + 1]), in item order. For lookups built once over a few thousand to a
// few million registrations (BoxGrid's cells, RingGrid's strips) where an item may belong to
// several buckets: counted, then placed, with no list of (bucket, item) pairs in between.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace crowddb {

// each(k, to) calls to(b) for every bucket b < buckets that item k < items belongs to; it is
// called twice per item and must name the same buckets both times.
template <class Each>
void fill_bucket_lists(std::size_t buckets, std::size_t items, Each&& each,
                       std::vector<uint32_t>& start, std::vector<uint32_t>& ids) {
  start.assign(buckets + 1, 0);
  for (std::size_t k = 0; k < items; ++k) each(k, [&](std::size_t b) { ++start[b + 1]; });
  for (std::size_t b = 1; b <= buckets; ++b) start[b] += start[b - 1];
  ids.resize(start[buckets]);
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t k = 0; k < items; ++k)
    each(k, [&](std::size_t b) { ids[fill[b]++] = static_cast<uint32_t>(k); });
}

}  // namespace crowddb
