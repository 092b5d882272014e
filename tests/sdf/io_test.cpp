#include "sdf/io.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>

#include "helpers.hpp"
#include "sdf/generate.hpp"
#include "sdf/json_detail.hpp"
#include "sdf/naive.hpp"
#include "sdf3_reader_checks.hpp"

namespace sdf {
namespace {

std::string sdf3(const std::string& body) {
  return "<?xml version='1.0'?>\n<sdf3 type='sdf' version='1.0'>\n<applicationGraph name='g'>\n"
         "<sdf name='g' type='g'>\n" +
         body + "</sdf>\n</applicationGraph>\n</sdf3>\n";
}

const char* kTwo =
    "<actor name='A' type='a'><port name='o' type='out' rate='2'/></actor>\n"
    "<actor name='B' type='b'><port name='i' type='in' rate='3'/></actor>\n";

// The error message of reading `text`, or "" if it reads.
std::string sdf3_error(const std::string& text) {
  try {
    read_sdf3(text, "f.xml");
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::input);
    return e.what();
  }
  return "";
}

std::string json_error(const std::string& text) {
  try {
    read_json(text, "f.json");
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::input);
    return e.what();
  }
  return "";
}

bool same_graph(const Graph& a, const Graph& b) {
  if (a.actor_count() != b.actor_count() || a.channel_count() != b.channel_count()) return false;
  for (ActorId x = 0; x < a.actor_count(); ++x)
    if (a.actor_name(x) != b.actor_name(x) || a.actor_time(x) != b.actor_time(x) ||
        (!a.actor_type(x).empty() && a.actor_type(x) != b.actor_type(x)))
      return false;
  for (ChannelId c = 0; c < a.channel_count(); ++c) {
    const Channel &p = a.channel(c), &q = b.channel(c);
    if (p.src != q.src || p.dst != q.dst || p.prd != q.prd || p.cns != q.cns ||
        p.delay != q.delay || a.channel_name(c) != b.channel_name(c))
      return false;
  }
  return true;
}

TEST(Sdf3Reader, ReadsSingleQuotedSdf3WithProperties) {
  const Graph g = read_graph_file(test::data("cd2dat.xml"));
  ASSERT_EQ(g.actor_count(), 6u);
  ASSERT_EQ(g.channel_count(), 5u);
  EXPECT_EQ(g.name, "cd2dat");
  EXPECT_EQ(std::string(g.channel_name(1)), "bc");
  EXPECT_EQ(g.channel(1).prd, 2u);
  EXPECT_EQ(g.channel(1).cns, 3u);
  EXPECT_EQ(std::string(g.src_port(1)), "o");
}

TEST(Sdf3Reader, ReadsCrlfFilesAndCountsTheirLines) {
  const Graph g = read_graph_file(test::data("crlf_loop.xml"));
  ASSERT_EQ(g.channel_count(), 2u);
  EXPECT_EQ(g.channel(1).delay, 2u);
  EXPECT_EQ(g.channel(0).prd, 3u);
  try {
    read_graph_file(test::data("unconnected_port_crlf.xml"));
    FAIL() << "an unconnected port must be rejected";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unconnected_port_crlf.xml:12: port 'spare' of actor 'Y' "
                                         "is not connected"),
              std::string::npos)
        << e.what();
  }
}

TEST(Sdf3Reader, RejectsNamesThatAreNotUtf8) {
  // Found by fuzzing: such a name was read, and writing the graph as JSON then threw.
  EXPECT_NE(sdf3_error(sdf3("<actor name='\xff\xfe'/>\n"))
                .find("f.xml:5: attribute 'name' is not valid UTF-8"),
            std::string::npos);
  EXPECT_NE(sdf3_error(sdf3("<actor name='\xed\xa0\x80'/>\n")).find("not valid UTF-8"),
            std::string::npos);  // a UTF-16 surrogate
  EXPECT_NE(sdf3_error(sdf3("<actor name='\xc0\x80'/>\n")).find("not valid UTF-8"),
            std::string::npos);                                            // overlong
  EXPECT_EQ(sdf3_error(sdf3("<actor name='\xc3\xa9t\xc3\xa9'/>\n")), "");  // "été"
  // The scanner notes bytes above 0x7F 16 bytes at a time: a bad byte at every place of a long
  // name, with a stop ('&', a tab, the other quote) before or after it, and a bad byte just
  // after the closing quote, which belongs to the next value.
  for (const std::string stop : {"", "&amp;", "\t", "\""})
    for (size_t at = 0; at <= 40; ++at) {
      std::string name(40, 'n');
      name.insert(at, "\xff");
      for (const std::string& value : {stop + name, name + stop}) {
        const std::string text = sdf3("<actor name='" + value + "'/>\n");
        EXPECT_NE(sdf3_error(text).find("f.xml:5: attribute 'name' is not valid UTF-8"),
                  std::string::npos)
            << at;
      }
      name.erase(at, 1);
      EXPECT_EQ(sdf3_error(sdf3("<actor name='" + name + "' type='\xc3\xa9'/>\n")), "") << at;
      EXPECT_NE(sdf3_error(sdf3("<actor name='" + name + "' type='\xff'/>\n"))
                    .find("f.xml:5: attribute 'type' is not valid UTF-8"),
                std::string::npos)
          << at;
    }
}

TEST(Sdf3Reader, ElementOrderDoesNotMatter) {
  const Graph g =
      read_sdf3(sdf3("<channel name='c' srcActor='A' srcPort='o' dstActor='B' dstPort='i'/>\n" +
                     std::string(kTwo)));
  EXPECT_EQ(std::string(g.channel_name(0)), "c");
}

TEST(Sdf3Reader, NamesTheLineOfEachMistake) {
  const std::string ch = "<channel name='c' srcActor='A' srcPort='o' dstActor='B' dstPort='i'/>\n";
  // Line 5 is the first body line (after the xml declaration, sdf3, applicationGraph, sdf).
  EXPECT_EQ(sdf3_error(sdf3(std::string(kTwo) + ch)), "");
  EXPECT_NE(sdf3_error(sdf3(kTwo)).find("f.xml:5: port 'o' of actor 'A' is not connected"),
            std::string::npos);
  EXPECT_NE(
      sdf3_error(sdf3(std::string(kTwo) +
                      "<channel name='c' srcActor='A' srcPort='o' dstActor='Z' dstPort='i'/>\n"))
          .find("f.xml:7: channel refers to an unknown actor 'Z'"),
      std::string::npos);
  EXPECT_NE(
      sdf3_error(sdf3(std::string(kTwo) +
                      "<channel name='c' srcActor='A' srcPort='x' dstActor='B' dstPort='i'/>\n"))
          .find("f.xml:7: actor 'A' has no port 'x'"),
      std::string::npos);
  EXPECT_NE(
      sdf3_error(sdf3(std::string(kTwo) +
                      "<channel name='c' srcActor='B' srcPort='i' dstActor='A' dstPort='o'/>\n"))
          .find("is an input port"),
      std::string::npos);
  EXPECT_NE(
      sdf3_error(sdf3(std::string(kTwo) + ch +
                      "<channel name='d' srcActor='A' srcPort='o' dstActor='B' dstPort='i'/>\n"))
          .find("f.xml:8: port 'o' of actor 'A' is already connected to channel 'c'"),
      std::string::npos);
  EXPECT_NE(
      sdf3_error(sdf3("<actor name='A' type='a'><port name='o' type='out' rate='1,2'/></actor>\n"))
          .find("f.xml:5: attribute rate='1,2' is not a positive 64-bit integer (CSDF"),
      std::string::npos);
  EXPECT_NE(
      sdf3_error(sdf3("<actor name='A' type='a'><port name='o' type='out' rate='0'/></actor>\n"))
          .find("f.xml:5: attribute rate='0'"),
      std::string::npos);
  EXPECT_NE(sdf3_error(sdf3("<actor name='A' type='a'><port name='o' type='out' "
                            "rate='99999999999999999999'/></actor>\n"))
                .find("not a positive 64-bit integer"),
            std::string::npos);
  EXPECT_NE(sdf3_error(sdf3("<actor name='A'/>\n<actor name='A'/>\n"))
                .find("f.xml:6: duplicate actor name 'A'"),
            std::string::npos);
  EXPECT_EQ(sdf3_error(sdf3(
                "<actor name='A' type='a'><port name='o' type='out' rate='1'/>"
                "<port name='p' type='out' rate='1'/></actor>\n"
                "<actor name='B' type='b'><port name='i' type='in' rate='1'/>"
                "<port name='j' type='in' rate='1'/></actor>\n" +
                ch + "<channel name='c' srcActor='A' srcPort='p' dstActor='B' dstPort='j'/>\n")),
            "f.xml:8: duplicate channel name 'c'");
  EXPECT_NE(
      sdf3_error(sdf3("<actor type='a'/>\n")).find("f.xml:5: <actor> lacks the attribute 'name'"),
      std::string::npos);
  EXPECT_NE(sdf3_error(std::string(kTwo) + ch).find("f.xml:"), std::string::npos);  // no root
  EXPECT_NE(sdf3_error("<sdf3 type='csdf'><applicationGraph/></sdf3>").find("not supported"),
            std::string::npos);
  EXPECT_NE(sdf3_error(sdf3(kTwo).substr(0, 120)).find("f.xml:"), std::string::npos);  // truncated
  EXPECT_NE(sdf3_error("<sdf3 type=\"sdf\">\r\n<applicationGraph>\r\n<sdf>\r\n<actor name='A' "
                       "x='1\"/>\r\n</sdf></applicationGraph></sdf3>")
                .find("f.xml:4: XML"),
            std::string::npos);
}

// Ports are looked up by name in each actor's ports sorted by name: written in any order, with
// more than eight (a binary search) or fewer (a scan), and a name given twice, in order or not.
TEST(Sdf3Reader, FindsPortsWrittenInAnyOrder) {
  for (const int n : {3, 12}) {
    std::string a = "<actor name='A'>", b = "<actor name='B'>", channels;
    for (int k = n - 1; k >= 0; --k) {  // backwards: z11 ... z0, out of name order
      const std::string p = "z" + std::to_string(k);
      a += "<port name='" + p + "' type='out' rate='" + std::to_string(k + 1) + "'/>";
      b += "<port name='" + p + "' type='in' rate='1'/>";
      channels += "<channel name='c" + std::to_string(k) + "' srcActor='A' srcPort='" + p +
                  "' dstActor='B' dstPort='" + p + "'/>\n";
    }
    const Graph g = read_sdf3(sdf3(a + "</actor>\n" + b + "</actor>\n" + channels), "f.xml");
    ASSERT_EQ(g.channel_count(), static_cast<size_t>(n));
    for (ChannelId c = 0; c < g.channel_count(); ++c)  // channel c_k carries rate k + 1
      EXPECT_EQ(std::to_string(g.channel(c).prd - 1), std::string(g.channel_name(c)).substr(1))
          << n;
  }
  for (const char* ports :
       {"<port name='p' type='out' rate='1'/><port name='p' type='out' rate='1'/>",
        "<port name='q' type='out' rate='1'/><port name='p' type='out' rate='1'/>"
        "<port name='q' type='in' rate='1'/>"})
    EXPECT_NE(sdf3_error(sdf3("<actor name='A'>\n" + std::string(ports) + "</actor>\n"))
                  .find("f.xml:6: duplicate port '"),
              std::string::npos)
        << ports;
}

TEST(JsonReader, ReadsTheDesignForm) {
  const Graph g = read_graph_file(test::data("cd2dat.json"));
  EXPECT_EQ(g.actor_count(), 6u);
  EXPECT_EQ(std::string(g.channel_name(4)), "E->F#0");
  EXPECT_EQ(g.channel(4).prd, 5u);
  const Graph d =
      read_json(R"({"channels":[{"src":"A","dst":"A","prd":1,"cns":1}],"actors":[{"name":"A"}]})");
  EXPECT_EQ(d.channel(0).delay, 0u);  // delay defaults to 0; channels may precede actors
}

TEST(JsonReader, NamesTheFieldOfEachMistake) {
  EXPECT_EQ(json_error(R"({"actors":[{"name":"A"}],"channels":[]})"), "");
  EXPECT_EQ(json_error(R"({"channels":[]})"), "f.json: top level: missing field 'actors'");
  EXPECT_EQ(
      json_error(R"({"actors":[{"name":"A"}],"channels":[{"src":"A","dst":"A","prd":0,"cns":1}]})"),
      "f.json: channels[0].prd: must be positive");
  EXPECT_EQ(json_error(
                R"({"actors":[{"name":"A"}],"channels":[{"src":"A","dst":"A","prd":1,"cns":-1}]})"),
            "f.json: channels[0].cns: must not be negative");
  EXPECT_EQ(
      json_error(
          R"({"actors":[{"name":"A"}],"channels":[{"src":"A","dst":"A","prd":1.5,"cns":1}]})"),
      "f.json: channels[0].prd: '1.5' is not an integer below 2^64");
  EXPECT_EQ(
      json_error(
          R"({"actors":[{"name":"A"}],"channels":[{"src":"A","dst":"A","prd":1,"cns":1,"dely":1}]})"),
      "f.json: channels[0]: unknown field 'dely'");
  EXPECT_EQ(json_error(R"({"actors":[{"name":"A"}],"channels":[{"src":"A","dst":"A","cns":1}]})"),
            "f.json: channels[0]: missing field 'prd'");
  EXPECT_EQ(
      json_error(R"({"actors":[{"name":"A"}],"channels":[{"src":"A","dst":"B","prd":1,"cns":1}]})"),
      "f.json: channels[0].dst: unknown actor 'B'");
  EXPECT_EQ(json_error(R"({"actors":[{"name":"A"},{"name":"A"}]})"),
            "f.json: actors[1].name: duplicate actor name 'A'");
  // Padded names would come back trimmed from SDF3 (found by the JSON fuzzer in CI).
  EXPECT_EQ(json_error(R"({"actors":[{"name":"A"},{"name":" B"}]})"),
            "f.json: actors[1].name: begins or ends with white space");
  EXPECT_EQ(
      json_error(
          R"({"actors":[{"name":"A"}],"channels":[{"src":"A","dst":"A","prd":1,"cns":1,"name":"c\n"}]})"),
      "f.json: channels[0].name: begins or ends with white space");
  EXPECT_EQ(json_error(R"({"actors":[{"name":"A"},{}]})"),
            "f.json: actors[1]: missing field 'name'");
  EXPECT_EQ(json_error(R"({"actors":[{"name":["A"]}]})"),
            "f.json: actors[0].name: unexpected an array");
  EXPECT_EQ(
      json_error(
          R"({"actors":[{"name":"A"}],"channels":[{"src":"A","dst":"A","prd":"1","cns":1}]})"),
      "f.json: channels[0].prd: unexpected a string");
  EXPECT_EQ(
      json_error(
          R"({"actors":[{"name":"A"}],"channels":[{"src":"A","dst":"A","prd":1,"cns":99999999999999999999}]})"),
      "f.json: channels[0].cns: '99999999999999999999' is not an integer below 2^64");
  EXPECT_EQ(json_error("[]"), "f.json: top level: unexpected an array");
  EXPECT_NE(json_error("{\r\n\"actors\": [\r\n{\"name\": \"A\"},\r\n]}")
                .find("f.json: parse error at line 4"),
            std::string::npos);
  EXPECT_NE(json_error("").find("f.json: parse error"), std::string::npos);
}

// The direct scanner against nlohmann's SAX reader: on every text the scanner accepts, the same
// graph or the same error (duplicate or unknown names are found after parsing); read_json, which
// tries the scanner first, always agrees with the SAX reader, and the streaming form of the
// scanner with the scanner. Texts: written random graphs in
// three layouts, with channel names and a graph name, then random byte-level mutations.
TEST(JsonReader, DirectScannerAgreesWithTheSaxReader) {
  crowddb::Rng rng(71);
  const std::string alphabet = "{}[],:\" \n\r\t0123456789-+.eE\\/aAbz#>\x7f\xc3\xa9";
  int accepted = 0, scanned_errors = 0, rejected = 0;
  for (int i = 0; i < 1500; ++i) {
    gen::Spec spec;
    spec.shape = static_cast<gen::Shape>(rng.below(6));
    spec.actors = 1 + static_cast<uint32_t>(rng.below(8));
    Graph g = gen::generate(spec, rng).graph;
    if (rng.below(3) == 0) g.name = "g" + std::to_string(i);
    std::string text = write_json(g);
    if (rng.below(3) == 0) {  // explicit channel and port names, duplicates possible (an error)
      nlohmann::ordered_json j = nlohmann::ordered_json::parse(text);
      for (auto& c : j["channels"]) {
        c["name"] = "c" + std::to_string(rng.below(5));
        if (rng.below(4) == 0) c["src_port"] = "p" + std::to_string(rng.below(3));
      }
      text = j.dump(1);
    }
    if (rng.below(2) == 0)
      text = nlohmann::ordered_json::parse(text).dump(static_cast<int>(rng.below(3)) - 1);
    const int mutations = i % 4 == 0 ? 0 : 1 + static_cast<int>(rng.below(3));
    for (int m = 0; m < mutations && !text.empty(); ++m) {
      const size_t at = rng.below(text.size());
      switch (rng.below(4)) {
        case 0:
          text.erase(at, 1);
          break;
        case 1:
          text.insert(at, 1, alphabet[rng.below(alphabet.size())]);
          break;
        case 2:
          text[at] = alphabet[rng.below(alphabet.size())];
          break;
        default:
          text.insert(at, text.substr(at, rng.below(12)));
          break;
      }
    }
    const std::string sax = test::outcome([&] { return detail::read_json_sax(text, "f.json"); });
    std::optional<std::string> plain;
    try {
      if (auto pg = detail::read_json_plain(text, "f.json"))
        plain = test::outcome([&] { return *pg; });
    } catch (const Error& e) {
      plain = std::string("error: ") + e.what();
    }
    if (plain) {
      EXPECT_EQ(*plain, sax) << text;
      ++(plain->rfind("error: ", 0) == 0 ? scanned_errors : accepted);
    } else {
      ++rejected;
    }
    EXPECT_EQ(test::outcome([&] { return read_json(text, "f.json"); }), sax) << text;
    // Blocks of two: the streaming reader adds and releases in many steps on these small graphs.
    std::optional<std::string> streamed;
    try {
      if (auto sg = detail::read_json_streaming(text, "f.json", nullptr, 2))
        streamed = test::outcome([&] { return *sg; });
    } catch (const Error& e) {
      streamed = std::string("error: ") + e.what();
    }
    EXPECT_EQ(streamed, plain) << text;
  }
  EXPECT_GT(accepted, 300);
  EXPECT_GT(scanned_errors, 20);
  EXPECT_GT(rejected, 300);
}

TEST(Sdf3Reader, StreamingReaderAgreesWithTheDocumentReader) {
  test::streaming_reader_agrees(73, 1500);
}

// Deeply nested <sdfProperties> are written unindented: indentation grows with the depth on
// every line, and 300,000 nested elements (2.1 MB) were written as tens of gigabytes. Shallow
// ones stay indented. (1,000 levels: a regression writes ~1 MB for 7 KB and fails at once.)
TEST(Writers, DeepPropertiesAreWrittenInProportion) {
  const char* kChannel = "<channel name='c' srcActor='A' srcPort='o' dstActor='B' dstPort='i'/>\n";
  const size_t depth = 1000;
  std::string nested;
  for (size_t i = 0; i < depth; ++i) nested += "<b>";
  for (size_t i = 0; i < depth; ++i) nested += "</b>";
  const std::string text =
      "<?xml version='1.0'?>\n<sdf3 type='sdf' version='1.0'>\n<applicationGraph name='g'>\n"
      "<sdf name='g' type='g'>\n" +
      std::string(kTwo) + kChannel + "</sdf>\n<sdfProperties>" + nested +
      "</sdfProperties>\n</applicationGraph>\n</sdf3>\n";
  const Graph g = read_sdf3(text, "f.xml");
  const std::string out = write_sdf3(g);
  EXPECT_LT(out.size(), 2 * text.size());
  EXPECT_EQ(write_sdf3(read_sdf3(out, "out.xml")), out);
  EXPECT_EQ(read_sdf3(out, "out.xml").sdf3_properties, g.sdf3_properties);
  // A real file's properties keep the indented form.
  EXPECT_NE(write_sdf3(read_sdf3(sdf3(std::string(kTwo) + kChannel), "f.xml")).find("\n    <sdf "),
            std::string::npos);
}

// A repeated attribute name: the first one counts, as in the document reader (pugixml), which
// keeps every attribute. The scanner keeps them all too, without comparing each with the
// earlier ones (that was quadratic in a tag's attributes).
TEST(Sdf3Reader, ARepeatedAttributeTakesTheFirstValue) {
  const std::string text = sdf3(
      "<actor name='A' name='Z' type='a'><port name='o' type='out' rate='2' rate='5'/></actor>\n"
      "<actor name='B' type='b' type='c'><port name='i' type='in' rate='3'/></actor>\n"
      "<channel name='c' name='d' srcActor='A' srcPort='o' dstActor='B' dstPort='i'/>\n");
  const Graph g = read_sdf3(text, "f.xml");
  EXPECT_EQ(g.actor_name(0), "A");
  EXPECT_EQ(g.actor_type(1), "b");
  EXPECT_EQ(g.channel(0).prd, 2u);
  EXPECT_EQ(g.channel_name(0), "c");
  EXPECT_EQ(test::outcome([&] { return read_sdf3(text, "f.xml"); }),
            test::outcome([&] { return naive::read_sdf3(text, "f.xml"); }));
}

// Found by fuzzing the streaming reader (inputs in fuzz/corpus/sdf3/): a NUL inside a name was
// kept, and pugixml's writer cut the name there, so the graph changed in a round trip; an actor
// without ports made the duplicate-port check step past an empty vector's null data (UBSan).
TEST(Sdf3Reader, RejectsNulCharactersAndReadsActorsWithoutPorts) {
  const std::string nul = std::string("<channel name='a") + '\0' +
                          "b' srcActor='A' srcPort='o' dstActor='B' dstPort='i'/>\n";
  EXPECT_NE(sdf3_error(sdf3(std::string(kTwo) + nul)).find("f.xml:7: XML: Error parsing attribute"),
            std::string::npos);
  const Graph g = read_sdf3(sdf3("<actor name='X'></actor>\n<actor name='Y'/>\n"));
  EXPECT_EQ(g.actor_count(), 2u);
  EXPECT_NE(sdf3_error(test::slurp(test::data(
                           "../../../fuzz/corpus/sdf3/empty-actor-then-stray-end-tag.xml")))
                .find("f.xml:7: <channel> lacks the attribute 'srcActor'"),
            std::string::npos);
}

// Found by the test above: a mistake inside an actor whose element was still open, with a
// channel naming that actor waiting in the pending block, made the reader resolve the channel
// against the open actor's unfinished port list (out of bounds).
TEST(Sdf3Reader, AMistakeInsideAnActorWithAPendingChannelNamingIt) {
  EXPECT_NE(
      sdf3_error(sdf3("<actor name='A' type='a'><port name='o' type='out' rate='1'/></actor>\n"
                      "<channel name='c' srcActor='A' srcPort='o' dstActor='C' dstPort='i'/>\n"
                      "<actor name='C'><port name='i' type='in'/></actor>\n"))
          .find("f.xml:7: <port> lacks the attribute 'rate'"),
      std::string::npos);
}

// A channel naming a port of the last actor, which has none: the reader fetched that actor's
// first port ahead (ports_[ports_.size()], out of bounds) before finding it missing.
TEST(Sdf3Reader, AChannelToTheLastActorWithoutPorts) {
  EXPECT_EQ(sdf3_error(sdf3("<actor name='A'><port name='o' type='out' rate='1'/></actor>\n"
                            "<actor name='B'/>\n"
                            "<channel name='c' srcActor='A' srcPort='o' dstActor='B' "
                            "dstPort='i'/>\n")),
            "f.xml:7: actor 'B' has no port 'i'");
}

// Errors come in file order as far as the text read tells them: a mistake in a channel that
// waited for a later actor comes before a later mistake once that actor has been seen, and a
// pending block's mistake before a later XML error.
TEST(Sdf3Reader, EarlierMistakesComeFirst) {
  const std::string waiting =
      "<actor name='A'><port name='o' type='out' rate='1'/>"
      "<port name='p' type='out' rate='1'/></actor>\n"
      "<channel name='c' srcActor='A' srcPort='o' dstActor='B' dstPort='i'/>\n"
      "<actor name='B'><port name='i' type='in' rate='1'/><port name='j' type='in' rate='1'/>"
      "</actor>\n"
      "<channel name='d' srcActor='A' srcPort='x' dstActor='B' dstPort='j'/>\n";
  EXPECT_EQ(sdf3_error(sdf3(waiting + "<actor type='t'/>\n")),
            "f.xml:8: actor 'A' has no port 'x'");
  EXPECT_EQ(sdf3_error(sdf3(waiting + "<actor name='C' x='1\"/>\n")),
            "f.xml:8: actor 'A' has no port 'x'");
  // A channel still waiting for an actor the text has not reached cannot be judged yet.
  EXPECT_EQ(sdf3_error(sdf3("<channel name='c' srcActor='A' srcPort='x' dstActor='B' "
                            "dstPort='i'/>\n<actor type='t'/>\n")),
            "f.xml:6: <actor> lacks the attribute 'name'");
  EXPECT_EQ(sdf3_error(sdf3("<actor name='A'/>\n<actor name='A'/>\n<actor name='C' x='1\"/>\n")),
            "f.xml:6: duplicate actor name 'A'");
}

// Texts of a megabyte and more are scanned on a thread of their own beside the builder: a
// mistake the builder finds early (a duplicate actor) stops the scan, one only the end decides
// (a port left unconnected) waits for it, and either is reported as on one thread.
TEST(Sdf3Reader, AScanOnItsOwnThreadReportsAsOnOne) {
  crowddb::Rng rng(5);
  gen::Spec spec;
  spec.shape = gen::Shape::dag;
  spec.actors = 20000;
  const std::string text = write_sdf3(gen::generate(spec, rng).graph);
  ASSERT_GT(text.size(), size_t{1} << 20);  // so that read_sdf3 takes a thread
  const size_t second = text.find("<actor", text.find("<actor") + 1);
  const size_t last_channel = text.rfind("<channel");
  // Mistakes in a channel half way through the channels, where the scan looks up actors and
  // ports ahead of the builder: a port that is not there, and a port connected twice.
  const size_t mid = text.find("<channel", (text.find("<channel") + last_channel) / 2);
  const size_t mid_end = text.find('\n', mid) + 1;
  const std::string mid_line = text.substr(mid, mid_end - mid);
  std::string no_port = text;
  no_port.insert(no_port.find("dstPort=\"", mid) + 9, "no-");
  std::string twice = text;
  twice.insert(mid_end,
               std::regex_replace(mid_line, std::regex("name=\"[^\"]*\""), "name=\"again\""));
  for (const std::string& bad :
       {text.substr(0, second) + "<actor name='a0'/>\n" + text.substr(second),
        text.substr(0, last_channel) + text.substr(text.find('\n', last_channel) + 1), no_port,
        twice, text}) {
    std::string one;
    try {
      (void)detail::read_sdf3_with(bad, "f.xml", nullptr, 1024, detail::ScanThread::caller);
    } catch (const Error& e) {
      one = e.what();
    }
    EXPECT_EQ(sdf3_error(bad), one);
    for (size_t block : {64, 1024})
      for (const detail::ScanThread own :
           {detail::ScanThread::own, detail::ScanThread::own_resolving})
        EXPECT_EQ(test::outcome(
                      [&] { return detail::read_sdf3_with(bad, "f.xml", nullptr, block, own); }),
                  test::outcome([&] {
                    return detail::read_sdf3_with(bad, "f.xml", nullptr, block,
                                                  detail::ScanThread::caller);
                  }))
            << block;
  }
  EXPECT_NE(sdf3_error(text.substr(0, second) + "<actor name='a0'/>\n" + text.substr(second))
                .find("duplicate actor name 'a0'"),
            std::string::npos);
  EXPECT_NE(
      sdf3_error(text.substr(0, last_channel) + text.substr(text.find('\n', last_channel) + 1))
          .find("is not connected to a channel"),
      std::string::npos);
  EXPECT_NE(sdf3_error(no_port).find("has no port 'no-"), std::string::npos) << sdf3_error(no_port);
  EXPECT_NE(sdf3_error(twice).find("is already connected to channel"), std::string::npos)
      << sdf3_error(twice);
}

// The i-th of a series of small generated graphs: every shape in turn, 1 to max_actors actors,
// self-loops on every fourth.
Graph small_graph(int i, uint64_t max_actors, crowddb::Rng& rng) {
  gen::Spec spec;
  spec.shape = static_cast<gen::Shape>(i % 6);
  spec.actors = 1 + static_cast<uint32_t>(rng.below(max_actors));
  spec.self_loops = i % 4 == 0;
  return gen::generate(spec, rng).graph;
}

TEST(Writers, RoundTripRandomGraphsThroughBothFormats) {
  crowddb::Rng rng(7);
  for (int i = 0; i < 60; ++i) {
    const Graph g = small_graph(i, 12, rng);
    const Graph j = read_json(write_json(g));
    EXPECT_TRUE(same_graph(g, j)) << i;
    const Graph x = read_sdf3(write_sdf3(g));
    EXPECT_TRUE(same_graph(g, x)) << i;
    // Port names invented on the first write are kept by the second.
    EXPECT_EQ(write_sdf3(x), write_sdf3(read_sdf3(write_sdf3(x)))) << i;
  }
}

// The streaming writers against their twins, the documents built with pugixml and nlohmann and
// printed whole: the same bytes on random graphs with names of every awkward kind (markup
// characters, quotes, backslashes, control characters, non-ASCII), actor types, times, delays,
// kept <sdfProperties>, actors without ports, and ports named on all, some or none of the
// channels (invented names must avoid the given ones).
TEST(Writers, StreamingWritersMatchTheirTrees) {
  crowddb::Rng rng(31);
  const char* pieces[] = {"a",  "&",    "<",    ">",   "\"",   "'",  "\t",   "\n",
                          "\r", "\x01", "\x1f", "\\",  "\b",   "\f", "\x7f", "\xc3\xa9",
                          " ",  "->",   "#",    "in0", "out1", "]]>"};
  auto word = [&] {
    std::string w = "x";
    for (uint64_t k = rng.below(4); k > 0; --k) w += pieces[rng.below(std::size(pieces))];
    return w;
  };
  for (int i = 0; i < 400; ++i) {
    const Graph base = small_graph(i, 10, rng);
    Graph g;
    if (i % 3 == 0) g.name = word();
    if (i % 5 == 0) g.type = word();
    std::vector<ActorId> ids;
    for (ActorId a = 0; a < base.actor_count(); ++a)
      ids.push_back(g.add_actor(i % 2 ? base.actor_name(a) + word() : base.actor_name(a)));
    if (i % 7 == 0) g.add_actor("lonely");  // no ports: a self-closing element
    if (i % 6 == 0) g.sdf3_properties = "<sdfProperties>" + word() + "</sdfProperties>";
    for (ActorId a = 0; a < base.actor_count(); ++a) {
      if (rng.below(3) == 0) g.set_actor_type(a, word());
      if (rng.below(2) == 0) g.set_actor_time(a, rng.below(1000));
    }
    const int naming = i % 3;  // 0: no port names, 1: all, 2: some
    for (ChannelId c = 0; c < base.channel_count(); ++c) {
      const Channel& ch = base.channel(c);
      const ChannelId id = g.add_channel(ids[ch.src], ids[ch.dst], ch.prd, ch.cns,
                                         rng.below(3) == 0 ? rng.below(50) : 0,
                                         i % 4 == 1 ? word() + std::to_string(c) : std::string());
      if (naming == 1 || (naming == 2 && rng.below(2) == 0))
        g.set_port_names(id, "out" + std::to_string(c % 3) + word() + std::to_string(c),
                         "in" + std::to_string(c % 2) + word() + std::to_string(c));
    }
    ASSERT_EQ(write_sdf3(g), detail::write_sdf3_tree(g)) << i;
    ASSERT_EQ(write_json(g), detail::write_json_tree(g)) << i;
  }
  EXPECT_EQ(write_json(Graph{}), detail::write_json_tree(Graph{}));
  int files = 0;  // and every graph file of the tests (kept <sdfProperties>, SDF3 port names)
  for (const auto& entry : std::filesystem::recursive_directory_iterator(test::data(""))) {
    Graph g;
    try {
      g = read_graph_file(entry.path().string());
    } catch (const Error&) {
      continue;  // the files that test errors
    }
    EXPECT_EQ(write_sdf3(g), detail::write_sdf3_tree(g)) << entry.path();
    EXPECT_EQ(write_json(g), detail::write_json_tree(g)) << entry.path();
    ++files;
  }
  EXPECT_GT(files, 10);
}

// Everything read comes back: names, ports, actor types, execution times and the rest of
// <sdfProperties>, through SDF3, JSON and JSON-then-SDF3, for every graph file of the tests.
TEST(Writers, ConvertLosesNothingOnEveryDataFile) {
  int files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(test::data(""))) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".xml" && ext != ".json") continue;
    Graph g;
    try {
      g = read_graph_file(entry.path().string());
    } catch (const Error&) {
      continue;  // the files of the error tests
    }
    ++files;
    const std::string name = entry.path().filename().string();
    auto check = [&](const Graph& back, const char* route) {
      EXPECT_TRUE(same_graph(g, back)) << name << " via " << route;
      if (!g.name.empty()) {  // SDF3 needs a name: an unnamed graph is written as "graph"
        EXPECT_EQ(g.name, back.name) << name << " via " << route;
        EXPECT_EQ(g.type.empty() ? g.name : g.type, back.type.empty() ? back.name : back.type)
            << name << " via " << route;
      }
      for (ChannelId c = 0; c < g.channel_count(); ++c) {
        if (std::string(g.src_port(c)).empty()) continue;  // invented on write
        EXPECT_EQ(std::string(g.src_port(c)), std::string(back.src_port(c)))
            << name << " via " << route;
        EXPECT_EQ(std::string(g.dst_port(c)), std::string(back.dst_port(c)))
            << name << " via " << route;
      }
      if (!g.sdf3_properties.empty()) {
        EXPECT_EQ(g.sdf3_properties, back.sdf3_properties) << name << " via " << route;
      }
    };
    check(read_sdf3(write_sdf3(g)), "sdf3");
    check(read_json(write_json(g)), "json");
    check(read_sdf3(write_sdf3(read_json(write_json(g)))), "json, sdf3");
    const std::string x = write_sdf3(g);
    EXPECT_EQ(x, write_sdf3(read_sdf3(x))) << name;
  }
  EXPECT_GE(files, 10);
}

TEST(Sdf3Reader, ReadsExecutionTimesBySdf3sRule) {
  const Graph g = read_graph_file(test::data("timed_modem.xml"));
  // src: its only processor is the default; filt: default='false' still counts (the attribute
  // is there); sink: the last of two defaults.
  EXPECT_EQ(g.actor_time(*g.find_actor("src")), 3u);
  EXPECT_EQ(g.actor_time(*g.find_actor("filt")), 2u);
  EXPECT_EQ(g.actor_time(*g.find_actor("sink")), 1u);
  EXPECT_EQ(g.actor_type(*g.find_actor("filt")), "Filter");
  EXPECT_NE(g.sdf3_properties.find("<tokenSize sz=\"32\""), std::string::npos);
  // Without a processor carrying `default`, no time.
  const Graph h = read_sdf3(
      "<sdf3 type='sdf'><applicationGraph><sdf name='g'><actor name='A'/></sdf><sdfProperties>"
      "<actorProperties actor='A'><processor type='p'><executionTime time='4'/></processor>"
      "</actorProperties></sdfProperties></applicationGraph></sdf3>");
  EXPECT_FALSE(h.actor_time(0));
  // A time written into a graph that had none goes where SDF3 reads it.
  Graph k = h;
  k.set_actor_time(0, 9);
  EXPECT_EQ(read_sdf3(write_sdf3(k)).actor_time(0), 9u);
  EXPECT_EQ(
      sdf3_error("<sdf3 type='sdf'><applicationGraph><sdf name='g'><actor name='A'/></sdf>"
                 "<sdfProperties><actorProperties actor='Z'/></sdfProperties></applicationGraph>"
                 "</sdf3>"),
      "f.xml:1: <actorProperties> names an unknown actor 'Z'");
  EXPECT_EQ(sdf3_error("<sdf3 type='sdf'><applicationGraph><sdf name='g'><actor name='A'/></sdf>"
                       "<sdfProperties><actorProperties actor='A'><processor default='1'>"
                       "<executionTime time='-1'/></processor></actorProperties>"
                       "</sdfProperties></applicationGraph></sdf3>"),
            "f.xml:1: attribute time='-1' is not a non-negative 64-bit integer");
}

TEST(JsonReader, ReadsTimesTypesAndPorts) {
  const Graph g = read_json(
      R"({"actors": [{"time": 3, "name": "A", "type": "fir"}, {"name": "B"}],
          "channels": [{"src": "A", "dst": "B", "prd": 1, "cns": 1, "src_port": "o"}]})");
  EXPECT_EQ(g.actor_time(0), 3u);
  EXPECT_FALSE(g.actor_time(1));
  EXPECT_EQ(g.actor_type(0), "fir");
  EXPECT_EQ(std::string(g.src_port(0)), "o");
  // sdf3_properties: times for actors without "time", by SDF3's rule; "time" wins.
  const Graph p = read_json(
      R"({"actors": [{"name": "A", "time": 3}, {"name": "B"}], "sdf3_properties":
          "<sdfProperties><actorProperties actor='A'><processor default='1'><executionTime time='8'/></processor></actorProperties><actorProperties actor='B'><processor default='1'><executionTime time='6'/></processor></actorProperties></sdfProperties>"})");
  EXPECT_EQ(p.actor_time(0), 3u);
  EXPECT_EQ(p.actor_time(1), 6u);
  EXPECT_EQ(read_sdf3(write_sdf3(p)).actor_time(0), 3u);
  EXPECT_EQ(json_error(R"({"actors": [{"name": "A"}], "sdf3_properties": "<sdfProperties>"})"),
            "f.json: sdf3_properties: XML: Start-end tags mismatch");
  EXPECT_EQ(json_error(R"({"actors": [{"name": "A"}], "sdf3_properties": "<x/>"})"),
            "f.json: sdf3_properties: is not one <sdfProperties> element");
  EXPECT_EQ(json_error(R"({"actors": [{"name": "A"}], "sdf3_properties":
                 "<sdfProperties><actorProperties actor='Q'/></sdfProperties>"})"),
            "f.json: sdf3_properties: <actorProperties> names an unknown actor 'Q'");
  EXPECT_EQ(json_error(R"({"actors": [{"name": "A", "time": -2}]})"),
            "f.json: actors[0].time: must not be negative");
  EXPECT_EQ(json_error(R"({"actors": [{"name": "A", "time": 1.5}]})"),
            "f.json: actors[0].time: '1.5' is not an integer below 2^63");
  EXPECT_EQ(json_error(R"({"actors": [{"name": "A", "time": 9223372036854775808}]})"),
            "f.json: actors[0].time: must be below 2^63");
  EXPECT_EQ(json_error(R"({"actors": [{"name": "A", "name": "B"}]})"),
            "f.json: actors[0]: duplicate field 'name'");
  EXPECT_EQ(json_error(R"({"actors": [{"name": "A"}, {"name": "B"}], "channels": [
              {"src": "A", "dst": "B", "prd": 1, "cns": 1, "src_port": "o"},
              {"src": "A", "dst": "B", "prd": 1, "cns": 1, "src_port": "o"}]})"),
            "f.json: channels[1].src_port: actor 'A' already has a port 'o'");
}

TEST(Writers, KeepsSdf3NamesAndWritesDot) {
  const Graph g = read_graph_file(test::data("cd2dat.xml"));
  const Graph j = read_json(write_json(g));
  EXPECT_EQ(std::string(j.channel_name(0)), "ab");  // a non-default name travels as "name"
  const std::string x = write_sdf3(g);
  EXPECT_NE(x.find("srcPort=\"o\""), std::string::npos);
  const std::string dot = write_dot(test::make({"a\"b", "c"}, {{"a\"b", "c", 2, 3, 1}}));
  EXPECT_NE(dot.find("\"a\\\"b\" -> \"c\" [label=\"2:3 (1)\""), std::string::npos) << dot;
}

TEST(GraphFile, ReportsMissingFilesAndUnknownContent) {
  try {
    read_graph_file("/nonexistent/g.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::io);
  }
  const std::string path = test::temp_path("graph.txt");
  std::ofstream(path) << "  {\"actors\":[{\"name\":\"A\"}]}";
  EXPECT_EQ(read_graph_file(path).actor_count(), 1u);  // sniffed as JSON
  std::ofstream(path) << "hello";
  EXPECT_THROW(read_graph_file(path), Error);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace sdf
