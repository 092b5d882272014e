#include "xml_scanner.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "sdf/text.hpp"
#include "util/utf8.hpp"

namespace sdf::detail {

namespace {

// Character classes by table (the tokenizer tests every byte of a tag).
enum : uint8_t { kSpace = 1, kNameStart = 2, kNameChar = 4, kValueStop = 8 };
constexpr auto kClass = [] {
  std::array<uint8_t, 256> t{};
  for (unsigned char c : {' ', '\t', '\n', '\r'}) t[c] = kSpace;
  // Where a scan of an attribute value stops: a quote, NUL, or what decoding changes.
  for (unsigned char c : {'"', '\'', '\0', '&', '\t', '\n', '\r'}) t[c] |= kValueStop;
  // Name characters as pugixml accepts them: ASCII letters, digits (not first), '_', ':', '-',
  // '.', and every byte of a multi-byte UTF-8 sequence.
  for (unsigned c = 0; c < 256; ++c)
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == ':' || c >= 0x80)
      t[c] = kNameStart | kNameChar;
  for (unsigned char c : {'0', '1', '2', '3', '4', '5', '6', '7', '8', '9', '-', '.'})
    t[c] |= kNameChar;
  return t;
}();
bool space(char c) {
  return kClass[static_cast<unsigned char>(c)] & kSpace;
}
bool name_start(char c) {
  return kClass[static_cast<unsigned char>(c)] & kNameStart;
}
bool name_char(char c) {
  return kClass[static_cast<unsigned char>(c)] & kNameChar;
}
// The first `c` at or after `from`, or npos. The gaps between tags and attribute values are
// short: a plain loop first, memchr past that.
size_t find_char(std::string_view text, char c, size_t from) {
  const size_t near = std::min(text.size(), from + 32);
  for (size_t i = from; i < near; ++i)
    if (text[i] == c) return i;
  return near == text.size() ? std::string_view::npos : text.find(c, near);
}

// The first byte at or after `from` that ends a plain run of an attribute value (kValueStop), or
// the text's size; `high` is set if a byte above 0x7F is passed. Values run to tens of bytes
// (names like "a747779->a799143#0"): 16 at a time where SSE2 is there.
size_t skip_value_bytes(std::string_view text, size_t from, bool& high) {
  const char* const s = text.data();
  size_t i = from;
#if defined(__SSE2__)
  // Candidates: both quotes, '&', and every byte up to 0x1F (a superset of the stops' control
  // bytes, sorted out below by the table).
  const __m128i dq = _mm_set1_epi8('"'), sq = _mm_set1_epi8('\''), amp = _mm_set1_epi8('&');
  const __m128i low = _mm_set1_epi8(0x1F);
  for (; i + 16 <= text.size(); i += 16) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + i));
    const __m128i hit =
        _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi8(v, dq), _mm_cmpeq_epi8(v, sq)),
                     _mm_or_si128(_mm_cmpeq_epi8(v, amp), _mm_cmpeq_epi8(_mm_min_epu8(v, low), v)));
    auto m = static_cast<unsigned>(_mm_movemask_epi8(hit));
    const auto top = static_cast<unsigned>(_mm_movemask_epi8(v));  // bytes above 0x7F
    for (; m != 0; m &= m - 1) {
      const unsigned at = static_cast<unsigned>(std::countr_zero(m));
      if (kClass[static_cast<unsigned char>(s[i + at])] & kValueStop) {
        high |= (top & ((1u << at) - 1)) != 0;
        return i + at;
      }
    }
    high |= top != 0;
  }
#endif
  for (; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (kClass[c] & kValueStop) return i;
    high |= c > 0x7F;
  }
  return i;
}

// name_key of text.substr(at, size) by one load where the text goes on for eight bytes (it does
// after every attribute name but near the end): building the key byte by byte on the stack and
// reading it back as a word stalls the load.
uint64_t key_at(std::string_view text, size_t at, size_t size) {
  if constexpr (std::endian::native == std::endian::little) {
    if (at + 8 <= text.size()) {
      uint64_t word;
      std::memcpy(&word, text.data() + at, 8);
      return size >= 8 ? word : word & ((uint64_t{1} << (8 * size)) - 1);
    }
  }
  return name_key(text.substr(at, size));
}

}  // namespace

void XmlScanner::fail(size_t offset, const char* what) const {
  throw XmlError{offset, std::string("XML: ") + what};
}

void XmlScanner::skip_until(std::string_view close, size_t from, const char* what) {
  const size_t at = text_.find(close, from);
  if (at == std::string_view::npos) fail(from, what);
  pos_ = at + close.size();
}

XmlScanner::Token XmlScanner::next() {
  for (;;) {
    const size_t lt = find_char(text_, '<', pos_);
    if (lt == std::string_view::npos) {
      if (!open_.empty()) fail(text_.size(), "Start-end tags mismatch (an element is not closed)");
      pos_ = text_.size();
      return {};
    }
    if (lt + 1 >= text_.size()) fail(lt, "Unrecognized tag");
    const char c = text_[lt + 1];
    if (c == '?') {
      // A processing instruction names its target: <?xml ... ?>, <?pi?>.
      if (lt + 2 >= text_.size() || !name_start(text_[lt + 2]))
        fail(lt, "Error parsing document declaration/processing instruction");
      skip_until("?>", lt + 2, "Error parsing document declaration/processing instruction");
    } else if (c == '!') {
      const std::string_view rest = text_.substr(lt);
      if (rest.starts_with("<!--")) {
        skip_until("-->", lt + 4, "Error parsing comment");
      } else if (rest.starts_with("<![CDATA[")) {
        skip_until("]]>", lt + 9, "Error parsing CDATA section");
      } else if (rest.starts_with("<!DOCTYPE")) {
        if (!open_.empty()) fail(lt, "DOCTYPE inside an element");
        // Up to the '>' outside quotes and outside the internal subset's brackets.
        size_t i = lt + 9, brackets = 0;
        char quote = 0;
        for (; i < text_.size(); ++i) {
          const char d = text_[i];
          if (quote) {
            if (d == quote) quote = 0;
          } else if (d == '"' || d == '\'') {
            quote = d;
          } else if (d == '[') {
            ++brackets;
          } else if (d == ']') {
            if (brackets == 0) fail(i, "Error parsing document type declaration");
            --brackets;
          } else if (d == '>' && brackets == 0) {
            break;
          }
        }
        if (i >= text_.size()) fail(lt, "Error parsing document type declaration");
        pos_ = i + 1;
      } else {
        fail(lt, "Unrecognized tag");
      }
    } else if (c == '/') {
      return end_tag(lt);
    } else {
      return start_tag(lt);
    }
  }
}

XmlScanner::Token XmlScanner::start_tag(size_t lt) {
  size_t i = lt + 1;
  if (!name_start(text_[i])) fail(lt, "Error parsing start element tag");
  const size_t name_from = i;
  while (i < text_.size() && name_char(text_[i])) ++i;
  Token t;
  t.kind = Kind::start;
  t.name = text_.substr(name_from, i - name_from);
  t.offset = lt;
  attributes_.clear();
  for (;;) {
    const size_t before = i;
    while (i < text_.size() && space(text_[i])) ++i;
    if (i >= text_.size()) fail(lt, "Error parsing start element tag");
    if (text_[i] == '>') {
      t.end = i + 1;
      break;
    }
    if (text_[i] == '/') {
      if (i + 1 >= text_.size() || text_[i + 1] != '>') fail(i, "Error parsing start element tag");
      t.self_closing = true;
      t.end = i + 2;
      break;
    }
    // An attribute needs white space before it.
    if (i == before || !name_start(text_[i])) fail(i, "Error parsing start element tag");
    const size_t an = i;
    while (i < text_.size() && name_char(text_[i])) ++i;
    const std::string_view name = text_.substr(an, i - an);
    while (i < text_.size() && space(text_[i])) ++i;
    if (i >= text_.size() || text_[i] != '=') fail(an, "Attribute value is not properly quoted");
    ++i;
    while (i < text_.size() && space(text_[i])) ++i;
    if (i >= text_.size() || (text_[i] != '"' && text_[i] != '\''))
      fail(an, "Attribute value is not properly quoted");
    const char quote = text_[i++];
    // One pass to the closing quote, noting what decoding would change, any NUL, and any byte
    // above 0x7F.
    bool plain = true, nul = false, high = false;
    size_t close = i;
    for (;; ++close) {
      close = skip_value_bytes(text_, close, high);
      if (close >= text_.size() || text_[close] == quote) break;
      if (text_[close] == '\0') nul = true;
      if (text_[close] != '"' && text_[close] != '\'') plain = false;
    }
    if (close >= text_.size()) fail(an, "Error parsing attribute value");
    const std::string_view raw = text_.substr(i, close - i);
    // XML has no NUL character; pugixml's tree cut values at one, which made names change
    // between a read and a write (found by fuzzing).
    if (nul) fail(an, "Error parsing attribute value (NUL)");
    // A repeated name is kept too: attribute() returns the first, as pugixml does, and checking
    // here would cost time quadratic in a tag's attributes.
    attributes_.push_back({name, raw, key_at(text_, an, name.size()), plain, !high});
    i = close + 1;
  }
  pos_ = t.end;
  if (!t.self_closing) open_.push_back(t.name);
  return t;
}

XmlScanner::Token XmlScanner::end_tag(size_t lt) {
  size_t i = lt + 2;
  const size_t name_from = i;
  while (i < text_.size() && name_char(text_[i])) ++i;
  const std::string_view name = text_.substr(name_from, i - name_from);
  while (i < text_.size() && space(text_[i])) ++i;
  if (i >= text_.size() || text_[i] != '>') fail(lt, "Error parsing end element tag");
  if (open_.empty() || open_.back() != name) fail(lt, "Start-end tags mismatch");
  open_.pop_back();
  pos_ = i + 1;
  Token t;
  t.kind = Kind::end;
  t.name = name;
  t.offset = lt;
  t.end = pos_;
  return t;
}

std::string_view decode_attribute(std::string_view raw, std::string& storage) {
  size_t i = 0;
  while (i < raw.size() && raw[i] != '&' && raw[i] != '\t' && raw[i] != '\n' && raw[i] != '\r') ++i;
  if (i == raw.size()) return raw;
  storage.assign(raw.data(), i);
  while (i < raw.size()) {
    const char c = raw[i];
    if (c == '\r') {
      storage += ' ';
      i += i + 1 < raw.size() && raw[i + 1] == '\n' ? 2 : 1;
      continue;
    }
    if (c == '\t' || c == '\n') {
      storage += ' ';
      ++i;
      continue;
    }
    if (c != '&') {
      storage += c;
      ++i;
      continue;
    }
    const size_t semi = raw.find(';', i);
    const std::string_view ref =
        semi == std::string_view::npos ? std::string_view{} : raw.substr(i + 1, semi - i - 1);
    static constexpr std::pair<std::string_view, char> kNamed[] = {
        {"lt", '<'}, {"gt", '>'}, {"amp", '&'}, {"quot", '"'}, {"apos", '\''}};
    bool done = false;
    for (const auto& [n, ch] : kNamed)
      if (ref == n) storage += ch, done = true;
    if (!done && ref.size() >= 2 && ref[0] == '#') {
      const bool hex = ref[1] == 'x';
      const std::string_view digits = ref.substr(hex ? 2 : 1);
      uint32_t cp = 0;
      const auto [p, ec] =
          std::from_chars(digits.data(), digits.data() + digits.size(), cp, hex ? 16 : 10);
      if (!digits.empty() && ec == std::errc() && p == digits.data() + digits.size() && cp != 0 &&
          cp <= 0x10FFFF && !(cp >= 0xD800 && cp <= 0xDFFF)) {
        crowddb::append_utf8(storage, cp);
        done = true;
      }
    }
    if (done) {
      i = semi + 1;
    } else {
      storage += '&';  // not a reference we know: kept as written
      ++i;
    }
  }
  return storage;
}

}  // namespace sdf::detail
