// SDF3 XML reading and writing (pugixml). Two passes over <sdf>: actors and their ports first,
// then channels, so element order does not matter. Ports are sorted by (actor, name) and found
// by binary search among their actor's own: O(P log P) for P ports, never the quadratic scan
// that makes SDF3's own loader take minutes on 10^5 actors. Line numbers are computed only for
// an error message.
#include <algorithm>
#include <charconv>
#include <pugixml.hpp>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "sdf/io.hpp"
#include "sdf/text.hpp"

namespace sdf {

namespace {

// Execution times by SDF3's rule: in an actor's <actorProperties>, the last <processor> that
// carries a `default` attribute (whatever its value) gives <executionTime time=...>. Actors
// that already have a time keep it when `keep_times`. The element itself is kept as text for
// the writers. fail(node, message) does not return; number(node, attr) reads a count.
template <class Fail, class Number>
void apply_properties(Graph& g, pugi::xml_node props, Fail&& fail, Number&& number,
                      bool keep_times) {
  for (pugi::xml_node ap : props.children("actorProperties")) {
    const std::string_view name = trim(ap.attribute("actor").value());
    const auto a = g.find_actor(name);
    if (!a) fail(ap, "<actorProperties> names an unknown actor '" + std::string(name) + "'");
    pugi::xml_node chosen;
    for (pugi::xml_node proc : ap.children("processor"))
      if (proc.attribute("default")) chosen = proc;
    if (!chosen) continue;
    const pugi::xml_node et = chosen.child("executionTime");
    if (!et || (keep_times && g.actor_time(*a))) continue;
    const uint64_t t = number(et, "time");
    if (t >= (uint64_t{1} << 63))
      fail(et, "execution time " + std::to_string(t) + " is 2^63 or more");
    g.set_actor_time(*a, t);
  }
  std::ostringstream out;
  props.print(out, "", pugi::format_raw, pugi::encoding_utf8);
  g.sdf3_properties = out.str();
  if (!valid_utf8(g.sdf3_properties)) fail(props, "<sdfProperties> is not valid UTF-8");
}

struct Port {
  ActorId actor;
  std::string_view name;
  bool out;
  uint64_t rate;
  size_t offset;  // of the <port> element; its line is computed only for an error message
  int64_t channel = -1;
};

class Sdf3Reader {
 public:
  Sdf3Reader(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  Graph read(std::string_view text) {
    const pugi::xml_parse_result res =
        doc_.load_buffer(text.data(), text.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!res) fail(static_cast<size_t>(res.offset), std::string("XML: ") + res.description());
    const pugi::xml_node root = doc_.child("sdf3");
    if (!root) fail(0, "no <sdf3> root element");
    const std::string_view type = root.attribute("type").value();
    if (!type.empty() && type != "sdf")
      fail(root, "graph type '" + std::string(type) + "' is not supported (only type=\"sdf\")");
    const pugi::xml_node app = root.child("applicationGraph");
    if (!app) fail(root, "<sdf3> has no <applicationGraph>");
    const pugi::xml_node sdf = app.child("sdf");
    if (!sdf) fail(app, "<applicationGraph> has no <sdf>");
    Graph g;
    g.name = sdf.attribute("name").value();
    if (!valid_utf8(g.name)) fail(sdf, "attribute 'name' is not valid UTF-8");
    g.type = sdf.attribute("type").value();
    if (!valid_utf8(g.type)) fail(sdf, "attribute 'type' is not valid UTF-8");
    for (pugi::xml_node actor : sdf.children("actor")) read_actor(g, actor);
    std::sort(ports_.begin(), ports_.end(), [](const Port& a, const Port& b) {
      return a.actor != b.actor ? a.actor < b.actor : a.name < b.name;
    });
    for (size_t i = 1; i < ports_.size(); ++i)
      if (ports_[i].actor == ports_[i - 1].actor && ports_[i].name == ports_[i - 1].name)
        fail(std::max(ports_[i].offset, ports_[i - 1].offset),
             "duplicate port '" + std::string(ports_[i].name) + "' on actor '" +
                 g.actor_name(ports_[i].actor) + "'");
    port_begin_.assign(g.actor_count() + 1, 0);
    for (const Port& p : ports_) ++port_begin_[p.actor + 1];
    for (size_t a = 0; a < g.actor_count(); ++a) port_begin_[a + 1] += port_begin_[a];
    for (pugi::xml_node ch : sdf.children("channel")) read_channel(g, ch);
    for (const Port& p : ports_)
      if (p.channel < 0)
        fail(p.offset, "port '" + std::string(p.name) + "' of actor '" + g.actor_name(p.actor) +
                           "' is not connected to a channel");
    if (const pugi::xml_node props = app.child("sdfProperties")) read_properties(g, props);
    return g;
  }

 private:
  [[noreturn]] void fail_line(size_t line, const std::string& msg) const {
    throw Error(Error::Kind::input, source_ + ":" + std::to_string(line) + ": " + msg);
  }
  [[noreturn]] void fail(size_t offset, const std::string& msg) const {
    fail_line(LineIndex(text_).line_of(offset), msg);  // built only for the one error
  }
  [[noreturn]] void fail(pugi::xml_node node, const std::string& msg) const {
    fail(static_cast<size_t>(std::max<ptrdiff_t>(0, node.offset_debug())), msg);
  }

  std::string_view required(pugi::xml_node node, const char* attr) const {
    const pugi::xml_attribute a = node.attribute(attr);
    if (!a) fail(node, "<" + std::string(node.name()) + "> lacks the attribute '" + attr + "'");
    const std::string_view v = trim(a.value());
    if (v.empty()) fail(node, "attribute '" + std::string(attr) + "' is empty");
    if (!valid_utf8(v)) fail(node, "attribute '" + std::string(attr) + "' is not valid UTF-8");
    return v;
  }

  uint64_t number(pugi::xml_node node, const char* attr, std::string_view text,
                  bool positive) const {
    uint64_t v = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || ptr != text.data() + text.size() || (positive && v == 0)) {
      std::string msg = "attribute " + std::string(attr) + "='" + std::string(text) +
                        "' is not a " + (positive ? "positive" : "non-negative") +
                        " 64-bit integer";
      if (text.find(',') != std::string_view::npos) msg += " (CSDF rate lists are not supported)";
      fail(node, msg);
    }
    return v;
  }

  void read_actor(Graph& g, pugi::xml_node actor) {
    const std::string_view name = required(actor, "name");
    ActorId id;
    try {
      id = g.add_actor(std::string(name));  // "duplicate actor name '...'"
    } catch (const Error& e) {
      fail(actor, e.what());
    }
    if (const pugi::xml_attribute type = actor.attribute("type")) {
      if (!valid_utf8(type.value())) fail(actor, "attribute 'type' is not valid UTF-8");
      g.set_actor_type(id, type.value());
    }
    for (pugi::xml_node port : actor.children("port")) {
      Port p;
      p.actor = id;
      p.name = required(port, "name");
      const std::string_view type = required(port, "type");
      if (type != "in" && type != "out")
        fail(port, "port type '" + std::string(type) + "' is neither 'in' nor 'out'");
      p.out = type == "out";
      p.rate = number(port, "rate", required(port, "rate"), true);
      p.offset = static_cast<size_t>(std::max<ptrdiff_t>(0, port.offset_debug()));
      ports_.push_back(p);
    }
  }

  void read_properties(Graph& g, pugi::xml_node props) {
    apply_properties(
        g, props, [&](pugi::xml_node n, const std::string& m) { fail(n, m); },
        [&](pugi::xml_node n, const char* attr) {
          return number(n, attr, required(n, attr), false);
        },
        false);
  }

  Port& find_port(const Graph& g, pugi::xml_node ch, ActorId actor, std::string_view name) {
    // The actor's ports are ports_[port_begin_[actor], port_begin_[actor + 1]), sorted by name.
    const auto first = ports_.begin() + static_cast<ptrdiff_t>(port_begin_[actor]);
    const auto last = ports_.begin() + static_cast<ptrdiff_t>(port_begin_[actor + 1]);
    auto it = std::lower_bound(first, last, name,
                               [](const Port& p, std::string_view k) { return p.name < k; });
    if (it == last || it->name != name)
      fail(ch, "actor '" + g.actor_name(actor) + "' has no port '" + std::string(name) + "'");
    return *it;
  }

  void read_channel(Graph& g, pugi::xml_node ch) {
    const pugi::xml_attribute name_attr = ch.attribute("name");
    const std::string name(trim(name_attr.value()));
    if (name_attr && name.empty()) fail(ch, "attribute 'name' is empty");
    if (!valid_utf8(name)) fail(ch, "attribute 'name' is not valid UTF-8");
    auto actor = [&](const char* attr) {
      const std::string_view v = required(ch, attr);
      const auto a = g.find_actor(v);
      if (!a) fail(ch, "channel refers to an unknown actor '" + std::string(v) + "'");
      return *a;
    };
    const ActorId src = actor("srcActor");
    const ActorId dst = actor("dstActor");
    Port& sp = find_port(g, ch, src, required(ch, "srcPort"));
    Port& dp = find_port(g, ch, dst, required(ch, "dstPort"));
    if (!sp.out) fail(ch, "srcPort '" + std::string(sp.name) + "' is an input port");
    if (dp.out) fail(ch, "dstPort '" + std::string(dp.name) + "' is an output port");
    for (Port* p : {&sp, &dp})
      if (p->channel >= 0)
        fail(ch, "port '" + std::string(p->name) + "' of actor '" + g.actor_name(p->actor) +
                     "' is already connected to channel '" +
                     g.channel(static_cast<ChannelId>(p->channel)).name + "'");
    uint64_t delay = 0;
    if (const pugi::xml_attribute t = ch.attribute("initialTokens"))
      delay = number(ch, "initialTokens", trim(t.value()), false);
    ChannelId c;
    try {
      c = g.add_channel(src, dst, sp.rate, dp.rate, delay, name);  // "duplicate channel name"
    } catch (const Error& e) {
      fail(ch, e.what());
    }
    g.set_port_names(c, std::string(sp.name), std::string(dp.name));
    sp.channel = dp.channel = c;
  }

  std::string_view text_;
  const std::string& source_;
  pugi::xml_document doc_;
  std::vector<Port> ports_;
  std::vector<size_t> port_begin_;  // per actor, into ports_ (sorted by actor, then name)
};

// Port names for writing: the ones read, else "in<k>"/"out<k>" avoiding names already taken.
std::vector<std::pair<std::string, std::string>> port_names(const Graph& g) {
  std::vector<std::unordered_set<std::string>> taken(g.actor_count());
  bool any_named = false;
  for (const Channel& c : g.channels()) {
    if (!c.src_port.empty()) taken[c.src].insert(c.src_port), any_named = true;
    if (!c.dst_port.empty()) taken[c.dst].insert(c.dst_port), any_named = true;
  }
  std::vector<uint32_t> next(g.actor_count(), 0);
  auto invent = [&](ActorId a, const char* prefix) {
    for (;;) {
      std::string p = prefix + std::to_string(next[a]++);
      if (!any_named || taken[a].insert(p).second) return p;
    }
  };
  std::vector<std::pair<std::string, std::string>> names(g.channel_count());
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    names[c].first = ch.src_port.empty() ? invent(ch.src, "out") : ch.src_port;
    names[c].second = ch.dst_port.empty() ? invent(ch.dst, "in") : ch.dst_port;
  }
  return names;
}

// <sdfProperties>: the element as read, with every actor's execution time merged in (the graph's
// time wins; it goes into the processor SDF3 would read it from, or a new default processor).
void write_properties(const Graph& g, pugi::xml_node app) {
  pugi::xml_document kept;
  pugi::xml_node props;
  if (!g.sdf3_properties.empty() &&
      kept.load_buffer(g.sdf3_properties.data(), g.sdf3_properties.size(), pugi::parse_default,
                       pugi::encoding_utf8) &&
      kept.child("sdfProperties"))
    props = app.append_copy(kept.child("sdfProperties"));
  else
    props = app.append_child("sdfProperties");
  if (!g.has_actor_times()) return;
  std::unordered_map<std::string_view, pugi::xml_node> by_actor;
  for (pugi::xml_node ap : props.children("actorProperties"))
    by_actor[ap.attribute("actor").value()] = ap;
  for (ActorId a = 0; a < g.actor_count(); ++a) {
    const std::optional<uint64_t> t = g.actor_time(a);
    if (!t) continue;
    pugi::xml_node ap;
    if (auto it = by_actor.find(g.actor_name(a)); it != by_actor.end()) {
      ap = it->second;
    } else {
      ap = props.append_child("actorProperties");
      ap.append_attribute("actor") = g.actor_name(a).c_str();
    }
    pugi::xml_node chosen;
    for (pugi::xml_node proc : ap.children("processor"))
      if (proc.attribute("default")) chosen = proc;
    if (!chosen) {
      chosen = ap.append_child("processor");
      chosen.append_attribute("type") = "default";
      chosen.append_attribute("default") = "true";
    }
    pugi::xml_node et = chosen.child("executionTime");
    if (!et) et = chosen.prepend_child("executionTime");
    pugi::xml_attribute time = et.attribute("time");
    if (!time) time = et.append_attribute("time");
    time = static_cast<unsigned long long>(*t);
  }
}

}  // namespace

namespace detail {

void read_sdf3_properties(Graph& g, std::string_view xml, const std::string& source) {
  auto fail = [&](pugi::xml_node, const std::string& msg) {
    throw Error(Error::Kind::input, source + ": sdf3_properties: " + msg);
  };
  pugi::xml_document doc;
  const pugi::xml_parse_result res =
      doc.load_buffer(xml.data(), xml.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!res) fail({}, std::string("XML: ") + res.description());
  const pugi::xml_node props = doc.first_child();
  if (std::string_view(props.name()) != "sdfProperties" || props.next_sibling())
    fail({}, "is not one <sdfProperties> element");
  auto number = [&](pugi::xml_node n, const char* attr) {
    const std::string_view v = trim(n.attribute(attr).value());
    uint64_t x = 0;
    const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
    if (v.empty() || ec != std::errc() || ptr != v.data() + v.size())
      fail(n, "attribute " + std::string(attr) + "='" + std::string(v) +
                  "' is not a non-negative 64-bit integer");
    return x;
  };
  apply_properties(g, props, fail, number, true);
}

}  // namespace detail

Graph read_sdf3(std::string_view text, const std::string& source) {
  Sdf3Reader reader(text, source);
  return reader.read(text);
}

std::string write_sdf3(const Graph& g) {
  const auto ports = port_names(g);
  const Adjacency adj(g);
  pugi::xml_document doc;
  pugi::xml_node decl = doc.append_child(pugi::node_declaration);
  decl.append_attribute("version") = "1.0";
  decl.append_attribute("encoding") = "UTF-8";
  pugi::xml_node root = doc.append_child("sdf3");
  root.append_attribute("type") = "sdf";
  root.append_attribute("version") = "1.0";
  pugi::xml_node app = root.append_child("applicationGraph");
  const std::string name = g.name.empty() ? "graph" : g.name;
  app.append_attribute("name") = name.c_str();
  pugi::xml_node sdf = app.append_child("sdf");
  sdf.append_attribute("name") = name.c_str();
  sdf.append_attribute("type") = (g.type.empty() ? name : g.type).c_str();
  for (ActorId a = 0; a < g.actor_count(); ++a) {
    pugi::xml_node actor = sdf.append_child("actor");
    actor.append_attribute("name") = g.actor_name(a).c_str();
    const std::string& type = g.actor_type(a);
    actor.append_attribute("type") = (type.empty() ? g.actor_name(a) : type).c_str();
    for (ChannelId c : adj.inputs(a)) {
      pugi::xml_node p = actor.append_child("port");
      p.append_attribute("name") = ports[c].second.c_str();
      p.append_attribute("type") = "in";
      p.append_attribute("rate") = static_cast<unsigned long long>(g.channel(c).cns);
    }
    for (ChannelId c : adj.outputs(a)) {
      pugi::xml_node p = actor.append_child("port");
      p.append_attribute("name") = ports[c].first.c_str();
      p.append_attribute("type") = "out";
      p.append_attribute("rate") = static_cast<unsigned long long>(g.channel(c).prd);
    }
  }
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    pugi::xml_node e = sdf.append_child("channel");
    e.append_attribute("name") = ch.name.c_str();
    e.append_attribute("srcActor") = g.actor_name(ch.src).c_str();
    e.append_attribute("srcPort") = ports[c].first.c_str();
    e.append_attribute("dstActor") = g.actor_name(ch.dst).c_str();
    e.append_attribute("dstPort") = ports[c].second.c_str();
    if (ch.delay != 0)
      e.append_attribute("initialTokens") = static_cast<unsigned long long>(ch.delay);
  }
  write_properties(g, app);
  std::ostringstream out;
  doc.save(out, "  ", pugi::format_default, pugi::encoding_utf8);
  return out.str();
}

}  // namespace sdf
