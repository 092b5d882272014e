// Checks of command-line numbers, shared by the crowddb and sdfsched tools. CLI11's own
// (Range, PositiveNumber) let NaN through and print their bounds with every digit
// ("not in range 0.000000 to 1797693...368.000000"); these reject NaN and infinities and say the
// bound in plain words: "--every: must be a whole number >= 1 (got 0)".
#pragma once

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>

#include "util/plain_number.hpp"

namespace crowddb::cli_checks {

inline std::string plain(double v) {
  return plain_number(v);
}

// A whole number in [lo, hi].
inline CLI::Validator whole(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        long long v = 0;
        const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (ec != std::errc() || end != s.data() + s.size() || v < lo || v > hi)
          return "must be a whole number " +
                 (hi == std::numeric_limits<long long>::max()
                      ? ">= " + std::to_string(lo)
                      : "from " + std::to_string(lo) + " to " + std::to_string(hi)) +
                 " (got " + s + ")";
        return {};
      },
      "INT");
}
inline CLI::Validator whole_at_least(long long lo) {
  return whole(lo, std::numeric_limits<long long>::max());
}

// A finite number in [lo, hi] (above lo when `open_low`).
inline CLI::Validator finite(double lo, double hi, bool open_low = false) {
  return CLI::Validator(
      [lo, hi, open_low](std::string& s) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        const bool number = !s.empty() && end == s.c_str() + s.size() && std::isfinite(v);
        const bool low_ok = open_low ? v > lo : v >= lo;
        if (!number || !low_ok || v > hi) {
          std::string range = (open_low ? "> " : ">= ") + plain(lo);
          if (std::isfinite(hi)) range += " and <= " + plain(hi);
          return "must be a finite number " + range + " (got " + s + ")";
        }
        return {};
      },
      "NUMBER");
}
inline CLI::Validator positive() {
  return finite(0, HUGE_VAL, true);
}
inline CLI::Validator non_negative() {
  return finite(0, HUGE_VAL);
}

}  // namespace crowddb::cli_checks
