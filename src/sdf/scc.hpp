// Strongly connected components of a directed graph in compressed form (Tarjan's algorithm with
// an explicit stack, so deep graphs do not overflow the call stack). O(V + E).
#pragma once

#include <cstdint>
#include <vector>

namespace sdf::detail {

// Successors of v are succ[off[v] .. off[v + 1]). Returns the component of every vertex;
// components are numbered in reverse topological order of the condensation (a component's
// successors have smaller numbers), `count` receives their number.
inline std::vector<uint32_t> strong_components(uint32_t n, const std::vector<uint32_t>& off,
                                               const std::vector<uint32_t>& succ, uint32_t& count) {
  constexpr uint32_t kNone = UINT32_MAX;
  std::vector<uint32_t> index(n, kNone), low(n, 0), comp(n, kNone);
  std::vector<uint32_t> stack;                      // Tarjan's stack of vertices
  std::vector<std::pair<uint32_t, uint32_t>> call;  // (vertex, next successor slot)
  uint32_t next_index = 0;
  count = 0;
  for (uint32_t root = 0; root < n; ++root) {
    if (index[root] != kNone) continue;
    call.push_back({root, off[root]});
    index[root] = low[root] = next_index++;
    stack.push_back(root);
    while (!call.empty()) {
      auto& [v, slot] = call.back();
      if (slot < off[v + 1]) {
        const uint32_t w = succ[slot++];
        if (index[w] == kNone) {
          index[w] = low[w] = next_index++;
          stack.push_back(w);
          call.push_back({w, off[w]});
        } else if (comp[w] == kNone && index[w] < low[v]) {
          low[v] = index[w];
        }
        continue;
      }
      const uint32_t done = v;
      call.pop_back();
      if (!call.empty() && low[done] < low[call.back().first]) low[call.back().first] = low[done];
      if (low[done] == index[done]) {
        uint32_t w;
        do {
          w = stack.back();
          stack.pop_back();
          comp[w] = count;
        } while (w != done);
        ++count;
      }
    }
  }
  return comp;
}

}  // namespace sdf::detail
