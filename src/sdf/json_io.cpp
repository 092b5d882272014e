// The JSON form. Two readers feed the same graph-building step:
//  - a direct scanner for the plain form (ASCII strings without escapes, non-negative integers,
//    the known fields each at most once, nothing missing): one pass over the bytes, names kept as
//    views into the text. It does not report errors: on anything else it gives up, and
//  - nlohmann's SAX interface (no document tree) reads the text again, accepting what JSON
//    allows and producing every error message (line and column, field).
// Both produce the same actor names and channels in the same order for every text the scanner
// accepts (tests/sdf/io_test.cpp compares them on random and mutated texts), so the graph and
// its errors do not depend on which reader ran. Channels are kept as names until the end
// because the "channels" array may come before "actors".
#include <charconv>
#include <nlohmann/json.hpp>
#include <set>
#include <tuple>
#include <unordered_map>

#include "sdf/io.hpp"
#include "sdf/json_detail.hpp"
#include "sdf/text.hpp"

namespace sdf {

namespace {

constexpr uint64_t kNoTime = UINT64_MAX;
constexpr uint64_t kTimeLimit = uint64_t{1} << 63;

struct PendingChannel {
  std::string src, dst, name, src_port, dst_port;
  uint64_t prd = 0, cns = 0, delay = 0;
  bool has_src = false, has_dst = false, has_prd = false, has_cns = false;
};

class JsonReader : public nlohmann::json_sax<nlohmann::json> {
 public:
  explicit JsonReader(const std::string& source) : source_(source) {}
  Graph graph;
  std::vector<PendingChannel> channels;
  std::vector<std::string> actor_names;
  std::vector<std::string> actor_types;  // "" = unset
  std::vector<uint64_t> actor_times;     // kNoTime = unset
  std::string sdf3_properties;

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
        actor_fields_ = 0;
        actor_types.emplace_back();
        actor_times.push_back(kNoTime);
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
      if (k == "actors" || k == "channels" || k == "name" || k == "type" ||
          k == "sdf3_properties") {
        if (!seen_top_.insert(k).second) fail("duplicate field '" + k + "'");
        return true;
      }
    } else if (at_ == At::actor) {
      const unsigned bit = k == "name" ? 1 : k == "type" ? 2 : k == "time" ? 4 : 0;
      if (bit != 0) {
        if (actor_fields_ & bit) fail(where() + ": duplicate field '" + k + "'");
        actor_fields_ |= bit;
        return true;
      }
    } else if (at_ == At::channel) {
      if (k == "src" || k == "dst" || k == "prd" || k == "cns" || k == "delay" || k == "name" ||
          k == "src_port" || k == "dst_port")
        return true;
    }
    fail(where() + ": unknown field '" + k + "'");
  }
  bool string(string_t& s) override {
    if (at_ == At::top && key_ == "name") {
      graph.name = s;
    } else if (at_ == At::top && key_ == "type") {
      graph.type = s;
    } else if (at_ == At::top && key_ == "sdf3_properties") {
      sdf3_properties = std::move(s);
    } else if (at_ == At::actor && key_ == "type") {
      actor_types.back() = std::move(s);
    } else if (at_ == At::actor && key_ == "name") {
      if (s.empty()) fail(where() + ".name: empty");
      if (padded(s)) fail(where() + ".name: begins or ends with white space");
      actor_names.push_back(std::move(s));
      has_name_ = true;
    } else if (at_ == At::channel && key_ != "prd" && key_ != "cns" && key_ != "delay") {
      PendingChannel& c = channels.back();
      if (key_ == "src") c.src = std::move(s), c.has_src = true;
      if (key_ == "dst") c.dst = std::move(s), c.has_dst = true;
      if (key_ == "name" || key_ == "src_port" || key_ == "dst_port") {
        if (s.empty()) fail(where() + "." + key_ + ": empty");
        if (padded(s)) fail(where() + "." + key_ + ": begins or ends with white space");
        (key_ == "name" ? c.name : key_ == "src_port" ? c.src_port : c.dst_port) = std::move(s);
      }
    } else {
      unexpected("a string");
    }
    return true;
  }
  bool number_unsigned(number_unsigned_t v) override {
    if (at_ == At::actor && key_ == "time") {
      if (v >= kTimeLimit) fail(where() + ".time: must be below 2^63");
      actor_times.back() = v;
      return true;
    }
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
    if (at_ == At::channel || (at_ == At::actor && key_ == "time"))
      fail(where() + "." + key_ + ": must not be negative");
    unexpected("a number");
  }
  bool number_float(number_float_t, const string_t& s) override {
    if (at_ == At::channel)
      fail(where() + "." + key_ + ": '" + s + "' is not an integer below 2^64");
    if (at_ == At::actor && key_ == "time")
      fail(where() + ".time: '" + s + "' is not an integer below 2^63");
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
  unsigned actor_fields_ = 0;  // name, type, time seen in the current actor
  std::set<std::string> seen_top_;
};

}  // namespace

namespace {

struct ChannelView {
  std::string_view src, dst, name, src_port, dst_port;
  uint64_t prd = 0, cns = 0, delay = 0;
};

struct Parsed {
  std::string graph_name;
  std::string graph_type;
  std::string sdf3_properties;
  std::vector<std::string_view> actors;
  // Parallel to actors, or empty when no actor has one.
  std::vector<std::string_view> actor_types;  // "" = unset
  std::vector<uint64_t> actor_times;          // kNoTime = unset
  std::vector<ChannelView> channels;
};

// The graph from parsed names; the errors found only once everything is read (duplicate
// actors, unknown actors, duplicate channel names).
Graph build(Parsed& p, const std::string& source) {
  auto fail = [&](const std::string& msg) { throw Error(Error::Kind::input, source + ": " + msg); };
  Graph g;
  g.name = std::move(p.graph_name);
  g.type = std::move(p.graph_type);
  g.reserve(p.actors.size(), p.channels.size());
  if (const size_t i = g.add_actors(p.actors); i < p.actors.size())
    fail("actors[" + std::to_string(i) + "].name: duplicate actor name '" +
         std::string(p.actors[i]) + "'");
  for (size_t a = 0; a < p.actor_types.size(); ++a)
    if (!p.actor_types[a].empty()) g.set_actor_type(static_cast<ActorId>(a), p.actor_types[a]);
  for (size_t a = 0; a < p.actor_times.size(); ++a)
    if (p.actor_times[a] != kNoTime) g.set_actor_time(static_cast<ActorId>(a), p.actor_times[a]);
  // A block at a time: resolve the names (Graph::find_actors overlaps the probes), add the
  // channels before the first unknown name, then report the first failure in file order.
  constexpr size_t kBlock = 4096;
  std::vector<std::string_view> names;
  std::vector<int64_t> ids(2 * kBlock);
  std::vector<Graph::NewChannel> batch;
  names.reserve(2 * kBlock);
  batch.reserve(kBlock);
  for (size_t b = 0; b < p.channels.size(); b += kBlock) {
    const size_t end = std::min(p.channels.size(), b + kBlock);
    names.clear();
    for (size_t i = b; i < end; ++i) {
      names.push_back(p.channels[i].src);
      names.push_back(p.channels[i].dst);
    }
    g.find_actors(names, std::span(ids).first(names.size()));
    batch.clear();
    for (size_t i = b; i < end && ids[2 * (i - b)] >= 0 && ids[2 * (i - b) + 1] >= 0; ++i) {
      const ChannelView& c = p.channels[i];
      batch.push_back({static_cast<ActorId>(ids[2 * (i - b)]),
                       static_cast<ActorId>(ids[2 * (i - b) + 1]), c.prd, c.cns, c.delay, c.name});
    }
    const size_t added = g.add_channels(batch);
    for (size_t k = 0; k < added; ++k) {
      const ChannelView& c = p.channels[b + k];
      if (!c.src_port.empty() || !c.dst_port.empty())
        g.set_port_names(static_cast<ChannelId>(b + k), c.src_port, c.dst_port);
    }
    const size_t i = b + added;
    if (i == end) continue;
    const ChannelView& c = p.channels[i];
    if (added < batch.size()) {  // rejected by the graph: add_channel says why
      try {
        g.add_channel(batch[added].src, batch[added].dst, c.prd, c.cns, c.delay,
                      std::string(c.name));
      } catch (const Error& e) {
        fail("channels[" + std::to_string(i) + "]: " + e.what());
      }
    }
    if (ids[2 * (i - b)] < 0)
      fail("channels[" + std::to_string(i) + "].src: unknown actor '" + std::string(c.src) + "'");
    fail("channels[" + std::to_string(i) + "].dst: unknown actor '" + std::string(c.dst) + "'");
  }
  if (!p.sdf3_properties.empty()) detail::read_sdf3_properties(g, p.sdf3_properties, source);
  // A port belongs to one channel: the names given must be unique per actor (SDF3 would refuse
  // the file written from them).
  std::set<std::pair<ActorId, std::string_view>> ports;
  for (size_t i = 0; i < p.channels.size(); ++i) {
    const Channel& c = g.channel(static_cast<ChannelId>(i));
    for (const auto& [actor, port, field] : {std::tuple{c.src, p.channels[i].src_port, "src_port"},
                                             std::tuple{c.dst, p.channels[i].dst_port, "dst_port"}})
      if (!port.empty() && !ports.insert({actor, port}).second)
        fail("channels[" + std::to_string(i) + "]." + field + ": actor '" + g.actor_name(actor) +
             "' already has a port '" + std::string(port) + "'");
  }
  return g;
}

// Builds the graph while the scanner reads, so that neither the text nor views into it stay in
// memory: actors, then channels, are added in blocks, and the text before a block is released
// once the block is in the graph. It builds what build() would from the same text, but does not
// report errors: at anything build() might refuse (a duplicate or unknown name, a port name used
// twice) or cannot judge yet (channels before actors) it stops with `retry` set, and build()
// then reads the text again for the error. Errors are rare; the common case reads the text once.
class Streamer {
 public:
  Streamer(std::string_view text, const std::function<void(size_t)>* release, size_t block)
      : text_(text), release_(release), block_(block) {
    actors_.reserve(block);
    channels_.reserve(block);
  }
  bool retry = false;
  bool actors_done = false;  // every actor is in the graph; channels may come
  Graph g;

  bool actor(std::string_view name, std::string_view type, uint64_t time, const char* at) {
    actors_.push_back({name, type, time});
    return actors_.size() < block_ || flush_actors(at);
  }
  bool flush_actors(const char* at) {
    names_.clear();
    for (const ActorView& a : actors_) names_.push_back(a.name);
    const auto base = static_cast<ActorId>(g.actor_count());
    if (g.add_actors(names_) < names_.size()) return stop();
    for (size_t i = 0; i < actors_.size(); ++i) {
      if (!actors_[i].type.empty())
        g.set_actor_type(base + static_cast<ActorId>(i), actors_[i].type);
      if (actors_[i].time != kNoTime)
        g.set_actor_time(base + static_cast<ActorId>(i), actors_[i].time);
    }
    actors_.clear();
    release(at);
    return true;
  }
  bool channel(const ChannelView& c, const char* at) {
    if (!actors_done) return stop();
    channels_.push_back(c);
    return channels_.size() < block_ || flush_channels(at);
  }
  bool flush_channels(const char* at) {
    if (channels_.empty()) return true;
    if (!reserved_) {
      // Room for as many channels as the rest of the text holds at the first block's density
      // (bounded by the shortest channel a valid text can have), so the tables do not regrow.
      // No margin: the tables are zeroed, hence resident, and a margin that crosses a power of
      // two doubles them; a longer tail costs one rehash.
      reserved_ = true;
      const auto done = static_cast<size_t>(at - first_channel_);
      const auto rest = static_cast<size_t>(text_.data() + text_.size() - at);
      const size_t per = std::max<size_t>(done / channels_.size(), 40);
      g.reserve(g.actor_count(), g.channel_count() + channels_.size() + rest / per);
    }
    names_.clear();
    for (const ChannelView& c : channels_) {
      names_.push_back(c.src);
      names_.push_back(c.dst);
    }
    ids_.resize(names_.size());
    g.find_actors(names_, ids_);
    batch_.clear();
    for (size_t i = 0; i < channels_.size(); ++i) {
      const ChannelView& c = channels_[i];
      if (ids_[2 * i] < 0 || ids_[2 * i + 1] < 0) return stop();
      batch_.push_back({static_cast<ActorId>(ids_[2 * i]), static_cast<ActorId>(ids_[2 * i + 1]),
                        c.prd, c.cns, c.delay, c.name});
    }
    const auto base = static_cast<ChannelId>(g.channel_count());
    if (g.add_channels(batch_) < batch_.size()) return stop();
    for (size_t i = 0; i < channels_.size(); ++i)
      if (!channels_[i].src_port.empty() || !channels_[i].dst_port.empty()) {
        g.set_port_names(base + static_cast<ChannelId>(i), channels_[i].src_port,
                         channels_[i].dst_port);
        ports_ = true;
      }
    channels_.clear();
    release(at);
    return true;
  }
  void channels_start(const char* at) { first_channel_ = at; }
  // After the last block: the port names given must be unique per actor, as build() checks.
  bool finish() {
    if (!ports_) return true;
    std::set<std::pair<ActorId, std::string_view>> seen;
    for (ChannelId c = 0; c < g.channel_count(); ++c)
      for (const auto& [actor, port] :
           {std::pair{g.channel(c).src, g.src_port(c)}, std::pair{g.channel(c).dst, g.dst_port(c)}})
        if (!port.empty() && !seen.insert({actor, port}).second) return stop();
    return true;
  }

 private:
  struct ActorView {
    std::string_view name, type;
    uint64_t time;
  };
  bool stop() {
    retry = true;
    return false;
  }
  void release(const char* at) {
    const auto offset = static_cast<size_t>(at - text_.data());
    if (release_ && offset >= released_ + kReleaseStep) {
      (*release_)(offset);
      released_ = offset;
    }
  }
  static constexpr size_t kReleaseStep = size_t{16} << 20;
  std::string_view text_;
  const std::function<void(size_t)>* release_;
  size_t block_, released_ = 0;
  bool reserved_ = false, ports_ = false;
  const char* first_channel_ = nullptr;
  std::vector<ActorView> actors_;
  std::vector<ChannelView> channels_;
  std::vector<std::string_view> names_;
  std::vector<int64_t> ids_;
  std::vector<Graph::NewChannel> batch_;
};

// The direct scanner of the plain form; false as soon as the text leaves it. With a streamer,
// the actors and channels go to it instead of `Parsed` (false also when it stops).
class Scanner {
 public:
  explicit Scanner(std::string_view text, Streamer* stream = nullptr)
      : p_(text.data()), end_(text.data() + text.size()), stream_(stream) {}

  bool parse(Parsed& out) {
    bool seen_actors = false, seen_channels = false, seen_name = false;
    if (!skip_to('{')) return false;
    if (!peek_is('}')) {
      for (;;) {
        std::string_view k;
        if (!string(k) || !skip_to(':')) return false;
        if (k == "actors") {
          if (seen_actors) return false;
          seen_actors = true;
          if (!actors(out)) return false;
        } else if (k == "channels") {
          if (seen_channels) return false;
          seen_channels = true;
          if (!channels(out)) return false;
        } else if (k == "name") {
          std::string_view v;
          if (seen_name || !string(v)) return false;
          seen_name = true;
          out.graph_name = v;
        } else {
          return false;
        }
        if (peek_is(',')) continue;
        break;
      }
    }
    if (!skip_to('}')) return false;
    skip_space();
    return p_ == end_ && seen_actors;
  }

 private:
  void skip_space() {
    while (p_ != end_ && (*p_ == ' ' || *p_ == '\n' || *p_ == '\r' || *p_ == '\t')) ++p_;
  }
  // Skips blanks and the character c.
  bool skip_to(char c) {
    skip_space();
    if (p_ == end_ || *p_ != c) return false;
    ++p_;
    return true;
  }
  // Skips blanks, then c if it is next.
  bool peek_is(char c) {
    skip_space();
    if (p_ != end_ && *p_ == c) {
      ++p_;
      return true;
    }
    return false;
  }
  // A string of printable ASCII without escapes.
  bool string(std::string_view& out) {
    if (!skip_to('"')) return false;
    const char* start = p_;
    while (p_ != end_ && *p_ != '"') {
      const auto c = static_cast<unsigned char>(*p_);
      if (c < 0x20 || c >= 0x80 || c == '\\') return false;
      ++p_;
    }
    if (p_ == end_) return false;
    out = std::string_view(start, static_cast<size_t>(p_ - start));
    ++p_;
    return true;
  }
  // A non-negative integer below 2^64 in JSON's form (no leading zeros, no fraction, no exponent).
  bool number(uint64_t& out) {
    skip_space();
    if (p_ == end_ || *p_ < '0' || *p_ > '9') return false;
    uint64_t v = 0;
    const char* start = p_;
    while (p_ != end_ && *p_ >= '0' && *p_ <= '9') {
      if (__builtin_mul_overflow(v, uint64_t{10}, &v) ||
          __builtin_add_overflow(v, static_cast<uint64_t>(*p_ - '0'), &v))
        return false;
      ++p_;
    }
    if (*start == '0' && p_ - start > 1) return false;
    if (p_ != end_ && (*p_ == '.' || *p_ == 'e' || *p_ == 'E')) return false;
    out = v;
    return true;
  }
  // One object of known fields in any order, each at most once: field(key) reads the value and
  // returns the field's bit, 0 for an unknown key or a value outside the plain form.
  template <class Field>
  bool object(Field&& field, unsigned& seen) {
    if (!skip_to('{')) return false;
    seen = 0;
    do {
      std::string_view k;
      if (!string(k) || !skip_to(':')) return false;
      const unsigned bit = field(k);
      if (bit == 0 || (seen & bit)) return false;
      seen |= bit;
    } while (peek_is(','));
    return skip_to('}');
  }
  // A name as the plain form has it: not empty, no white space at either end.
  bool name(std::string_view& out) { return string(out) && !out.empty() && !padded(out); }

  // Actor objects: "name" with an optional "type" and "time".
  bool actors(Parsed& out) {
    if (!skip_to('[')) return false;
    if (peek_is(']')) return true;
    do {
      std::string_view actor, type;
      uint64_t time = kNoTime;
      unsigned seen;
      auto field = [&](std::string_view k) -> unsigned {
        if (k == "name") return name(actor) ? 1 : 0;
        if (k == "type") return string(type) ? 2 : 0;
        if (k == "time") return number(time) && time < kTimeLimit ? 4 : 0;
        return 0;
      };
      if (!object(field, seen) || !(seen & 1)) return false;
      if (stream_) {
        if (!stream_->actor(actor, type, time, p_)) return false;
        continue;
      }
      out.actors.push_back(actor);
      if (seen & 2) {
        out.actor_types.resize(out.actors.size());
        out.actor_types.back() = type;
      }
      if (seen & 4) {
        out.actor_times.resize(out.actors.size(), kNoTime);
        out.actor_times.back() = time;
      }
    } while (peek_is(','));
    if (!skip_to(']')) return false;
    if (stream_ && !stream_->flush_actors(p_)) return false;
    if (stream_) stream_->actors_done = true;
    return true;
  }
  bool channels(Parsed& out) {
    if (!skip_to('[')) return false;
    if (stream_) stream_->channels_start(p_);
    if (peek_is(']')) return true;
    do {
      ChannelView c;
      unsigned seen;
      auto field = [&](std::string_view k) -> unsigned {
        if (k == "src") return string(c.src) ? 1 : 0;
        if (k == "dst") return string(c.dst) ? 2 : 0;
        if (k == "prd") return number(c.prd) && c.prd != 0 ? 4 : 0;
        if (k == "cns") return number(c.cns) && c.cns != 0 ? 8 : 0;
        if (k == "delay") return number(c.delay) ? 16 : 0;
        if (k == "name") return name(c.name) ? 32 : 0;
        if (k == "src_port") return name(c.src_port) ? 64 : 0;
        if (k == "dst_port") return name(c.dst_port) ? 128 : 0;
        return 0;
      };
      if (!object(field, seen) || (seen & 15) != 15) return false;
      if (stream_) {
        if (!stream_->channel(c, p_)) return false;
        continue;
      }
      out.channels.push_back(c);
    } while (peek_is(','));
    if (!skip_to(']')) return false;
    return !stream_ || stream_->flush_channels(p_);
  }

  const char* p_;
  const char* end_;
  Streamer* stream_;
};

}  // namespace

namespace detail {

Graph read_json_sax(std::string_view text, const std::string& source) {
  JsonReader r(source);
  nlohmann::json::sax_parse(text.begin(), text.end(), &r);
  if (!r.saw_actors()) r.fail("top level: missing field 'actors'");
  Parsed p;
  p.graph_name = std::move(r.graph.name);
  p.graph_type = std::move(r.graph.type);
  p.sdf3_properties = std::move(r.sdf3_properties);
  p.actors.assign(r.actor_names.begin(), r.actor_names.end());
  p.actor_types.assign(r.actor_types.begin(), r.actor_types.end());
  p.actor_times = std::move(r.actor_times);
  p.channels.reserve(r.channels.size());
  for (const PendingChannel& c : r.channels)
    p.channels.push_back({c.src, c.dst, c.name, c.src_port, c.dst_port, c.prd, c.cns, c.delay});
  return build(p, source);
}

std::optional<Graph> read_json_streaming(std::string_view text, const std::string& source,
                                         const std::function<void(size_t)>* release, size_t block) {
  {
    Streamer s(text, release, block);
    Parsed p;
    const bool ok = Scanner(text, &s).parse(p);
    if (ok && s.finish()) {
      s.g.name = std::move(p.graph_name);
      return std::move(s.g);
    }
    if (!s.retry) return std::nullopt;  // not the plain form
  }
  return read_json_plain(text, source);  // an error to report, or channels before actors
}

std::optional<Graph> read_json_plain(std::string_view text, const std::string& source) {
  Parsed p;
  // Rough sizes from the file length, so the vectors do not grow in steps (a written actor
  // takes at least ~20 bytes, a channel ~70).
  p.actors.reserve(text.size() / 64);
  p.channels.reserve(text.size() / 128);
  if (!Scanner(text).parse(p)) return std::nullopt;
  return build(p, source);
}

}  // namespace detail

Graph read_json(std::string_view text, const std::string& source) {
  if (auto g = detail::read_json_streaming(text, source)) return std::move(*g);
  return detail::read_json_sax(text, source);
}

namespace detail {

Graph read_json_released(std::string_view text, const std::string& source,
                         const std::function<void(size_t)>& release) {
  if (auto g = read_json_streaming(text, source, &release)) return std::move(*g);
  return read_json_sax(text, source);
}

}  // namespace detail

// The nlohmann document of write_json, dumped whole: the streaming writer's twin (tests compare
// them byte for byte).
std::string detail::write_json_tree(const Graph& g) {
  nlohmann::ordered_json j;
  if (!g.name.empty()) j["name"] = g.name;
  if (!g.type.empty() && g.type != g.name) j["type"] = g.type;
  auto& actors = j["actors"] = nlohmann::ordered_json::array();
  for (ActorId a = 0; a < g.actor_count(); ++a) {
    nlohmann::ordered_json e = {{"name", g.actor_name(a)}};
    if (!g.actor_type(a).empty()) e["type"] = g.actor_type(a);
    if (const auto t = g.actor_time(a)) e["time"] = *t;
    actors.push_back(std::move(e));
  }
  auto& channels = j["channels"] = nlohmann::ordered_json::array();
  std::unordered_map<uint64_t, uint32_t> parallel;
  for (ChannelId id = 0; id < g.channel_count(); ++id) {
    const Channel& c = g.channel(id);
    const std::string_view name = g.channel_name(id);
    nlohmann::ordered_json e = {{"src", g.actor_name(c.src)},
                                {"dst", g.actor_name(c.dst)},
                                {"prd", c.prd},
                                {"cns", c.cns},
                                {"delay", c.delay}};
    const uint32_t k = parallel[(static_cast<uint64_t>(c.src) << 32) | c.dst]++;
    if (name != g.actor_name(c.src) + "->" + g.actor_name(c.dst) + "#" + std::to_string(k))
      e["name"] = name;
    if (!g.src_port(id).empty()) e["src_port"] = g.src_port(id);
    if (!g.dst_port(id).empty()) e["dst_port"] = g.dst_port(id);
    channels.push_back(std::move(e));
  }
  // Last: adding a key to an ordered_json moves its members (the references above).
  if (!g.sdf3_properties.empty()) j["sdf3_properties"] = g.sdf3_properties;
  return j.dump(1) + "\n";
}

namespace {

// A JSON string as nlohmann's dump writes it: ", \\ and the control characters escaped (\b \f
// \n \r \t short, the rest as \u00xx), everything else (valid UTF-8) as it is.
void put_json_string(std::string& out, std::string_view v) {
  static constexpr char kHex[] = "0123456789abcdef";
  out += '"';
  for (const char ch : v) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20) {
          out += "\\u00";
          out += kHex[c >> 4];
          out += kHex[c & 15];
        } else {
          out += ch;
        }
    }
  }
  out += '"';
}

}  // namespace

// Streams the document in the layout of nlohmann's dump(1) (one space per level), without
// building it: at 10^6 actors the document took about 2 GB.
std::string write_json(const Graph& g) {
  std::string out;
  // Generous: pages reserved and never written are never resident.
  out.reserve(4096 + g.actor_count() * 64 + g.channel_count() * 192 + g.sdf3_properties.size() * 2);
  // A member of an object: its separator (a line break, after a comma but for the first), its
  // indentation and its key. `first` is the object's own flag.
  auto field = [&](bool& first, const char* indent, const char* k) {
    out += first ? "\n" : ",\n";
    first = false;
    out += indent;
    out += '"';
    out += k;
    out += "\": ";
  };
  auto text = [&](bool& first, const char* indent, const char* k, std::string_view v) {
    field(first, indent, k);
    put_json_string(out, v);
  };
  auto number = [&](bool& first, const char* k, uint64_t v) {
    field(first, "   ", k);
    char digits[24];
    const auto [end, ec] = std::to_chars(digits, digits + sizeof digits, v);
    out.append(digits, end);
  };
  // An array of objects, one per index, each written by `element`.
  auto array = [&](bool& top, const char* k, size_t n, auto&& element) {
    field(top, " ", k);
    if (n == 0) {
      out += "[]";
      return;
    }
    out += '[';
    for (size_t i = 0; i < n; ++i) {
      out += i == 0 ? "\n  {" : ",\n  {";
      bool first = true;
      element(i, first);
      out += "\n  }";
    }
    out += "\n ]";
  };

  bool top = true;
  out += '{';
  if (!g.name.empty()) text(top, " ", "name", g.name);
  if (!g.type.empty() && g.type != g.name) text(top, " ", "type", g.type);
  array(top, "actors", g.actor_count(), [&](size_t i, bool& first) {
    const auto a = static_cast<ActorId>(i);
    text(first, "   ", "name", g.actor_name(a));
    if (!g.actor_type(a).empty()) text(first, "   ", "type", g.actor_type(a));
    if (const auto t = g.actor_time(a)) number(first, "time", *t);
  });
  std::unordered_map<uint64_t, uint32_t> parallel;
  std::string default_name;
  array(top, "channels", g.channel_count(), [&](size_t i, bool& first) {
    const auto id = static_cast<ChannelId>(i);
    const Channel& c = g.channel(id);
    text(first, "   ", "src", g.actor_name(c.src));
    text(first, "   ", "dst", g.actor_name(c.dst));
    number(first, "prd", c.prd);
    number(first, "cns", c.cns);
    number(first, "delay", c.delay);
    const uint32_t k = parallel[(static_cast<uint64_t>(c.src) << 32) | c.dst]++;
    default_name = g.actor_name(c.src);
    default_name += "->";
    default_name += g.actor_name(c.dst);
    default_name += '#';
    default_name += std::to_string(k);
    const std::string_view name = g.channel_name(id);
    if (name != default_name) text(first, "   ", "name", name);
    if (!g.src_port(id).empty()) text(first, "   ", "src_port", g.src_port(id));
    if (!g.dst_port(id).empty()) text(first, "   ", "dst_port", g.dst_port(id));
  });
  if (!g.sdf3_properties.empty()) text(top, " ", "sdf3_properties", g.sdf3_properties);
  out += "\n}\n";
  return out;
}

}  // namespace sdf
