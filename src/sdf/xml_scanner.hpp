// A streaming XML tokenizer for the SDF3 reader: one pass over the text, no document tree. It
// reports element start tags (with their attributes, as views into the text) and end tags, and
// skips text, comments, processing instructions, CDATA sections and a DOCTYPE. It checks what the
// reader relies on — tags well formed, attribute values quoted, every end tag matching its start
// tag, nothing left open at the end — and reports the byte offset of a mistake (the reader turns
// it into a line number). Like pugixml's default mode it does not validate beyond that.
//
// Memory: the open elements' names (views) and the current tag's attributes; O(depth + attributes
// of one tag), never proportional to the document.
//
// Thread-safety: a scanner is single-threaded state over an immutable text.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace sdf::detail {

// The first eight bytes of a name, zero-padded, as one word: attribute lookups compare names by
// this key and their length first (every attribute name SDF3 uses but one fits in it).
// Byte i goes to bits 8i..8i+7: on a little-endian machine, the word a load of the name gives.
constexpr uint64_t name_key(std::string_view name) {
  uint64_t key = 0;
  for (size_t i = 0; i < name.size() && i < sizeof key; ++i)
    key |= uint64_t{static_cast<unsigned char>(name[i])} << (8 * i);
  return key;
}

// An attribute name the reader looks for, with its key made at compile time (a key built at run
// time went through the stack and stalled every lookup).
struct AttrName {
  std::string_view name;
  uint64_t key;
  consteval AttrName(const char* literal) : name(literal), key(name_key(name)) {}
};

struct XmlAttribute {
  std::string_view name;
  std::string_view raw;  // between the quotes, undecoded (see decode_attribute)
  uint64_t key = 0;      // name_key(name)
  bool plain = false;    // no reference, tab or line end: decode_attribute would return raw
  bool ascii = false;    // raw has no byte above 0x7F (so it is valid UTF-8)
};

struct XmlError {
  size_t offset;
  std::string message;  // "XML: ..."
};

class XmlScanner {
 public:
  explicit XmlScanner(std::string_view text) : text_(text) {}

  enum class Kind { start, end, eof };
  struct Token {
    Kind kind = Kind::eof;
    std::string_view name;
    bool self_closing = false;  // start tags only: <x/> (no end token follows)
    size_t offset = 0;          // of the '<'
    size_t end = 0;             // just past the '>'
  };

  // The next start or end tag, or eof (only once every element is closed). Throws XmlError.
  Token next();
  // An attribute of the last start tag (a repeated name: the first counts), or null.
  const XmlAttribute* attribute(AttrName n) const {
    for (const XmlAttribute& a : attributes_)
      if (a.key == n.key && a.name.size() == n.name.size() &&
          (n.name.size() <= sizeof n.key ||
           a.name.substr(sizeof n.key) == n.name.substr(sizeof n.key)))
        return &a;
    return nullptr;
  }
  size_t depth() const { return open_.size(); }

 private:
  [[noreturn]] void fail(size_t offset, const char* what) const;
  void skip_until(std::string_view close, size_t from, const char* what);
  Token start_tag(size_t lt);
  Token end_tag(size_t lt);

  std::string_view text_;
  size_t pos_ = 0;
  std::vector<std::string_view> open_;
  std::vector<XmlAttribute> attributes_;
};

// Calls f(offset) for every '<' in text, in order: a whole-text count of tags without a library
// call per tag (16 bytes per step where SSE2 is there, a byte at a time elsewhere).
template <class F>
void for_each_lt(std::string_view text, F&& f) {
  const char* const s = text.data();
  size_t i = 0;
#if defined(__SSE2__)
  const __m128i lt = _mm_set1_epi8('<');
  for (; i + 16 <= text.size(); i += 16) {
    auto m = static_cast<unsigned>(_mm_movemask_epi8(
        _mm_cmpeq_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(s + i)), lt)));
    for (; m != 0; m &= m - 1) f(i + static_cast<size_t>(std::countr_zero(m)));
  }
#endif
  for (; i < text.size(); ++i)
    if (s[i] == '<') f(i);
}

// An attribute value as pugixml's default mode gives it: the five named entities and numeric
// character references decoded (an unknown or malformed reference is kept as written), tabs,
// line feeds and carriage returns (CR LF counting once) turned into spaces. Returns `raw` itself
// when nothing changes, else a view of `storage`, which it overwrites.
std::string_view decode_attribute(std::string_view raw, std::string& storage);

}  // namespace sdf::detail
