// Numbers in messages the way a person writes them: "1e9", "2000", "0.25" (not "1e+09" or a
// 309-digit bound).
#pragma once

#include <cmath>
#include <sstream>
#include <string>

namespace crowddb {

inline std::string plain_number(double v) {
  if (std::isfinite(v) && v != 0 && v == std::floor(v)) {
    const double e = std::round(std::log10(std::abs(v)));
    if (e >= 6 && std::pow(10.0, e) == std::abs(v))
      return (v < 0 ? "-1e" : "1e") + std::to_string(static_cast<int>(e));
    if (std::abs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  }
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace crowddb
