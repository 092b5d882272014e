// Small text helpers shared by the graph readers.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

namespace sdf {

inline std::string_view trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

// a == b without a call to memcmp: the readers compare many short names (tags, attributes,
// ports), where the call costs more than the comparison.
inline bool same(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i] != b[i]) return false;
  return true;
}

// The readers' message for an attribute that is not a (positive) 64-bit integer (the streaming
// reader and its DOM twin in naive.cpp, whose messages the tests compare).
inline std::string not_an_integer(std::string_view attr, std::string_view text, bool positive) {
  std::string msg = "attribute " + std::string(attr) + "='" + std::string(text) + "' is not a " +
                    (positive ? "positive" : "non-negative") + " 64-bit integer";
  if (text.find(',') != std::string_view::npos) msg += " (CSDF rate lists are not supported)";
  return msg;
}

// Names may not begin or end with white space: the SDF3 reader trims attribute values (XML
// tools pad them), so such a name read from JSON would come back changed from SDF3.
inline bool padded(std::string_view s) {
  return trim(s).size() != s.size();
}

// Well-formed UTF-8 (no overlong forms, surrogates or code points above U+10FFFF): names end up
// in JSON output, which must be valid UTF-8.
inline bool valid_utf8(std::string_view s) {
  size_t i = 0;
  // ASCII eight bytes at a time (names nearly always are).
  for (; i + 8 <= s.size(); i += 8) {
    uint64_t w;
    std::memcpy(&w, s.data() + i, 8);
    if (w & 0x8080808080808080ull) break;
  }
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    size_t len;
    uint32_t cp;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      len = 2, cp = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      len = 3, cp = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      len = 4, cp = c & 0x07;
    } else {
      return false;
    }
    if (i + len > s.size()) return false;
    for (size_t k = 1; k < len; ++k) {
      const auto d = static_cast<unsigned char>(s[i + k]);
      if ((d & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (d & 0x3F);
    }
    if ((len == 2 && cp < 0x80) || (len == 3 && cp < 0x800) || (len == 4 && cp < 0x10000) ||
        cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
      return false;
    i += len;
  }
  return true;
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
