// SDF3 XML reading (a streaming scan, xml_scanner.hpp; no document tree) and writing (pugixml).
// Element order does not matter. Each actor's ports are sorted by name and found by binary
// search: O(P log P) for P ports, never the quadratic scan that makes SDF3's own loader take
// minutes on 10^5 actors. Line numbers are computed only for an error message.
#include <algorithm>
#include <atomic>
#include <bit>
#include <charconv>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <pugixml.hpp>
#include <sstream>
#include <system_error>
#include <thread>
#include <unordered_map>
#include <unordered_set>

#include "json_detail.hpp"
#include "prefetch.hpp"
#include "sdf/io.hpp"
#include "sdf/text.hpp"
#include "xml_scanner.hpp"

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

// A port keeps a short name (all of SDF3's are) in itself, so that resolving channels does not
// go back to the text (which the reader may release behind it); a longer one is a view.
// 32 bytes (there are two per channel): the offset of the <port> element (its line is computed
// only for an error message) and a long name's length take 40 bits, as texts stay far below
// 2^40 bytes.
struct Port {
  uint64_t rate;
  uint32_t offset_low;
  uint32_t channel = UINT32_MAX;
  uint8_t offset_high;
  bool out;
  uint8_t length = 0;   // of a short name, kLong for a view
  char bytes[13] = {};  // a short name, or a long one's pointer and 40-bit length
  static constexpr uint8_t kLong = 255;
  size_t offset() const { return static_cast<size_t>(offset_high) << 32 | offset_low; }
  void set_offset(size_t at) {
    offset_low = static_cast<uint32_t>(at);
    offset_high = static_cast<uint8_t>(static_cast<uint64_t>(at) >> 32);
  }
  std::string_view name() const {
    if (length != kLong) return {bytes, length};
    const char* data;
    uint64_t size = 0;
    std::memcpy(&data, bytes, sizeof data);
    std::memcpy(&size, bytes + sizeof data, 5);  // little-endian
    return {data, static_cast<size_t>(size)};
  }
  void set_name(std::string_view n) {
    if (n.size() <= sizeof bytes) {
      std::copy(n.begin(), n.end(), bytes);
      length = static_cast<uint8_t>(n.size());
    } else {
      const char* data = n.data();
      const uint64_t size = n.size();
      std::memcpy(bytes, &data, sizeof data);
      std::memcpy(bytes + sizeof data, &size, 5);
      length = kLong;
    }
  }
};
static_assert(sizeof(Port) == 32);
static_assert(std::endian::native == std::endian::little);

// Names in std::string_view's order (bytes as unsigned), without a call to memcmp: ports are
// sorted and searched by their short names.
int compare_names(std::string_view a, std::string_view b) {
  const size_t n = std::min(a.size(), b.size());
  for (size_t i = 0; i < n; ++i)
    if (a[i] != b[i])
      return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[i]) ? -1 : 1;
  return a.size() < b.size() ? -1 : a.size() > b.size() ? 1 : 0;
}

// A <channel> as read, resolved when its actors are known. On two threads the scan looks up
// its actors and ports ahead of the builder where it safely can (see pre_resolve): then `ids`
// and `ports` hold them, else kUnresolved.
struct ChannelRecord {
  static constexpr uint32_t kUnresolved = UINT32_MAX;
  std::string_view name, src, src_port, dst, dst_port;
  bool has_name = false;
  uint64_t delay = 0;
  size_t offset;
  uint32_t ids[2] = {kUnresolved, kUnresolved};    // source, destination actor
  uint32_t ports[2] = {kUnresolved, kUnresolved};  // their ports, indices into the builder's ports_
  bool resolved() const { return ports[1] != kUnresolved; }
};

// An <actor> as read, added to the graph with the next hand-over.
struct ActorRecord {
  std::string_view name;
  size_t offset;
  bool typed;
  std::string_view type;
};

// What the scan hands to the graph builder: the actors closed since the last hand-over, with
// their ports (each actor's sorted by name); the channels read since the last hand-over that
// included channels; and whether a mistake or the end of the text follows them.
struct Segment {
  std::vector<ActorRecord> actors;
  std::vector<Port> ports;
  std::vector<uint32_t> port_counts;  // per actor
  std::vector<ChannelRecord> channels;
  bool failed = false;  // the scan found a mistake after these: error at error_offset
  size_t error_offset = 0;
  std::string error;
  std::exception_ptr exception;  // something else the scan threw (out of memory)
  bool last = false;             // the scan has ended

  // The first offset in the text that these records point into (SIZE_MAX: none).
  size_t first_offset() const {
    size_t at = SIZE_MAX;
    if (!actors.empty()) at = actors.front().offset;
    if (!channels.empty()) at = std::min(at, channels.front().offset);
    return at;
  }
  void clear() {  // keeps the capacity
    actors.clear();
    ports.clear();
    port_counts.clear();
    channels.clear();
    failed = last = false;
    error.clear();
    exception = nullptr;
  }
};

// Thrown on the scan's thread to end it: the builder has given up, or has the scan's mistake.
struct StopScan {};

// The hand-over between the scan (one thread) and the builder (another): a short queue of
// segments in file order, and their spent buffers coming back.
class SegmentPipe {
 public:
  // Scan side. Waits while the queue is full; throws StopScan once the builder has stopped.
  void push(Segment&& s) {
    std::unique_lock lock(m_);
    changed_.wait(lock, [&] { return full_.size() < kDepth || stopped_; });
    if (stopped_) throw StopScan{};
    full_.push_back(std::move(s));
    changed_.notify_all();
  }
  Segment fresh() {
    const std::lock_guard lock(m_);
    if (spent_.empty()) return {};
    Segment s = std::move(spent_.back());
    spent_.pop_back();
    return s;
  }
  bool stopped() const { return stopped_flag_.load(std::memory_order_relaxed); }
  // How many segments wait for the builder.
  size_t queued() const {
    const std::lock_guard lock(m_);
    return full_.size();
  }
  // The first offset a queued or building segment still points into (SIZE_MAX: none).
  size_t needed_from() const {
    const std::lock_guard lock(m_);
    size_t at = building_;
    for (const Segment& s : full_) at = std::min(at, s.first_offset());
    return at;
  }

  // Build side.
  Segment pop() {
    std::unique_lock lock(m_);
    changed_.wait(lock, [&] { return !full_.empty(); });
    Segment s = std::move(full_.front());
    full_.pop_front();
    building_ = s.first_offset();
    changed_.notify_all();
    return s;
  }
  void recycle(Segment&& s) {
    s.clear();
    const std::lock_guard lock(m_);
    building_ = SIZE_MAX;
    spent_.push_back(std::move(s));
  }
  void stop() {
    const std::lock_guard lock(m_);
    stopped_ = true;
    stopped_flag_.store(true, std::memory_order_relaxed);
    changed_.notify_all();
  }

 private:
  static constexpr size_t kDepth = 4;
  mutable std::mutex m_;
  std::condition_variable changed_;
  std::deque<Segment> full_;
  std::vector<Segment> spent_;
  size_t building_ = SIZE_MAX;
  bool stopped_ = false;
  std::atomic<bool> stopped_flag_{false};  // stopped_, read without the lock between tokens
};

// One pass over the text with XmlScanner, no document tree, in two parts that can run on two
// threads: the scan (tokens, attributes, each actor's ports sorted by name) and the builder
// (the graph). The scan hands over segments: the actors of a block of `block` as its element
// closes, and the channels with them once `block` channels have been read. Actor ids are their
// order in the file, so ports can refer to them before their block is added. Channels are
// resolved as they are handed over; once a channel names an actor not seen yet (SDF3 does not
// fix the element order), it and every later channel wait for the end of the document, so
// channels keep their file order. <sdfProperties> is cut out of the text and parsed on its own
// (pugixml: it is small next to the graph). Errors come in file order as far as the text read
// tells them: the actors and channels read before a mistake of the scan, and the waiting
// channels whose actors have been seen, are resolved before it is reported; what only the end
// of the document decides (a port left unconnected, a channel naming an actor that never comes,
// <sdfProperties>, parsed last) is reported there. On two threads the builder does exactly what
// it does on one, in the same order, so the graph and the first error are the same.
class Sdf3Reader {
 public:
  Sdf3Reader(std::string_view text, const std::string& source,
             const std::function<void(size_t)>* release, size_t block, bool two_threads,
             bool always_resolve)
      : text_(text),
        source_(source),
        scan_(text),
        release_(release),
        block_(std::max<size_t>(1, block)),
        two_threads_(two_threads),
        always_resolve_(always_resolve) {}

  Graph read() {
    reserve();
    bool scanned = false;
    if (two_threads_) {
      SegmentPipe pipe;
      std::thread scanner;
      try {
        scanner = std::thread([&] { run_scan(&pipe); });
      } catch (const std::system_error&) {  // no thread to be had: read on this one
      }
      if (scanner.joinable()) {
        struct Join {  // also when the builder throws: stop the scan and wait for it
          SegmentPipe& pipe;
          std::thread& thread;
          ~Join() {
            pipe.stop();
            thread.join();
          }
        } join{pipe, scanner};
        for (bool last = false; !last;) {
          Segment s = pipe.pop();
          last = s.last;
          build(s);
          pipe.recycle(std::move(s));
        }
        scanned = true;
      }
    }
    if (!scanned) run_scan(nullptr);
    finish();
    return std::move(g_);
  }

 private:
  enum class Where { outside, sdf3, app, sdf, actor, other };

  // Room for as many actors and channels as the text has tags named like theirs (a quick
  // count: the graph's arrays and tables then never grow). The count also finds such tags in
  // comments or outside <sdf>, so it is capped at what a valid file of this size could hold:
  // the shortest actor element, <actor name='A'/>, has 17 bytes, and a channel's four
  // required attributes make it 60. A malformed file then costs no more before its first
  // error than a valid one of its size.
  void reserve() {
    struct Count {
      size_t actors = 0, channels = 0;
    };
    auto named = [&](size_t at, std::string_view name) {
      if (!same(text_.substr(at + 1, name.size()), name)) return false;
      const size_t after = at + 1 + name.size();
      return after < text_.size() &&
             (text_[after] == '/' || text_[after] == '>' || text_[after] == ' ' ||
              text_[after] == '\t' || text_[after] == '\n' || text_[after] == '\r');
    };
    // Counts the tags that begin in [from, to); `release`: drops what it has passed.
    auto count_tags = [&](size_t from, size_t to, bool release) {
      Count c;
      detail::for_each_lt(text_.substr(from, to - from), [&](size_t i) {
        c.actors += named(from + i, "actor");
        c.channels += named(from + i, "channel");
        // The count reads the whole text: what it has passed is dropped as it goes (the scan
        // faults it in again from the page cache), so the file is never resident at once.
        if (release && release_ && from + i >= released_ + kReleaseStep)
          (*release_)(released_ = from + i);
      });
      return c;
    };
    // On two threads the second half is counted beside the first. Only the first half's count
    // drops pages as it goes (the release callback runs on one thread at a time): the second
    // half stays resident until both are done, while nothing else is allocated yet.
    constexpr size_t kSplitBytes = size_t{16} << 20;
    Count first, second;
    const size_t half =
        two_threads_ && text_.size() >= kSplitBytes ? text_.size() / 2 : text_.size();
    std::thread helper;
    struct Join {
      std::thread& t;
      ~Join() {
        if (t.joinable()) t.join();
      }
    } join{helper};
    if (half < text_.size()) {
      try {
        helper = std::thread([&] { second = count_tags(half, text_.size(), false); });
      } catch (const std::system_error&) {  // no thread: one count
      }
    }
    first = count_tags(0, helper.joinable() ? half : text_.size(), true);
    if (helper.joinable()) helper.join();
    const size_t actors = first.actors + second.actors, channels = first.channels + second.channels;
    if (release_) (*release_)(text_.size());
    released_ = 0;
    release_at_ = kReleaseStep;
    g_.reserve(std::min(actors, text_.size() / 17), std::min(channels, text_.size() / 60));
    // Every channel connects two ports, and a port element, <port name='a' type='in'
    // rate='1'/>, has at least 35 bytes.
    ports_.reserve(std::min(2 * channels, text_.size() / 35));
  }

  // ---- The scan (on its own thread when `pipe` is given, else it builds as it goes) ----

  void run_scan(SegmentPipe* pipe) {
    pipe_ = pipe;
    try {
      try {
        scan();
      } catch (const detail::XmlError& e) {
        scan_fail(e.offset, e.message);
      }
    } catch (const StopScan&) {  // the builder has the mistake, or has stopped
    } catch (...) {
      if (!pipe_) throw;  // on one thread: the builder's error, thrown through the scan
      cur_.clear();
      cur_.exception = std::current_exception();
      cur_.last = true;
      try {
        pipe_->push(std::move(cur_));
      } catch (const StopScan&) {
      }
    }
  }

  void scan() {
    std::vector<Where> stack;
    bool seen_sdf3 = false, seen_app = false, seen_sdf = false;
    for (;;) {
      const detail::XmlScanner::Token t = scan_.next();
      if (t.kind == detail::XmlScanner::Kind::eof) break;
      if (pipe_ && pipe_->stopped()) throw StopScan{};
      if (release_ && t.offset >= release_at_) release_behind(t.offset);
      if (t.kind == detail::XmlScanner::Kind::end) {
        if (stack.back() == Where::actor) close_actor();
        stack.pop_back();
        continue;
      }
      const Where parent = stack.empty() ? Where::outside : stack.back();
      Where here = Where::other;
      if (parent == Where::outside && same(t.name, "sdf3") && !seen_sdf3) {
        seen_sdf3 = true;
        here = Where::sdf3;
        const std::string_view type = value("type");
        if (!type.empty() && type != "sdf")
          scan_fail(t.offset,
                    "graph type '" + std::string(type) + "' is not supported (only type=\"sdf\")");
        root_offset_ = t.offset;
      } else if (parent == Where::sdf3 && same(t.name, "applicationGraph") && !seen_app) {
        seen_app = true;
        here = Where::app;
        app_offset_ = t.offset;
      } else if (parent == Where::app && same(t.name, "sdf") && !seen_sdf) {
        seen_sdf = true;
        here = Where::sdf;
        graph_name_ = value("name");
        if (!valid_utf8(graph_name_)) scan_fail(t.offset, "attribute 'name' is not valid UTF-8");
        graph_type_ = value("type");
        if (!valid_utf8(graph_type_)) scan_fail(t.offset, "attribute 'type' is not valid UTF-8");
      } else if (parent == Where::app && same(t.name, "sdfProperties") && props_.empty()) {
        props_offset_ = t.offset;
        size_t end = t.end;
        if (!t.self_closing) {
          // Skip the element (still checking that it is well formed) and keep its text.
          const size_t depth = scan_.depth();
          for (;;) {
            const detail::XmlScanner::Token u = scan_.next();
            if (u.kind == detail::XmlScanner::Kind::end && scan_.depth() + 1 == depth) {
              end = u.end;
              break;
            }
          }
        }
        props_ = text_.substr(t.offset, end - t.offset);
        continue;
      } else if (parent == Where::sdf && same(t.name, "actor")) {
        here = Where::actor;
        open_actor(t);
      } else if (parent == Where::actor && same(t.name, "port")) {
        read_port(t);
      } else if (parent == Where::sdf && same(t.name, "channel")) {
        read_channel(t);
      }
      if (!t.self_closing) {
        stack.push_back(here);
      } else if (here == Where::actor) {
        close_actor();
      }
    }
    if (!seen_sdf3) scan_fail(0, "no <sdf3> root element");
    if (!seen_app) scan_fail(root_offset_, "<sdf3> has no <applicationGraph>");
    if (!seen_sdf) scan_fail(app_offset_, "<applicationGraph> has no <sdf>");
    cur_.last = true;
    hand_over(true);
  }

  // Hands over the closed actors, and the channels read if `channels`, to the builder.
  void hand_over(bool channels) {
    if (channels) {
      pre_resolve(channels_);
      std::swap(cur_.channels, channels_);  // cur_.channels is empty
    }
    Segment next = pipe_ ? pipe_->fresh() : std::move(spare_);
    next.clear();
    std::swap(next, cur_);
    if (pipe_) {
      actors_pushed_ += next.actors.size();
      pipe_->push(std::move(next));
    } else {
      build(next);
      spare_ = std::move(next);
      spare_.clear();
    }
  }

  // A mistake at `offset`: what was read before it goes to the builder first (its own mistakes
  // come first), with the message; an actor whose element is still open is left out (its ports
  // are not all read).
  [[noreturn]] void scan_fail(size_t offset, const std::string& msg) {
    size_t closed = 0;
    for (uint32_t n : cur_.port_counts) closed += n;
    cur_.ports.resize(closed);
    cur_.failed = true;
    cur_.error_offset = offset;
    cur_.error = msg;
    hand_over(true);  // on one thread this throws the error
    throw StopScan{};
  }

  // Among the channels the builder has the larger share of the work, most of it looking up
  // each channel's two actors and their ports: cache misses in tables of 10^6 entries. When the
  // builder falls behind (kBehind segments wait for it), the scan does those lookups for a block
  // of channels before handing it over, so the two threads share the work as it comes. It may
  // only while no actor it has handed over is still being added (actors_built_ ==
  // actors_pushed_): then the actor table,
  // port_begin_ and the ports' names, types and rates stay as they are until the scan hands
  // over its next actors, so reading them here races with nothing (the builder still writes
  // the ports' `channel`, a field of its own). It only finds: what it cannot find (an actor not
  // added yet, a port that is not there) stays unresolved for the builder, which also makes
  // every check, so the graph and the first error are those of one thread.
  static constexpr size_t kBehind = 2;
  void pre_resolve(std::vector<ChannelRecord>& records) {
    if (!pipe_ || records.empty() || (!always_resolve_ && pipe_->queued() < kBehind) ||
        actors_built_.load(std::memory_order_acquire) != actors_pushed_)
      return;
    const size_t n = records.size();
    scan_names_.resize(2 * n);
    scan_ids_.resize(2 * n);
    for (size_t i = 0; i < n; ++i)
      scan_names_[2 * i] = records[i].src, scan_names_[2 * i + 1] = records[i].dst;
    g_.find_actors(scan_names_, scan_ids_);
    auto ahead = [&](size_t k, int stage) {
      if (k >= n) return;
      for (size_t side = 0; side < 2; ++side) prefetch_ports(scan_ids_[2 * k + side], stage);
    };
    for (size_t i = 0; i < n; ++i) {
      ahead(i + 24, 0);
      ahead(i + 16, 1);
      ahead(i + 8, 2);
      ChannelRecord& r = records[i];
      const int64_t s = scan_ids_[2 * i], d = scan_ids_[2 * i + 1];
      if (s < 0 || d < 0) continue;
      const uint32_t sp = port_index(static_cast<ActorId>(s), r.src_port);
      const uint32_t dp = port_index(static_cast<ActorId>(d), r.dst_port);
      if (sp == ChannelRecord::kUnresolved || dp == ChannelRecord::kUnresolved) continue;
      r.ids[0] = static_cast<uint32_t>(s), r.ids[1] = static_cast<uint32_t>(d);
      r.ports[0] = sp, r.ports[1] = dp;
    }
  }

  // Releases the text before `at` that no record still points into.
  void release_behind(const size_t at) {
    size_t offset = std::min(at, cur_.first_offset());
    if (actor_open_) offset = std::min(offset, open_.offset);
    if (!channels_.empty()) offset = std::min(offset, channels_.front().offset);
    if (pipe_) offset = std::min(offset, pipe_->needed_from());
    if (offset < released_ + kReleaseStep) {  // the builder is behind: try again a little later
      release_at_ = at + kReleaseStep / 16;
      return;
    }
    (*release_)(offset);
    released_ = offset;
    release_at_ = released_ + kReleaseStep;
  }

  // The decoded value of an attribute of the current tag ("" when absent), kept alive as long
  // as the reader.
  std::string_view value(detail::AttrName attr) {
    const detail::XmlAttribute* a = scan_.attribute(attr);
    return a ? keep(*a) : std::string_view{};
  }
  std::string_view keep(const detail::XmlAttribute& a) {
    if (a.plain) return a.raw;
    const std::string_view v = detail::decode_attribute(a.raw, scratch_);
    if (v.data() != scratch_.data()) return v;  // a view into the text
    return decoded_.emplace_back(scratch_);     // a deque: earlier views stay valid
  }
  std::string_view required(const detail::XmlScanner::Token& t, detail::AttrName attr) {
    const detail::XmlAttribute* a = scan_.attribute(attr);
    if (!a)
      scan_fail(t.offset, "<" + std::string(t.name) + "> lacks the attribute '" +
                              std::string(attr.name) + "'");
    std::string_view v = keep(*a);
    if (v.empty() || padded_end(v.front()) || padded_end(v.back())) {  // rare: no call otherwise
      v = trim(v);
      if (v.empty()) scan_fail(t.offset, "attribute '" + std::string(attr.name) + "' is empty");
    }
    if (!(a->plain && a->ascii) && !valid_utf8(v))
      scan_fail(t.offset, "attribute '" + std::string(attr.name) + "' is not valid UTF-8");
    return v;
  }
  static bool padded_end(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
  uint64_t number(size_t offset, const char* attr, std::string_view text, bool positive) {
    const std::optional<uint64_t> v = count(text, positive);
    if (!v) scan_fail(offset, not_an_integer(attr, text, positive));
    return *v;
  }
  static std::optional<uint64_t> count(std::string_view text, bool positive) {
    uint64_t v = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || ptr != text.data() + text.size() || (positive && v == 0))
      return std::nullopt;
    return v;
  }

  void open_actor(const detail::XmlScanner::Token& t) {
    const std::string_view name = required(t, "name");
    std::string_view type;
    const bool typed = scan_.attribute("type") != nullptr;
    if (typed) {
      type = value("type");
      if (!valid_utf8(type)) scan_fail(t.offset, "attribute 'type' is not valid UTF-8");
    }
    open_ = {name, t.offset, typed, type};
    open_ports_ = cur_.ports.size();
    actor_open_ = true;
  }

  void read_port(const detail::XmlScanner::Token& t) {
    Port p;
    p.set_name(required(t, "name"));
    const std::string_view type = required(t, "type");
    if (!same(type, "in") && !same(type, "out"))
      scan_fail(t.offset, "port type '" + std::string(type) + "' is neither 'in' nor 'out'");
    p.out = same(type, "out");
    p.rate = number(t.offset, "rate", required(t, "rate"), true);
    p.set_offset(t.offset);
    cur_.ports.push_back(p);
  }

  // The open actor's ports are cur_.ports[open_ports_, end): sorted by name, then closed off.
  void close_actor() {
    // Ports are mostly written in name order: one pass finds that (and so no duplicates).
    // Indices, not iterators: `first + 1` on an empty vector's null data is undefined (UBSan).
    size_t i = open_ports_;
    while (i + 1 < cur_.ports.size() &&
           compare_names(cur_.ports[i].name(), cur_.ports[i + 1].name()) < 0)
      ++i;
    if (i + 1 < cur_.ports.size()) {
      std::sort(cur_.ports.begin() + static_cast<ptrdiff_t>(open_ports_), cur_.ports.end(),
                [](const Port& a, const Port& b) { return compare_names(a.name(), b.name()) < 0; });
      for (i = open_ports_; i + 1 < cur_.ports.size(); ++i)
        if (same(cur_.ports[i].name(), cur_.ports[i + 1].name()))
          scan_fail(std::max(cur_.ports[i].offset(), cur_.ports[i + 1].offset()),
                    "duplicate port '" + std::string(cur_.ports[i].name()) + "' on actor '" +
                        std::string(open_.name) + "'");
    }
    cur_.actors.push_back(open_);
    cur_.port_counts.push_back(static_cast<uint32_t>(cur_.ports.size() - open_ports_));
    actor_open_ = false;
    if (cur_.actors.size() >= block_) hand_over(false);
  }

  void read_channel(const detail::XmlScanner::Token& t) {
    ChannelRecord r;
    r.offset = t.offset;
    if (const detail::XmlAttribute* a = scan_.attribute("name")) {
      r.has_name = true;
      r.name = trim(keep(*a));
      if (r.name.empty()) scan_fail(t.offset, "attribute 'name' is empty");
      if (!valid_utf8(r.name)) scan_fail(t.offset, "attribute 'name' is not valid UTF-8");
    }
    r.src = required(t, "srcActor");
    r.dst = required(t, "dstActor");
    r.src_port = required(t, "srcPort");
    r.dst_port = required(t, "dstPort");
    if (const detail::XmlAttribute* a = scan_.attribute("initialTokens"))
      r.delay = number(t.offset, "initialTokens", trim(keep(*a)), false);
    channels_.push_back(r);
    if (channels_.size() >= block_) hand_over(true);
  }

  // ---- The builder (on the calling thread) ----

  // Adds a segment: its actors (a duplicate name is the first mistake), then its channels
  // (resolved, or waiting behind those that already wait), then the scan's mistake if any,
  // after the waiting channels whose actors have been seen by now (one naming an actor not
  // seen yet cannot be judged before the end of the document, which is not read).
  void build(Segment& s) {
    if (s.exception) std::rethrow_exception(s.exception);
    add_actors(s);
    if (!s.channels.empty()) {
      if (!deferred_.empty())  // once one waits, all later do
        deferred_.insert(deferred_.end(), s.channels.begin(), s.channels.end());
      else
        resolve(s.channels, false);
    }
    if (s.failed) {
      std::vector<ChannelRecord> waiting;
      waiting.swap(deferred_);
      resolve(waiting, false);  // those from the first unknown actor on wait again
      fail(s.error_offset, s.error);
    }
  }

  void add_actors(const Segment& s) {
    if (s.actors.empty()) return;
    names_.clear();
    for (const ActorRecord& a : s.actors) names_.push_back(a.name);
    const auto base = static_cast<ActorId>(g_.actor_count());
    const size_t ok = g_.add_actors(names_);
    for (size_t i = 0; i < ok; ++i)
      if (s.actors[i].typed) g_.set_actor_type(base + static_cast<ActorId>(i), s.actors[i].type);
    if (ok < s.actors.size()) {
      try {
        g_.add_actor(std::string(s.actors[ok].name));  // throws "duplicate actor name '...'"
      } catch (const Error& e) {
        fail(s.actors[ok].offset, e.what());
      }
    }
    ports_.insert(ports_.end(), s.ports.begin(), s.ports.end());
    for (uint32_t n : s.port_counts) port_begin_.push_back(port_begin_.back() + n);
    actors_built_.store(g_.actor_count(), std::memory_order_release);  // see pre_resolve
  }

  void finish() {
    resolve(deferred_, true);
    for (ActorId a = 0; a < g_.actor_count(); ++a)
      for (uint32_t i = port_begin_[a]; i < port_begin_[a + 1]; ++i)
        if (ports_[i].channel == UINT32_MAX)
          fail(ports_[i].offset(), "port '" + std::string(ports_[i].name()) + "' of actor '" +
                                       g_.actor_name(a) + "' is not connected to a channel");
    g_.name = graph_name_;
    g_.type = graph_type_;
    if (!props_.empty()) read_properties();
  }

  [[noreturn]] void fail(size_t offset, const std::string& msg) const {
    throw Error(Error::Kind::input, source_ + ":" +
                                        std::to_string(LineIndex(text_).line_of(offset)) + ": " +
                                        msg);  // the line index only for the one error
  }

  // Adds the channels of `records` in order. `last_chance`: an unknown actor is a mistake;
  // otherwise the channels from the first one naming an unknown actor on are deferred.
  void resolve(std::vector<ChannelRecord>& records, bool last_chance) {
    if (records.empty()) return;
    // The actors of the channels the scan has not resolved, looked up in one batch.
    names_.clear();
    for (const ChannelRecord& r : records)
      if (!r.resolved()) names_.push_back(r.src), names_.push_back(r.dst);
    found_.resize(names_.size());
    g_.find_actors(names_, found_);
    ids_.resize(2 * records.size());
    for (size_t i = 0, u = 0; i < records.size(); ++i) {
      const ChannelRecord& r = records[i];
      for (size_t side = 0; side < 2; ++side)
        ids_[2 * i + side] = r.resolved() ? int64_t{r.ids[side]} : found_[u++];
    }
    std::vector<Graph::NewChannel> batch;
    batch.reserve(records.size());
    // The ports of random actors are cache misses: the port ranges, then the first ports, then
    // their names are fetched ahead, overlapping the misses of later channels.
    auto ahead = [&](size_t k, int stage) {
      if (k >= records.size()) return;
      if (records[k].resolved()) {  // only the two ports, for their `channel`
        if (stage == 0)
          for (const uint32_t p : records[k].ports) detail::prefetch(&ports_[p]);
        return;
      }
      for (size_t side = 0; side < 2; ++side) prefetch_ports(ids_[2 * k + side], stage);
    };
    size_t i = 0;
    for (; i < records.size(); ++i) {
      ahead(i + 24, 0);
      ahead(i + 16, 1);
      ahead(i + 8, 2);
      const ChannelRecord& r = records[i];
      const int64_t s = ids_[2 * i], d = ids_[2 * i + 1];
      if (s < 0 || d < 0) {
        if (!last_chance) break;
        add_batch(records, batch);
        fail(r.offset,
             "channel refers to an unknown actor '" + std::string(s < 0 ? r.src : r.dst) + "'");
      }
      const auto src = static_cast<ActorId>(s), dst = static_cast<ActorId>(d);
      Port& sp = r.resolved() ? ports_[r.ports[0]]
                              : find_port_or_flush(records, batch, r, src, r.src_port);
      Port& dp = r.resolved() ? ports_[r.ports[1]]
                              : find_port_or_flush(records, batch, r, dst, r.dst_port);
      if (!sp.out)
        fail_in_batch(records, batch, r,
                      "srcPort '" + std::string(sp.name()) + "' is an input port");
      if (dp.out)
        fail_in_batch(records, batch, r,
                      "dstPort '" + std::string(dp.name()) + "' is an output port");
      for (Port* p : {&sp, &dp}) {
        if (p->channel == UINT32_MAX) continue;
        add_batch(records, batch);  // the other channel may be in the batch: named once added
        fail(r.offset, "port '" + std::string(p->name()) + "' of actor '" +
                           g_.actor_name(p == &sp ? src : dst) +
                           "' is already connected to channel '" +
                           std::string(g_.channel_name(p->channel)) + "'");
      }
      const auto c = static_cast<uint32_t>(g_.channel_count() + batch.size());
      sp.channel = dp.channel = c;
      batch.push_back(
          {src, dst, sp.rate, dp.rate, r.delay, r.has_name ? r.name : std::string_view{}});
    }
    add_batch(records, batch);
    if (i < records.size())  // not last_chance; records is not deferred_, which is empty
      deferred_.assign(records.begin() + static_cast<ptrdiff_t>(i), records.end());
  }

  Port& find_port_or_flush(std::vector<ChannelRecord>& records,
                           std::vector<Graph::NewChannel>& batch, const ChannelRecord& r,
                           ActorId actor, std::string_view name) {
    const uint32_t i = port_index(actor, name);
    if (i == ChannelRecord::kUnresolved)
      fail_in_batch(records, batch, r,
                    "actor '" + g_.actor_name(actor) + "' has no port '" + std::string(name) + "'");
    return ports_[i];
  }

  // Fetches ahead what a port lookup of actor `a` (< 0: none) reads, one stage per call, several
  // channels apart: its port range (stage 0), its first port (1), that port's name (2).
  void prefetch_ports(int64_t a, int stage) const {
    if (a < 0) return;
    const auto id = static_cast<size_t>(a);
    if (stage == 0) {
      detail::prefetch(&port_begin_[id]);
    } else if (port_begin_[id] != port_begin_[id + 1]) {  // an actor without ports: nothing
      const Port& p = ports_[port_begin_[id]];
      if (stage == 1)
        detail::prefetch(&p);
      else
        detail::prefetch(p.name().data());
    }
  }

  // The index in ports_ of the actor's port of that name, or kUnresolved. Reads only the ports'
  // names (the scan calls it too, see pre_resolve).
  uint32_t port_index(ActorId actor, std::string_view name) const {
    const uint32_t first = port_begin_[actor], last = port_begin_[actor + 1];
    uint32_t i = first;
    if (last - first <= 8) {  // most actors have a few ports: a scan, no calls to memcmp
      while (i != last && !same(ports_[i].name(), name)) ++i;
    } else {
      i = static_cast<uint32_t>(
          std::lower_bound(
              ports_.begin() + first, ports_.begin() + last, name,
              [](const Port& p, std::string_view k) { return compare_names(p.name(), k) < 0; }) -
          ports_.begin());
    }
    if (i == last || !same(ports_[i].name(), name)) return ChannelRecord::kUnresolved;
    return i;
  }

  // A mistake in channel r: the channels before it in the batch are added first (one of them
  // may be a duplicate name, an earlier mistake).
  [[noreturn]] void fail_in_batch(std::vector<ChannelRecord>& records,
                                  std::vector<Graph::NewChannel>& batch, const ChannelRecord& r,
                                  const std::string& msg) {
    add_batch(records, batch);
    fail(r.offset, msg);
  }

  // Adds `batch` (the first batch.size() records); a duplicate name is reported at its channel.
  void add_batch(const std::vector<ChannelRecord>& records, std::vector<Graph::NewChannel>& batch) {
    if (batch.empty()) return;
    const ChannelId base = static_cast<ChannelId>(g_.channel_count());
    const size_t ok = g_.add_channels(batch);
    for (size_t k = 0; k < ok; ++k) {
      const ChannelRecord& r = records[k];
      g_.set_port_names(base + static_cast<ChannelId>(k), r.src_port, r.dst_port);
    }
    if (ok < batch.size()) {
      const Graph::NewChannel& c = batch[ok];
      try {
        g_.add_channel(c.src, c.dst, c.prd, c.cns, c.delay, std::string(c.name));
      } catch (const Error& e) {
        fail(records[ok].offset, e.what());
      }
    }
    batch.clear();
  }

  void read_properties() {
    pugi::xml_document doc;
    const pugi::xml_parse_result res =
        doc.load_buffer(props_.data(), props_.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!res)
      fail(props_offset_ + static_cast<size_t>(res.offset),
           std::string("XML: ") + res.description());
    auto at = [&](pugi::xml_node n) {
      return props_offset_ + static_cast<size_t>(std::max<ptrdiff_t>(0, n.offset_debug()));
    };
    apply_properties(
        g_, doc.first_child(), [&](pugi::xml_node n, const std::string& m) { fail(at(n), m); },
        [&](pugi::xml_node n, const char* attr) {
          const pugi::xml_attribute a = n.attribute(attr);
          if (!a) fail(at(n), "<" + std::string(n.name()) + "> lacks the attribute '" + attr + "'");
          const std::string_view v = trim(a.value());
          if (v.empty()) fail(at(n), "attribute '" + std::string(attr) + "' is empty");
          const std::optional<uint64_t> x = count(v, false);
          if (!x) fail(at(n), not_an_integer(attr, v, false));
          return *x;
        },
        false);
  }

  static constexpr size_t kReleaseStep = size_t{4} << 20;  // 4 MiB of text resident at most
  std::string_view text_;
  const std::string& source_;

  // The scan's.
  detail::XmlScanner scan_;
  const std::function<void(size_t)>* release_;
  size_t released_ = 0;
  size_t release_at_ = 0;  // the offset at which to try releasing again
  const size_t block_;
  const bool two_threads_;
  const bool always_resolve_;  // pre_resolve whenever it may, not only when the builder is behind
  SegmentPipe* pipe_ = nullptr;
  Segment cur_;    // closed actors and their ports (and the open actor's), not handed over
  Segment spare_;  // on one thread: the last segment built, for its buffers
  std::vector<ChannelRecord> channels_;  // read, not handed over
  ActorRecord open_{};
  size_t open_ports_ = 0;  // where the open actor's ports begin in cur_.ports
  bool actor_open_ = false;
  std::string scratch_;
  std::deque<std::string> decoded_;  // attribute values that entities or white space changed
  std::string graph_name_, graph_type_;
  std::string_view props_;
  size_t props_offset_ = 0, root_offset_ = 0, app_offset_ = 0;

  // The builder's.
  Graph g_;
  std::vector<Port> ports_;
  // Actor a's ports are ports_[port_begin_[a], port_begin_[a + 1]), sorted by name; the last
  // entry is where the next actor's begin.
  std::vector<uint32_t> port_begin_{0};
  std::vector<ChannelRecord> deferred_;
  std::vector<std::string_view> names_;
  std::vector<int64_t> found_, ids_;
  // Between the two: how many actors the builder has added (it writes, the scan reads), and
  // the scan's count of actors handed over; see pre_resolve.
  std::atomic<size_t> actors_built_{0};
  size_t actors_pushed_ = 0;
  std::vector<std::string_view> scan_names_;  // pre_resolve's
  std::vector<int64_t> scan_ids_;
};

// Port names for writing: the ones read, else "in<k>"/"out<k>" avoiding names already taken.
std::vector<std::pair<std::string, std::string>> port_names(const Graph& g) {
  std::vector<std::unordered_set<std::string>> taken(g.actor_count());
  bool any_named = false;
  for (ChannelId id = 0; id < g.channel_count(); ++id) {
    const Channel& c = g.channel(id);
    if (!g.src_port(id).empty()) taken[c.src].emplace(g.src_port(id)), any_named = true;
    if (!g.dst_port(id).empty()) taken[c.dst].emplace(g.dst_port(id)), any_named = true;
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
    names[c].first = g.src_port(c).empty() ? invent(ch.src, "out") : std::string(g.src_port(c));
    names[c].second = g.dst_port(c).empty() ? invent(ch.dst, "in") : std::string(g.dst_port(c));
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

// Actors or channels per hand-over from the scan to the builder: small enough that the segments
// in flight between two threads stay near a megabyte, large enough that the hand-overs cost
// nothing measurable.
constexpr size_t kSdf3Block = 1024;

Graph read_sdf3(std::string_view text, const std::string& source) {
  return detail::read_sdf3_with(text, source, nullptr, kSdf3Block, detail::ScanThread::automatic);
}

namespace detail {

Graph read_sdf3_released(std::string_view text, const std::string& source,
                         const std::function<void(size_t)>& release) {
  return read_sdf3_with(text, source, &release, kSdf3Block, ScanThread::automatic);
}

Graph read_sdf3_with(std::string_view text, const std::string& source,
                     const std::function<void(size_t)>* release, size_t block, ScanThread scan) {
  // A thread of its own pays from about a megabyte of text (some 10^4 actors) on.
  constexpr size_t kOwnThreadBytes = size_t{1} << 20;
  const bool own = scan == ScanThread::own || scan == ScanThread::own_resolving ||
                   (scan == ScanThread::automatic && text.size() >= kOwnThreadBytes &&
                    std::thread::hardware_concurrency() > 1);
  Sdf3Reader reader(text, source, release, block, own, scan == ScanThread::own_resolving);
  return reader.read();
}

}  // namespace detail

namespace {

// Whether <sdfProperties> nests deeper than any real file. The writers indent unless it does:
// indentation grows with the depth on every line, so a 2.1 MB file of 300,000 nested elements
// would have been written as tens of gigabytes; unindented, the output stays in proportion.
bool too_deep_to_indent(pugi::xml_node props) {
  constexpr int kIndentDepth = 32;
  struct Depth : pugi::xml_tree_walker {
    bool deep = false;
    bool for_each(pugi::xml_node&) override {
      deep = depth() > kIndentDepth;
      return !deep;  // stops the walk
    }
  } walk;
  props.traverse(walk);  // iterative in pugixml: no recursion
  return walk.deep;
}

// An attribute as pugixml's default format writes it: double quotes; &, <, " and control
// characters escaped (the latter as two-digit references); '>' is not.
void put_attribute(std::string& out, std::string_view name, std::string_view v) {
  out += ' ';
  out += name;
  out += "=\"";
  for (const char ch : v) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 32 && c != '&' && c != '<' && c != '"') {
      out += ch;
    } else if (c == '&') {
      out += "&amp;";
    } else if (c == '<') {
      out += "&lt;";
    } else if (c == '"') {
      out += "&quot;";
    } else {
      out += "&#";
      out += static_cast<char>('0' + c / 10);
      out += static_cast<char>('0' + c % 10);
      out += ';';
    }
  }
  out += '"';
}

void put_number(std::string& out, std::string_view name, uint64_t v) {
  char buf[24];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  put_attribute(out, name, std::string_view(buf, static_cast<size_t>(end - buf)));
}

}  // namespace

// The element tree of write_sdf3, built with pugixml and printed as a whole: the twin of the
// streaming writer below (tests compare them byte for byte), and the writer for <sdfProperties>
// nested too deep to indent.
std::string detail::write_sdf3_tree(const Graph& g) {
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
    const std::string type(g.actor_type(a));
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
    e.append_attribute("name") = std::string(g.channel_name(c)).c_str();
    e.append_attribute("srcActor") = g.actor_name(ch.src).c_str();
    e.append_attribute("srcPort") = ports[c].first.c_str();
    e.append_attribute("dstActor") = g.actor_name(ch.dst).c_str();
    e.append_attribute("dstPort") = ports[c].second.c_str();
    if (ch.delay != 0)
      e.append_attribute("initialTokens") = static_cast<unsigned long long>(ch.delay);
  }
  write_properties(g, app);
  std::ostringstream out;
  doc.save(out, "  ",
           too_deep_to_indent(app.child("sdfProperties")) ? pugi::format_raw : pugi::format_default,
           pugi::encoding_utf8);
  return out.str();
}

// Streams the elements into the text (the document tree of 10^6 actors took about 2 GB), with
// only <sdfProperties> built as a tree (it is small, and times are merged into it). Port names
// invented for a graph without any are counted per actor as port_names() does, without strings.
std::string write_sdf3(const Graph& g) {
  pugi::xml_document kept;
  pugi::xml_node app = kept.append_child("applicationGraph");
  write_properties(g, app);
  const pugi::xml_node props = app.child("sdfProperties");
  if (too_deep_to_indent(props)) return detail::write_sdf3_tree(g);

  bool any_named = false;
  for (ChannelId c = 0; c < g.channel_count() && !any_named; ++c)
    any_named = !g.src_port(c).empty() || !g.dst_port(c).empty();
  std::vector<std::pair<std::string, std::string>> named;  // only when some ports are named
  std::vector<uint32_t> out_k, in_k;                       // otherwise "out<k>" / "in<k>"
  if (any_named) {
    named = port_names(g);
  } else {
    out_k.resize(g.channel_count());
    in_k.resize(g.channel_count());
    std::vector<uint32_t> next(g.actor_count(), 0);
    for (ChannelId c = 0; c < g.channel_count(); ++c) {
      out_k[c] = next[g.channel(c).src]++;
      in_k[c] = next[g.channel(c).dst]++;
    }
  }
  std::string scratch;
  auto port = [&](ChannelId c, bool out) -> std::string_view {
    if (any_named) return out ? named[c].first : named[c].second;
    scratch = out ? "out" : "in";
    scratch += std::to_string(out ? out_k[c] : in_k[c]);
    return scratch;
  };

  const Adjacency adj(g);
  std::string out;
  // Generous: reserved pages that are never written are never resident, while growing the
  // string would copy it (a channel with its two ports takes about 250 bytes at 10^6 actors).
  out.reserve(4096 + g.actor_count() * 96 + g.channel_count() * 384);
  out += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<sdf3 type=\"sdf\" version=\"1.0\">\n";
  const std::string name = g.name.empty() ? "graph" : g.name;
  out += "  <applicationGraph";
  put_attribute(out, "name", name);
  out += ">\n    <sdf";
  put_attribute(out, "name", name);
  put_attribute(out, "type", g.type.empty() ? name : g.type);
  out += g.actor_count() == 0 ? " />\n" : ">\n";  // no actors, no channels: an empty element
  for (ActorId a = 0; a < g.actor_count(); ++a) {
    out += "      <actor";
    put_attribute(out, "name", g.actor_name(a));
    const std::string_view type = g.actor_type(a);
    put_attribute(out, "type", type.empty() ? std::string_view(g.actor_name(a)) : type);
    if (adj.inputs(a).empty() && adj.outputs(a).empty()) {
      out += " />\n";
      continue;
    }
    out += ">\n";
    for (const bool output : {false, true})
      for (ChannelId c : output ? adj.outputs(a) : adj.inputs(a)) {
        out += "        <port";
        put_attribute(out, "name", port(c, output));
        put_attribute(out, "type", output ? "out" : "in");
        put_number(out, "rate", output ? g.channel(c).prd : g.channel(c).cns);
        out += " />\n";
      }
    out += "      </actor>\n";
  }
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    out += "      <channel";
    put_attribute(out, "name", g.channel_name(c));
    put_attribute(out, "srcActor", g.actor_name(ch.src));
    put_attribute(out, "srcPort", port(c, true));
    put_attribute(out, "dstActor", g.actor_name(ch.dst));
    put_attribute(out, "dstPort", port(c, false));
    if (ch.delay != 0) put_number(out, "initialTokens", ch.delay);
    out += " />\n";
  }
  if (g.actor_count() != 0) out += "    </sdf>\n";
  std::ostringstream p;
  props.print(p, "  ", pugi::format_default, pugi::encoding_utf8, 2);
  out += p.str();
  out += "  </applicationGraph>\n</sdf3>\n";
  return out;
}

}  // namespace sdf
