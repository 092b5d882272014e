// Small text helpers shared by the graph readers.
#pragma once

#include <algorithm>
#include <string_view>
#include <vector>

namespace sdf {

inline std::string_view trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

// Byte offset -> 1-based line number. CR LF and LF both end a line (a lone CR does not).
class LineIndex {
 public:
  explicit LineIndex(std::string_view text) {
    for (size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') newlines_.push_back(i);
  }
  size_t line_of(size_t offset) const {
    return static_cast<size_t>(std::lower_bound(newlines_.begin(), newlines_.end(), offset) -
                               newlines_.begin()) +
           1;
  }

 private:
  std::vector<size_t> newlines_;
};

}  // namespace sdf
