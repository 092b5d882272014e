// The two JSON readers behind sdf::read_json, exposed for the tests that compare them, and the
// SDF3 reader's entry for mapped files.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "sdf/graph.hpp"

namespace sdf::detail {

// nlohmann's SAX reader: every JSON text, every error message.
Graph read_json_sax(std::string_view text, const std::string& source);
// The direct scanner of the plain form: nothing when the text is not in it (then the SAX reader
// decides). Errors found after parsing (duplicate or unknown names) are thrown as by the SAX
// reader.
std::optional<Graph> read_json_plain(std::string_view text, const std::string& source);
// read_json_plain that builds the graph as it reads, in blocks of `block` actors or channels,
// and calls release(offset) now and then (as read_sdf3_released) so that the text behind it
// need not stay resident; where the graph refuses a block it reads the text again with
// read_json_plain, which reports the error. Same result and errors as read_json_plain.
std::optional<Graph> read_json_streaming(std::string_view text, const std::string& source,
                                         const std::function<void(size_t)>* release = nullptr,
                                         size_t block = 4096);
// read_json over a mapped file, releasing as read_json_streaming does.
Graph read_json_released(std::string_view text, const std::string& source,
                         const std::function<void(size_t)>& release);

// The JSON form's "sdf3_properties": an <sdfProperties> element as text, checked and read as
// the SDF3 reader does (execution times for the actors that have no "time"; unknown actors are
// errors); kept in g.sdf3_properties. Errors: Error(input) "SOURCE: sdf3_properties: ...".
void read_sdf3_properties(Graph& g, std::string_view xml, const std::string& source);

// read_sdf3 that calls release(offset) now and then with an offset before which it no longer
// needs the text resident (it may still read it: a mapped file's dropped pages come back). The
// file reader drops those pages, so a large file does not stay in memory beside its graph.
Graph read_sdf3_released(std::string_view text, const std::string& source,
                         const std::function<void(size_t)>& release);

// write_json through an nlohmann document, dumped whole: the streaming writer's twin.
std::string write_json_tree(const Graph& g);

// write_sdf3 through a pugixml document tree, printed whole: the streaming writer's twin (the
// same bytes), and its fallback for <sdfProperties> nested too deep to indent.
std::string write_sdf3_tree(const Graph& g);

// Where read_sdf3 runs its scan of the text: on a thread of its own beside the graph builder
// (`own`), on the calling thread (`caller`), or (`automatic`) on its own for texts of a megabyte
// and more on a machine with two or more cores. On its own thread the scan also looks up the
// channels' actors and ports when the builder falls behind; `own_resolving` makes it do so
// whenever it safely can, so that tests reach that path whatever the timing. The graph and the
// first error are the same.
enum class ScanThread { automatic, caller, own, own_resolving };
// read_sdf3 with its knobs: release as read_sdf3_released (may be null); the scan hands the
// builder `block` actors or channels at a time (1024 in read_sdf3).
Graph read_sdf3_with(std::string_view text, const std::string& source,
                     const std::function<void(size_t)>* release, size_t block, ScanThread scan);

}  // namespace sdf::detail
