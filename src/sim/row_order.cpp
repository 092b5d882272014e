#include "sim/row_order.hpp"

#include <algorithm>
#include <cmath>

namespace crowddb::sim {
namespace {

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

std::vector<uint32_t> curve_order(const AgentTable& t) {
  const std::size_t n = t.size();
  double xlo = INFINITY, ylo = INFINITY;
  for (std::size_t i = 0; i < n; ++i) {
    xlo = std::min(xlo, t.x[i]);
    ylo = std::min(ylo, t.y[i]);
  }
  struct Entry {
    uint64_t key, id;
    uint32_t row;
  };
  std::vector<Entry> e(n);
  for (std::size_t i = 0; i < n; ++i)
    e[i] = {spread(cell(t.x[i], xlo)) | (spread(cell(t.y[i], ylo)) << 1), t.id[i],
            static_cast<uint32_t>(i)};
  std::sort(e.begin(), e.end(), [](const Entry& a, const Entry& b) {
    return a.key < b.key || (a.key == b.key && a.id < b.id);
  });
  std::vector<uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = e[i].row;
  return order;
}

}  // namespace crowddb::sim
