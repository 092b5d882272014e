// Synchronous Data-Flow graphs: actors and channels, the typed errors of the sdf library, and
// the compact adjacency every algorithm walks.
//
// A channel carries tokens from `src` to `dst`: each firing of src appends `prd` tokens, each
// firing of dst removes `cns`; `delay` tokens sit on it initially. Rates are positive, delays
// non-negative, all 64-bit. Channel names are the SDF3 name when read from SDF3 XML, otherwise
// `src->dst#k` with k counting the channels from src to dst in order (0, 1, ...).
//
// Thread-safety: a Graph is a plain value; concurrent const use is safe, mutation is not.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace sdf {

using ActorId = uint32_t;
using ChannelId = uint32_t;

// Every failure the library reports by exception. what() is one line naming the file, line,
// element or field; the CLI prints it and exits with exit_code() (2 usage, 3 limit, 1 otherwise).
class Error : public std::runtime_error {
 public:
  enum class Kind {
    usage,     // bad command-line use
    input,     // malformed or invalid graph file or parameter
    io,        // the operating system refused (missing file, unwritable path)
    overflow,  // a count does not fit in 64 bits; never reported as a wrong number instead
    limit,     // an analysis reached one of its work limits (states, firings, distributions)
  };
  Error(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const { return kind_; }
  int exit_code() const { return kind_ == Kind::usage ? 2 : kind_ == Kind::limit ? 3 : 1; }

 private:
  Kind kind_;
};

// 32 bytes: the names (Graph::channel_name, src_port, dst_port) live in the graph's name columns,
// so that the hot loops over channels read only the topology and rates.
struct Channel {
  ActorId src = 0;
  ActorId dst = 0;
  uint64_t prd = 1;    // tokens produced per firing of src (> 0)
  uint64_t cns = 1;    // tokens consumed per firing of dst (> 0)
  uint64_t delay = 0;  // initial tokens
};

namespace detail {

// Strings stored back to back in one buffer, each entry an offset (34 bits) and a length (30 bits)
// packed in 64 bits: 8 bytes per entry plus the characters, no allocation per string (a
// std::string is 32 bytes, and a name longer than 15 characters is another allocation). A name
// may be up to 2^30 - 1 bytes (graph files are at most 1 GiB, so every name read fits), a column
// up to 2^34 bytes (Error(input) beyond). An entry changed later is appended again (the old
// characters stay, unused). Views returned are valid until the next change.
class NameColumn {
 public:
  static constexpr size_t kMaxLength = (size_t{1} << 30) - 1;  // Graph refuses longer names
  size_t size() const { return refs_.size(); }
  bool empty() const { return refs_.empty(); }
  std::string_view operator[](size_t i) const {
    const uint64_t r = refs_[i];
    return {chars_.data() + (r >> 30), static_cast<size_t>(r & kMaxLength)};
  }
  void push_back(std::string_view s) { refs_.push_back(append(s)); }
  void set(size_t i, std::string_view s) { refs_[i] = append(s); }
  void resize(size_t n) { refs_.resize(n, 0); }  // new entries are empty
  void reserve(size_t entries, size_t chars) {
    refs_.reserve(entries);
    chars_.reserve(chars);
  }

 private:
  uint64_t append(std::string_view s) {
    const std::less<const char*> before;
    if (!s.empty() && !before(s.data(), chars_.data()) &&
        before(s.data(), chars_.data() + chars_.size()))
      return append(std::string(s));  // a view into chars_, which the resize may move
    const size_t at = chars_.size();
    if (at + s.size() > (size_t{1} << 34))
      throw Error(Error::Kind::input, "the graph's names take more than 16 GiB");
    chars_.resize(at + s.size());
    std::copy(s.begin(), s.end(), chars_.begin() + static_cast<std::ptrdiff_t>(at));
    return (static_cast<uint64_t>(at) << 30) | s.size();
  }
  std::vector<char> chars_;
  std::vector<uint64_t> refs_;
};

}  // namespace detail

// New rates for one channel (dynamic rate changes).
struct ChannelRates {
  ChannelId channel = 0;
  uint64_t prd = 1, cns = 1;
};

class Graph {
 public:
  // Throws Error(input) on an empty or duplicate name.
  ActorId add_actor(std::string name);
  // Throws Error(input) on an unknown actor id, a zero rate, a duplicate channel name or one
  // longer than 2^30 - 1 bytes. An empty name becomes `src->dst#k`.
  ChannelId add_channel(ActorId src, ActorId dst, uint64_t prd, uint64_t cns, uint64_t delay,
                        std::string name = {});

  // Bulk forms for the readers, equal to calling add_actor / add_channel on each element in
  // order up to the first that would be rejected: they return its index (nothing of it added;
  // calling add_actor / add_channel on it then throws the error) or size() when all were added.
  // The table probes of later elements are prefetched while earlier ones complete: on a large
  // graph every probe is a cache miss, and overlapping them is several times faster.
  size_t add_actors(std::span<const std::string_view> names);
  struct NewChannel {
    ActorId src, dst;
    uint64_t prd, cns, delay;
    std::string_view name;  // empty: `src->dst#k`
  };
  size_t add_channels(std::span<const NewChannel> channels);

  size_t actor_count() const { return actor_names_.size(); }
  size_t channel_count() const { return channels_.size(); }
  const std::string& actor_name(ActorId a) const { return actor_names_[a]; }
  const Channel& channel(ChannelId c) const { return channels_[c]; }
  std::span<const Channel> channels() const { return channels_; }
  // A view into the graph, valid until the graph changes. Default names are made when the first
  // one is asked for (see ChannelNames below); that is safe under concurrent const use.
  std::string_view channel_name(ChannelId c) const {
    make_names();
    return names_.column[c];
  }
  // SDF3 port names, kept so that a file read and written again keeps them; empty when the
  // channel came from elsewhere (the writer then invents unique ones). Views as channel_name.
  std::string_view src_port(ChannelId c) const {
    return c < src_ports_.size() ? src_ports_[c] : std::string_view{};
  }
  std::string_view dst_port(ChannelId c) const {
    return c < dst_ports_.size() ? dst_ports_[c] : std::string_view{};
  }
  // Changes the rates of an existing channel (dynamic rate changes). Rates must be positive.
  void set_rates(ChannelId c, uint64_t prd, uint64_t cns);
  // Throws Error(input) for a name longer than 2^30 - 1 bytes.
  void set_port_names(ChannelId c, std::string_view src_port, std::string_view dst_port);

  // Room for this many actors and channels in total, so a reader that knows the sizes builds
  // the graph without regrowing its arrays and hash tables. Changes nothing else.
  void reserve(size_t actors, size_t channels);

  // Actor annotations, kept so that a graph read and written again loses nothing. The type is
  // SDF3's actor `type` (empty: unset; writers then use the name). The execution time is a
  // non-negative integer in the graph's time unit (SDF3 <executionTime time=...>, the JSON
  // form's "time"), needed by the timed analyses (throughput, latency); unset by default.
  std::string_view actor_type(ActorId a) const;  // a view as channel_name
  void set_actor_type(ActorId a, std::string_view actor_type);
  std::optional<uint64_t> actor_time(ActorId a) const;
  // Throws Error(input) for times of 2^63 or more (sums of times must stay exact).
  void set_actor_time(ActorId a, std::optional<uint64_t> time);
  bool has_actor_times() const { return !actor_times_.empty(); }
  bool has_actor_types() const { return !actor_types_.empty(); }

  std::optional<ActorId> find_actor(std::string_view name) const;
  std::optional<ChannelId> find_channel(std::string_view name) const;
  // find_actor for many names at once: ids[i] is the id of names[i] or -1. The probes of later
  // names are prefetched while earlier ones complete: on a large graph each probe is a cache
  // miss, and overlapping them makes this several times faster than a loop of find_actor.
  void find_actors(std::span<const std::string_view> names, std::span<int64_t> ids) const;

  // Initial token vector (the delays), indexed by channel.
  std::vector<uint64_t> delays() const;

  std::string name;  // the graph's name (SDF3 `sdf name=`), may be empty
  std::string type;  // the graph's type (SDF3 `sdf type=`); empty: writers use the name
  // The SDF3 <sdfProperties> element as read (XML text), so that its processors, memories,
  // channel and graph properties survive a conversion. The writers merge the actors' execution
  // times into it (docs/sdf.md, "Execution times"). Empty when the graph had none.
  std::string sdf3_properties;

 private:
  std::vector<std::string> actor_names_;
  // Sized to the actors only once one is set, so graphs without annotations pay nothing.
  detail::NameColumn actor_types_;
  std::vector<uint64_t> actor_times_;  // kNoTime = unset
  static constexpr uint64_t kNoTime = UINT64_MAX;
  std::vector<Channel> channels_;
  // Sized to the channels only once a port name is set.
  detail::NameColumn src_ports_, dst_ports_;
  // Flat open-addressing tables of ids (the names live in actor_names_ / channels_): no node
  // per entry, so a 10^6-actor graph loads without millions of small allocations. A slot holds
  // the high 32 bits of the name's hash beside id + 1 (0 = empty), so a probe compares names
  // only when the hashes agree (each comparison is a cache miss on a big graph).
  struct FlatIndex {
    std::vector<uint64_t> slots;
    size_t size = 0;
  };
  template <class KeyOf>
  static int64_t flat_find(const FlatIndex& t, std::string_view key, KeyOf&& key_of);
  template <class KeyOf>
  static int64_t flat_find(const FlatIndex& t, std::string_view key, uint64_t hash, KeyOf&& key_of);
  template <class KeyOf>
  static void flat_insert(FlatIndex& t, uint32_t id, uint64_t hash, KeyOf&& key_of);
  template <class KeyOf>
  static void flat_rehash(FlatIndex& t, size_t capacity, KeyOf&& key_of);
  // The actors' table keeps a short name (up to 7 bytes) in the slot itself, beside its length:
  // a lookup of such a name reads one cache line instead of two (the slot, then the name), and
  // resolving a channel's two actors is most of loading a large graph. Longer names compare
  // their first 7 bytes in the slot before reading the name.
  struct ActorSlot {
    uint64_t meta = 0;  // as FlatIndex's slots: hash tag | id + 1, 0 = empty
    uint64_t word = 0;  // short_word(name)
  };
  struct ActorIndex {
    std::vector<ActorSlot> slots;
    size_t size = 0;
  };
  ActorIndex actor_index_;
  int64_t actor_find(std::string_view key, uint64_t hash) const;
  void actor_insert(ActorId id, uint64_t hash, std::string_view key);
  void actor_rehash(size_t capacity);
  struct PairCount {
    uint64_t key;  // UINT64_MAX = free ((src, dst) are never both 2^32 - 1)
    uint64_t count;
  };
  // The channels' names, their index, and the (src, dst) counts of the default names.
  //
  // A graph whose channels all have default names (the JSON form, usually) makes none of them
  // until one is asked for (channel_name, find_channel) or a named channel is added: on a large
  // graph each costs cache misses (both actor names, a pair count, an index slot) and its bytes,
  // a third of the time and memory of loading a 10^6-actor graph for its repetitions vector.
  // Unmade, they are still unique: while no actor name contains "->", `src->dst#k` reads back as
  // exactly one (src, dst, k), and k counts the channels of each pair. They are made all at once,
  // from a const accessor too: under the lock, once (`made` tells readers it is done), and a
  // copy locks the source. Before that nothing reads the column, so no reader races the making.
  struct ChannelNames {
    detail::NameColumn column;  // every channel's name once made; empty before
    FlatIndex index;            // over the column
    // (src, dst) -> number of channels so far, for `src->dst#k`. Built at the first channel that
    // needs a default name once the names are made (a graph whose channels are all named, as
    // SDF3's are, never pays for it) and kept up to date from then on.
    bool pairs_live = false;
    std::vector<PairCount> pairs;
    size_t pair_size = 0;
    std::atomic<bool> made{true};  // false: the channels' default names are not made yet
    mutable std::mutex lock;

    ChannelNames() = default;
    ChannelNames(const ChannelNames& o) { *this = o; }
    ChannelNames(ChannelNames&& o) noexcept { *this = std::move(o); }
    ChannelNames& operator=(const ChannelNames& o);
    ChannelNames& operator=(ChannelNames&& o) noexcept;
    void pair_rehash(size_t capacity);
    size_t pair_slot(uint64_t pair);  // the pair's slot, created with count 0 if new
  };
  mutable ChannelNames names_;
  bool arrow_in_actor_name_ = false;  // some actor name contains "->": names are made at once
  size_t channel_reserve_ = 0;        // reserve()'s channel count, for the tables when made
  void make_names() const {
    if (!names_.made.load(std::memory_order_acquire)) make_default_names();
  }
  void make_default_names() const;
  // Whether channels with default names can be added without making their names (and then the
  // graph is in that state).
  bool defer_default_names();
  void note_actor_name(std::string_view actor);
  void make_pairs_live() const;
  void reserve_actor_table(size_t actors);
  // Room in the name column, the index and the pair counts (when live) for this many channels
  // (at least reserve()'s count), so that adding them rehashes nothing.
  void reserve_channel_tables(size_t channels) const;
  void default_name(ActorId src, ActorId dst, uint64_t k, std::string& out) const;
};

// Compressed incidence lists: for actor a, inputs(a) / outputs(a) are channel ids in channel
// order. A self-loop appears in both lists. Built in O(V + E); immutable.
class Adjacency {
 public:
  explicit Adjacency(const Graph& g);
  std::span<const ChannelId> inputs(ActorId a) const {
    return {in_.data() + in_off_[a], in_.data() + in_off_[a + 1]};
  }
  std::span<const ChannelId> outputs(ActorId a) const {
    return {out_.data() + out_off_[a], out_.data() + out_off_[a + 1]};
  }

 private:
  std::vector<uint32_t> in_off_, out_off_;
  std::vector<ChannelId> in_, out_;
};

// Connected components of the underlying undirected graph: component id per actor, numbered
// in order of each component's lowest actor id.
struct Components {
  std::vector<uint32_t> of_actor;
  uint32_t count = 0;
};
Components connected_components(const Graph& g, const Adjacency& adj);

}  // namespace sdf
