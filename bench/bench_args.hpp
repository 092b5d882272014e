// Strict reading of the benchmarks' option values: the whole text must be the number and in range,
// or the option is refused by name (a typo must not run some other benchmark than the one asked).
#pragma once

#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <system_error>

namespace crowddb::bench {

// An integer in [lo, hi], written in decimal digits only.
inline std::optional<long long> whole_number(const std::string& s, long long lo, long long hi) {
  long long v = 0;
  const auto [end, err] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || s.front() == '-' || err != std::errc() || end != s.data() + s.size() || v < lo ||
      v > hi)
    return std::nullopt;
  return v;
}

// A finite number above zero.
inline std::optional<double> positive_number(const std::string& s) {
  double v = 0;
  const auto [end, err] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || err != std::errc() || end != s.data() + s.size() || !std::isfinite(v) ||
      !(v > 0))
    return std::nullopt;
  return v;
}

// A tool's usage text (ending in a newline): asked for (--help, -h), it goes to standard output
// with exit status 0; after a complaint, to standard error with status 2.
struct Usage {
  const char* tool;
  const char* text;
  static bool asked(const std::string& option) { return option == "--help" || option == "-h"; }
  int print() const {
    std::printf("%s", text);
    return 0;
  }
  int refuse(const std::string& why) const {
    std::fprintf(stderr, "%s: %s\n%s", tool, why.c_str(), text);
    return 2;
  }
};

}  // namespace crowddb::bench
