// UTF-8 encoding of one code point, for the readers that decode escapes (XML character
// references, JSON \u escapes), and messages kept to one line. Header-only so the SDF library can
// use it without the crowd code.
#pragma once

#include <cstdint>
#include <string>

namespace crowddb {

// Appends `cp` (at most 0x10FFFF; callers reject larger values and lone surrogates) as UTF-8.
inline void append_utf8(std::string& out, uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

// `text` with its control characters (below 0x20, and DEL) as spaces: errors are one line, and
// messages that quote a file (SQLite's quote names and SQL from it) may hold anything.
inline std::string one_line(std::string text) {
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  return text;
}

}  // namespace crowddb
