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

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace sdf::detail {

struct XmlAttribute {
  std::string_view name;
  std::string_view raw;  // between the quotes, undecoded (see decode_attribute)
  bool plain = false;    // no reference, tab or line end: decode_attribute would return raw
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
  const XmlAttribute* attribute(std::string_view name) const;
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

// An attribute value as pugixml's default mode gives it: the five named entities and numeric
// character references decoded (an unknown or malformed reference is kept as written), tabs,
// line feeds and carriage returns (CR LF counting once) turned into spaces. Returns `raw` itself
// when nothing changes, else a view of `storage`, which it overwrites.
std::string_view decode_attribute(std::string_view raw, std::string& storage);

}  // namespace sdf::detail
