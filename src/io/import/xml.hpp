// XML input for the importers (pugixml): one parsed file that can name the line of any element,
// so that every error and warning says "file:LINE: <element>: what".
//
// Parsing is as lenient as the simulators whose files we read (TinyXML in SteerSuite and Menge):
// an <?xml?> declaration after a comment, and text after the root element, are accepted.
// Namespaces are ignored (elements are matched by their local name).
#pragma once

#include <pugixml.hpp>

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace crowddb::io {

class XmlFile {
 public:
  // Parses `text`; `source` names the file in messages. A malformed document throws
  // Error(input) naming the line and column.
  XmlFile(std::string_view text, std::string source);
  XmlFile(const XmlFile&) = delete;
  XmlFile& operator=(const XmlFile&) = delete;

  pugi::xml_node root() const { return doc_.document_element(); }
  const std::string& source() const { return source_; }

  // 1-based line of an element (0 when unknown).
  std::size_t line(const pugi::xml_node& n) const;
  // "file:LINE: <name>"
  std::string where(const pugi::xml_node& n) const;
  [[noreturn]] void fail(const pugi::xml_node& n, const std::string& what) const;

  // The element's name without a namespace prefix.
  static std::string_view local(const pugi::xml_node& n);
  // Element children by local name.
  static std::vector<pugi::xml_node> children(const pugi::xml_node& n, std::string_view name);
  // The single child of that name, or an empty node; a repeated child is an error.
  pugi::xml_node only_child(const pugi::xml_node& n, std::string_view name) const;

  // Numbers. Text content (SteerSuite) or attributes (Menge); surrounding white space is allowed,
  // anything else after the number is an error naming the element.
  double number(const pugi::xml_node& n) const;  // the element's text
  std::optional<double> child_number(const pugi::xml_node& parent, std::string_view name) const;
  double attr_number(const pugi::xml_node& n, const char* name) const;  // required attribute
  std::optional<double> attr_number_opt(const pugi::xml_node& n, const char* name) const;
  std::string attr_string(const pugi::xml_node& n, const char* name) const;  // required
  std::string text(const pugi::xml_node& n) const;  // trimmed text content

 private:
  std::string source_;
  std::vector<std::size_t> line_starts_;  // byte offset of each line's first character
  pugi::xml_document doc_;
};

// "1.5" -> 1.5 with only white space around it; nullopt otherwise.
std::optional<double> parse_number(std::string_view s);

}  // namespace crowddb::io
