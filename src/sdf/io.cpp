#include "sdf/io.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace sdf {

namespace {

bool ends_with(const std::string& s, const char* suffix) {
  const size_t n = std::strlen(suffix);
  return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

}  // namespace

Graph read_graph_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(Error::Kind::io, path + ": cannot open (" + std::strerror(errno) + ")");
  std::ostringstream buf;
  buf << in.rdbuf();
  if (in.bad()) throw Error(Error::Kind::io, path + ": read error");
  const std::string text = std::move(buf).str();
  if (ends_with(path, ".xml")) return read_sdf3(text, path);
  if (ends_with(path, ".json")) return read_json(text, path);
  for (char c : text) {
    if (c == '<') return read_sdf3(text, path);
    if (c == '{') return read_json(text, path);
    if (c != ' ' && c != '\t' && c != '\r' && c != '\n') break;
  }
  throw Error(Error::Kind::input,
              path + ":1: not a graph file (expected SDF3 XML or the JSON form, .xml or .json)");
}

std::string write_dot(const Graph& g) {
  std::string out = "digraph " + quoted(g.name.empty() ? "sdf" : g.name) + " {\n";
  for (ActorId a = 0; a < g.actor_count(); ++a) out += "  " + quoted(g.actor_name(a)) + ";\n";
  for (const Channel& c : g.channels()) {
    std::string label = std::to_string(c.prd) + ":" + std::to_string(c.cns);
    if (c.delay != 0) label += " (" + std::to_string(c.delay) + ")";
    out += "  " + quoted(g.actor_name(c.src)) + " -> " + quoted(g.actor_name(c.dst)) +
           " [label=" + quoted(label) + ", tooltip=" + quoted(c.name) + "];\n";
  }
  return out + "}\n";
}

}  // namespace sdf
