// The JSON form, read with nlohmann's SAX interface straight into the graph: no document tree,
// so a 10^6-actor file loads in one pass. Channels are kept as names until the end because the
// "channels" array may come before "actors".
#include <nlohmann/json.hpp>
#include <set>

#include "sdf/io.hpp"

namespace sdf {

namespace {

struct PendingChannel {
  std::string src, dst, name;
  uint64_t prd = 0, cns = 0, delay = 0;
  bool has_src = false, has_dst = false, has_prd = false, has_cns = false;
};

class JsonReader : public nlohmann::json_sax<nlohmann::json> {
 public:
  explicit JsonReader(const std::string& source) : source_(source) {}
  Graph graph;
  std::vector<PendingChannel> channels;
  std::vector<std::string> actor_names;

  // Structure: top-level object; "actors" and "channels" arrays of flat objects.
  enum class At { start, top, actors, actor, channels, channel, done };

  bool start_object(std::size_t) override {
    switch (at_) {
      case At::start:
        at_ = At::top;
        return true;
      case At::actors:
        if (!key_.empty()) break;
        at_ = At::actor;
        has_name_ = false;
        return true;
      case At::channels:
        if (!key_.empty()) break;
        at_ = At::channel;
        channels.emplace_back();
        return true;
      default:
        break;
    }
    unexpected("an object");
  }
  bool end_object() override {
    key_.clear();
    switch (at_) {
      case At::top:
        at_ = At::done;
        return true;
      case At::actor:
        if (!has_name_) fail(where() + ": missing field 'name'");
        at_ = At::actors;
        ++index_;
        return true;
      case At::channel: {
        const PendingChannel& c = channels.back();
        for (auto [ok, f] : {std::pair{c.has_src, "src"},
                             {c.has_dst, "dst"},
                             {c.has_prd, "prd"},
                             {c.has_cns, "cns"}})
          if (!ok) fail(where() + ": missing field '" + f + "'");
        at_ = At::channels;
        ++index_;
        return true;
      }
      default:
        unexpected("the end of an object");
    }
  }
  bool start_array(std::size_t) override {
    if (at_ == At::top && key_ == "actors") {
      at_ = At::actors;
    } else if (at_ == At::top && key_ == "channels") {
      at_ = At::channels;
    } else {
      unexpected("an array");
    }
    key_.clear();
    index_ = 0;
    return true;
  }
  bool end_array() override {
    if (at_ != At::actors && at_ != At::channels) unexpected("the end of an array");
    at_ = At::top;
    return true;
  }
  bool key(string_t& k) override {
    key_ = k;
    if (at_ == At::top) {
      if (k == "actors" || k == "channels" || k == "name") {
        if (!seen_top_.insert(k).second) fail("duplicate field '" + k + "'");
        return true;
      }
    } else if (at_ == At::actor) {
      if (k == "name") return true;
    } else if (at_ == At::channel) {
      if (k == "src" || k == "dst" || k == "prd" || k == "cns" || k == "delay" || k == "name")
        return true;
    }
    fail(where() + ": unknown field '" + k + "'");
  }
  bool string(string_t& s) override {
    if (at_ == At::top && key_ == "name") {
      graph.name = s;
    } else if (at_ == At::actor) {
      if (s.empty()) fail(where() + ".name: empty");
      actor_names.push_back(std::move(s));
      has_name_ = true;
    } else if (at_ == At::channel && key_ != "prd" && key_ != "cns" && key_ != "delay") {
      PendingChannel& c = channels.back();
      if (key_ == "src") c.src = std::move(s), c.has_src = true;
      if (key_ == "dst") c.dst = std::move(s), c.has_dst = true;
      if (key_ == "name") {
        if (s.empty()) fail(where() + ".name: empty");
        c.name = std::move(s);
      }
    } else {
      unexpected("a string");
    }
    return true;
  }
  bool number_unsigned(number_unsigned_t v) override {
    if (at_ != At::channel || (key_ != "prd" && key_ != "cns" && key_ != "delay"))
      unexpected("a number");
    PendingChannel& c = channels.back();
    if (key_ != "delay" && v == 0) fail(where() + "." + key_ + ": must be positive");
    if (key_ == "prd") c.prd = v, c.has_prd = true;
    if (key_ == "cns") c.cns = v, c.has_cns = true;
    if (key_ == "delay") c.delay = v;
    return true;
  }
  bool number_integer(number_integer_t v) override {
    if (v >= 0) return number_unsigned(static_cast<number_unsigned_t>(v));
    if (at_ == At::channel) fail(where() + "." + key_ + ": must not be negative");
    unexpected("a number");
  }
  bool number_float(number_float_t, const string_t& s) override {
    if (at_ == At::channel)
      fail(where() + "." + key_ + ": '" + s + "' is not an integer below 2^64");
    unexpected("a number");
  }
  bool null() override { unexpected("null"); }
  bool boolean(bool) override { unexpected("a boolean"); }
  bool binary(binary_t&) override { unexpected("binary data"); }
  bool parse_error(std::size_t, const std::string&,
                   const nlohmann::detail::exception& ex) override {
    // nlohmann's message: "[json.exception.parse_error.101] parse error at line 3, column 5: ..."
    std::string msg = ex.what();
    const auto p = msg.find("parse error");
    if (p != std::string::npos) msg = msg.substr(p);
    fail(msg);
  }

  bool saw_actors() const { return seen_top_.count("actors") != 0; }
  [[noreturn]] void fail(const std::string& msg) const {
    throw Error(Error::Kind::input, source_ + ": " + msg);
  }

 private:
  std::string where() const {
    if (at_ == At::actor) return "actors[" + std::to_string(index_) + "]";
    if (at_ == At::channel) return "channels[" + std::to_string(index_) + "]";
    return "top level";
  }
  [[noreturn]] void unexpected(const char* what) const {
    std::string field = where();
    if (!key_.empty()) field += (at_ == At::top ? ": field '" + key_ + "'" : "." + key_);
    fail(field + ": unexpected " + what);
  }

  const std::string& source_;
  At at_ = At::start;
  std::string key_;
  size_t index_ = 0;
  bool has_name_ = false;
  std::set<std::string> seen_top_;
};

}  // namespace

Graph read_json(std::string_view text, const std::string& source) {
  JsonReader r(source);
  nlohmann::json::sax_parse(text.begin(), text.end(), &r);
  if (!r.saw_actors()) r.fail("top level: missing field 'actors'");
  Graph& g = r.graph;
  for (size_t i = 0; i < r.actor_names.size(); ++i) {
    if (g.find_actor(r.actor_names[i]))
      r.fail("actors[" + std::to_string(i) + "].name: duplicate actor name '" + r.actor_names[i] +
             "'");
    g.add_actor(std::move(r.actor_names[i]));
  }
  for (size_t i = 0; i < r.channels.size(); ++i) {
    const PendingChannel& c = r.channels[i];
    const std::string at = "channels[" + std::to_string(i) + "]";
    const auto src = g.find_actor(c.src);
    if (!src) r.fail(at + ".src: unknown actor '" + c.src + "'");
    const auto dst = g.find_actor(c.dst);
    if (!dst) r.fail(at + ".dst: unknown actor '" + c.dst + "'");
    try {
      g.add_channel(*src, *dst, c.prd, c.cns, c.delay, c.name);
    } catch (const Error& e) {
      r.fail(at + ": " + e.what());
    }
  }
  return std::move(r.graph);
}

std::string write_json(const Graph& g) {
  nlohmann::ordered_json j;
  if (!g.name.empty()) j["name"] = g.name;
  auto& actors = j["actors"] = nlohmann::ordered_json::array();
  for (ActorId a = 0; a < g.actor_count(); ++a) actors.push_back({{"name", g.actor_name(a)}});
  auto& channels = j["channels"] = nlohmann::ordered_json::array();
  std::unordered_map<uint64_t, uint32_t> parallel;
  for (const Channel& c : g.channels()) {
    nlohmann::ordered_json e = {{"src", g.actor_name(c.src)},
                                {"dst", g.actor_name(c.dst)},
                                {"prd", c.prd},
                                {"cns", c.cns},
                                {"delay", c.delay}};
    const uint32_t k = parallel[(static_cast<uint64_t>(c.src) << 32) | c.dst]++;
    if (c.name != g.actor_name(c.src) + "->" + g.actor_name(c.dst) + "#" + std::to_string(k))
      e["name"] = c.name;
    channels.push_back(std::move(e));
  }
  return j.dump(1) + "\n";
}

}  // namespace sdf
