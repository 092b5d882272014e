// SDF3 reader checks shared by io_test.cpp and io_slow_test.cpp.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/json_detail.hpp"
#include "sdf/naive.hpp"

namespace sdf::test {

// What a reader made of a text: the graph written out (names, rates, delays, channel names) or
// the error message.
inline std::string outcome(const std::function<Graph()>& read) {
  try {
    const Graph g = read();
    std::string out = "graph '" + g.name + "':";
    for (ActorId a = 0; a < g.actor_count(); ++a) out += " " + g.actor_name(a);
    for (ActorId a = 0; a < g.actor_count(); ++a)
      out += " " + g.actor_name(a) + ":" + std::string(g.actor_type(a)) + ":" +
             (g.actor_time(a) ? std::to_string(*g.actor_time(a)) : "-");
    for (ChannelId id = 0; id < g.channel_count(); ++id) {
      const Channel& c = g.channel(id);
      out += " [" + std::to_string(c.src) + ">" + std::to_string(c.dst) + " " +
             std::to_string(c.prd) + "/" + std::to_string(c.cns) + "+" + std::to_string(c.delay) +
             " " + std::string(g.channel_name(id)) + " " + std::string(g.src_port(id)) + " " +
             std::string(g.dst_port(id)) + "]";
    }
    out += " props " + g.sdf3_properties;
    return out;
  } catch (const Error& e) {
    return std::string("error: ") + e.what();
  }
}

// The streaming SDF3 reader against its twin, the document-tree reader it replaced
// (naive::read_sdf3): on written random graphs (times, types, properties, channels before the
// actors, comments, entities, CR LF) and random mutations of them, either both read the same
// graph or both fail. Their messages may differ: the twin reports in two passes, the streaming
// reader in file order.
inline void streaming_reader_agrees(uint64_t seed, int count) {
  crowddb::Rng rng(seed);
  const char* pieces[] = {
      "<",       ">", "/",    "'",        "\"",         "&amp;", "&#65;",  "&lt;",
      "&bogus;", " ", "\r\n", "\t",       "<!-- c -->", "<x/>",  "</sdf>", "<![CDATA[<]]>",
      "<?pi?>",  "=", "a",    "\xc3\xa9", "\xff"};
  int both_read = 0, both_failed = 0, doctype = 0;
  for (int i = 0; i < count; ++i) {
    gen::Spec spec;
    spec.shape = static_cast<gen::Shape>(rng.below(6));
    spec.actors = 1 + static_cast<uint32_t>(rng.below(7));
    spec.self_loops = rng.below(3) == 0;
    Graph g = gen::generate(spec, rng).graph;
    if (rng.below(2) == 0)
      for (ActorId a = 0; a < g.actor_count(); ++a) g.set_actor_time(a, rng.below(100));
    if (rng.below(3) == 0) g.set_actor_type(0, "t&<'\"");
    std::string text = write_sdf3(g);
    if (rng.below(3) == 0) {  // channels before the actors
      const size_t first_channel = text.find("<channel");
      const size_t first_actor = text.find("<actor");
      const size_t end_channels = text.find("</sdf>");
      if (first_channel != std::string::npos && first_actor < first_channel) {
        const std::string channels = text.substr(first_channel, end_channels - first_channel);
        text.erase(first_channel, end_channels - first_channel);
        text.insert(first_actor, channels);
      }
    }
    if (rng.below(4) == 0) {  // CR LF line ends
      std::string crlf;
      for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
      text = crlf;
    }
    static const std::string kDoctype = "<!DOCTYPE sdf3 [ <!ENTITY x 'y'> ]>\n";
    if (rng.below(4) == 0) text.insert(text.find("<sdf3"), kDoctype);
    const int mutations = i % 3 == 0 ? 0 : 1 + static_cast<int>(rng.below(3));
    for (int m = 0; m < mutations && !text.empty(); ++m) {
      const size_t at = rng.below(text.size());
      switch (rng.below(4)) {
        case 0:
          text.erase(at, 1 + rng.below(3));
          break;
        case 1:
          text.insert(at, pieces[rng.below(std::size(pieces))]);
          break;
        case 2:
          text[at] = pieces[rng.below(std::size(pieces))][0];
          break;
        default:
          text.insert(at, text.substr(at, rng.below(40)));
          break;
      }
    }
    const std::string stream = outcome([&] { return read_sdf3(text, "f.xml"); });
    const std::string dom = outcome([&] { return naive::read_sdf3(text, "f.xml"); });
    // The scan on a thread of its own, handing over a few actors or channels at a time: the
    // same graph, or the same first error, as on the calling thread with the same blocks (the
    // block size may change which of two mistakes is found first, the thread may not).
    const size_t block = 1 + static_cast<size_t>(i % 3);
    const std::string caller = outcome([&] {
      return detail::read_sdf3_with(text, "f.xml", nullptr, block, detail::ScanThread::caller);
    });
    for (const detail::ScanThread own :
         {detail::ScanThread::own, detail::ScanThread::own_resolving})
      EXPECT_EQ(outcome([&] { return detail::read_sdf3_with(text, "f.xml", nullptr, block, own); }),
                caller)
          << text;
    EXPECT_EQ(caller.rfind("error: ", 0) == 0, stream.rfind("error: ", 0) == 0) << text;
    if (caller.rfind("error: ", 0) != 0) {
      EXPECT_EQ(caller, stream) << text;
    }
    const bool stream_failed = stream.rfind("error: ", 0) == 0;
    const bool dom_failed = dom.rfind("error: ", 0) == 0;
    if (stream_failed && dom_failed) {
      ++both_failed;
      EXPECT_NE(stream.find("f.xml:"), std::string::npos) << stream;  // a line, always
      continue;
    }
    // A DOCTYPE that a mutation mangled: each reader skips it its own way (the twin as pugixml
    // does), so only there may one read what the other refuses. An intact DOCTYPE, or none, is
    // no excuse.
    const size_t dt = text.find("<!DOCTYPE");
    if (stream_failed != dom_failed && dt != std::string::npos &&
        text.compare(dt, kDoctype.size(), kDoctype) != 0) {
      ++doctype;
      continue;
    }
    EXPECT_EQ(stream, dom) << text;
    if (::testing::Test::HasFailure()) return;
    ++both_read;
  }
  EXPECT_GT(both_read, count * 2 / 5);
  EXPECT_GT(both_failed, count / 5);
  EXPECT_LT(doctype, count / 50 + 3);
}

}  // namespace sdf::test
