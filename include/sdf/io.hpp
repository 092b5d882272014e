// Graph files: SDF3 XML (read and write), the JSON form of DESIGN §8 (read and write), and DOT
// (write) for Graphviz.
//
// SDF3 subset read: <sdf3 type="sdf"> / <applicationGraph> / <sdf name=...> holding <actor
// name=... type=...> elements with <port name=... type="in|out" rate=N/> children and <channel
// name=... srcActor=... srcPort=... dstActor=... dstPort=... [initialTokens=N]/> elements. Every
// port must be connected to exactly one channel of the right direction; CSDF rate lists are
// rejected. <sdfProperties> gives the actors' execution times (SDF3's rule: the last <processor>
// carrying a `default` attribute) and is kept whole as text; written files carry it back with the
// graph's times merged in.
//
// JSON form: {"actors":[{"name":"A","time":3},...], "channels":[{"src":"A","dst":"B","prd":2,
// "cns":3,"delay":0},...]}; optional "type" (graph, actor), "time" (actor), "src_port"/"dst_port"
// (channel) and "sdf3_properties" (docs/sdf.md). "delay" defaults to 0; a channel may carry an
// optional "name" (written only when it differs from the default `src->dst#k`), the top level an
// optional "name". Unknown fields are errors (they are usually typos).
//
// Errors: Error(input) whose what() is one line "FILE:LINE: message" (XML; JSON syntax errors)
// or "FILE: channels[3].prd: message" (JSON fields). Loading is O(size) for both formats: names
// resolve through hash maps, ports through a per-actor list.
//
// Thread-safety: pure functions. read_sdf3 (and read_graph_file on SDF3) scans a text of a
// megabyte or more on a second thread of its own while the calling thread builds the graph, when
// the machine has two cores or more; it joins it before returning or throwing. The graph and the
// first error are the same as on one thread.
#pragma once

#include <string>
#include <string_view>

#include "sdf/graph.hpp"

namespace sdf {

// `source` is the name used in error messages (usually the file path).
Graph read_sdf3(std::string_view text, const std::string& source = "<sdf3>");
Graph read_json(std::string_view text, const std::string& source = "<json>");
// By extension: .xml is SDF3, .json the JSON form; otherwise by the first non-blank character.
// Throws Error(io) when the file cannot be read.
Graph read_graph_file(const std::string& path);

std::string write_sdf3(const Graph& g);
std::string write_json(const Graph& g);
std::string write_dot(const Graph& g);

}  // namespace sdf
