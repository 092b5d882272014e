#include "io/import/xml.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "crowddb/error.hpp"

namespace crowddb::io {
namespace {

bool space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

}  // namespace

std::optional<double> parse_number(std::string_view s) {
  s = trim(s);
  if (s.empty() || s.size() > 64) return std::nullopt;
  const std::string copy(s);
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(copy.c_str(), &end);
  if (end != copy.c_str() + copy.size()) return std::nullopt;
  if (errno == ERANGE && std::isinf(v)) return std::nullopt;
  // strtod reads "nan" and "inf": no file of any format means them.
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

XmlFile::XmlFile(std::string_view text, std::string source)
    : source_(std::move(source)) {
  // TinyXML accepts an XML declaration after a comment (7 of SteerSuite's test cases have one)
  // and ignores text after the root element (one of Menge's examples has some); pugixml does both
  // by default.
  line_starts_.push_back(0);
  for (std::size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') line_starts_.push_back(i + 1);
  const pugi::xml_parse_result r =
      doc_.load_buffer(text.data(), text.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!r) {
    const auto off = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, r.offset));
    const auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), off);
    const std::size_t line = static_cast<std::size_t>(it - line_starts_.begin());
    const std::size_t col = off - line_starts_[line - 1] + 1;
    throw Error(Error::Kind::input, source_ + ":" + std::to_string(line) + ":" +
                                        std::to_string(col) + ": malformed XML: " +
                                        r.description());
  }
  if (!root()) throw Error(Error::Kind::input, source_ + ": malformed XML: no root element");
}

std::size_t XmlFile::line(const pugi::xml_node& n) const {
  const std::ptrdiff_t off = n.offset_debug();
  if (off < 0) return 0;
  const auto it =
      std::upper_bound(line_starts_.begin(), line_starts_.end(), static_cast<std::size_t>(off));
  return static_cast<std::size_t>(it - line_starts_.begin());
}

std::string XmlFile::where(const pugi::xml_node& n) const {
  const std::size_t l = line(n);
  return source_ + (l ? ":" + std::to_string(l) : std::string()) + ": <" + std::string(local(n)) +
         ">";
}

void XmlFile::fail(const pugi::xml_node& n, const std::string& what) const {
  throw Error(Error::Kind::input, where(n) + ": " + what);
}

std::string_view XmlFile::local(const pugi::xml_node& n) {
  std::string_view name = n.name();
  const auto colon = name.find(':');
  return colon == std::string_view::npos ? name : name.substr(colon + 1);
}

std::vector<pugi::xml_node> XmlFile::children(const pugi::xml_node& n, std::string_view name) {
  std::vector<pugi::xml_node> out;
  for (pugi::xml_node c = n.first_child(); c; c = c.next_sibling())
    if (c.type() == pugi::node_element && local(c) == name) out.push_back(c);
  return out;
}

pugi::xml_node XmlFile::only_child(const pugi::xml_node& n, std::string_view name) const {
  const auto all = children(n, name);
  if (all.size() > 1) fail(all[1], "repeated: give it once");
  return all.empty() ? pugi::xml_node() : all.front();
}

std::string XmlFile::text(const pugi::xml_node& n) const {
  return std::string(trim(n.text().get()));
}

double XmlFile::number(const pugi::xml_node& n) const {
  const std::string t = text(n);
  if (t.empty()) fail(n, "expected a number, got nothing");
  const auto v = parse_number(t);
  if (!v) fail(n, "expected a number, got '" + t.substr(0, 40) + "'");
  return *v;
}

std::optional<double> XmlFile::child_number(const pugi::xml_node& parent,
                                            std::string_view name) const {
  const pugi::xml_node c = only_child(parent, name);
  if (!c) return std::nullopt;
  return number(c);
}

double XmlFile::attr_number(const pugi::xml_node& n, const char* name) const {
  const auto v = attr_number_opt(n, name);
  if (!v) fail(n, std::string("missing attribute '") + name + "' (a number)");
  return *v;
}

std::optional<double> XmlFile::attr_number_opt(const pugi::xml_node& n, const char* name) const {
  const pugi::xml_attribute a = n.attribute(name);
  if (!a) return std::nullopt;
  const auto v = parse_number(a.value());
  if (!v)
    fail(n, std::string("attribute '") + name + "': expected a number, got '" +
                std::string(a.value()).substr(0, 40) + "'");
  return v;
}

std::string XmlFile::attr_string(const pugi::xml_node& n, const char* name) const {
  const pugi::xml_attribute a = n.attribute(name);
  if (!a) fail(n, std::string("missing attribute '") + name + "'");
  return a.value();
}

}  // namespace crowddb::io
