#include "sdf/graph.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>

#include "prefetch.hpp"
#include "text.hpp"

namespace sdf {

namespace {

using detail::prefetch;

uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// Bytes p[0, n), n < 8, as a word with byte i at bits 8i, by at most two loads each way (no
// call to memcpy with a run-time size, whose bytes went through the stack: a stall on every
// hash, and names are short).
uint64_t tail_word(const char* p, size_t n) {
  if (n >= 4) {
    uint32_t lo, hi;  // bytes [0, 4) and [n - 4, n); the overlap is the same bytes twice
    std::memcpy(&lo, p, 4);
    std::memcpy(&hi, p + n - 4, 4);
    if constexpr (std::endian::native == std::endian::big) {
      lo = __builtin_bswap32(lo);
      hi = __builtin_bswap32(hi);
    }
    return lo | (static_cast<uint64_t>(hi) << (8 * (n - 4)));
  }
  if (n == 0) return 0;
  auto byte = [&](size_t i) {
    return static_cast<uint64_t>(static_cast<uint8_t>(p[i])) << (8 * i);
  };
  return byte(0) | byte(n / 2) | byte(n - 1);
}

// Names are short: eight bytes at a time, then the tail, then a full mix (low bits index the
// table, high bits are the slot's tag).
uint64_t hash_of(std::string_view s) {
  uint64_t h = 0x9e3779b97f4a7c15ull ^ s.size();
  size_t i = 0;
  for (; i + 8 <= s.size(); i += 8) {
    uint64_t w;
    std::memcpy(&w, s.data() + i, 8);
    h = (h ^ w) * 0xff51afd7ed558ccdull;
    h ^= h >> 32;
  }
  return mix64(h ^ tail_word(s.data() + i, s.size() - i));
}

constexpr uint64_t tag_of(uint64_t hash) {
  return hash & 0xffffffff00000000ull;
}

// A key's home slot in a table of `size` (a power of two) slots: the hash's top bits, which the
// slot's tag keeps, so that a rehash moves the entries without hashing their names again (on a
// large graph each name is a cache miss).
size_t home(size_t size, uint64_t hash) {
  return static_cast<size_t>(hash >> (64 - std::countr_zero(size)));
}

// A name's first 7 bytes (byte i at bits 8i) and, in the top byte, its length, or 0xff when it
// is longer: two names of at most 7 bytes are equal exactly when their words are.
uint64_t short_word(std::string_view s) {
  const uint64_t w = tail_word(s.data(), std::min<size_t>(s.size(), 7));
  return w | (static_cast<uint64_t>(s.size() <= 7 ? s.size() : 0xff) << 56);
}

bool short_name(uint64_t word) {
  return (word >> 56) != 0xff;
}

size_t table_size_for(size_t entries) {
  size_t cap = 16;
  while (cap < 2 * entries) cap *= 2;  // load factor at most 1/2
  return cap;
}

}  // namespace

template <class KeyOf>
int64_t Graph::flat_find(const FlatIndex& t, std::string_view key, KeyOf&& key_of) {
  return flat_find(t, key, hash_of(key), key_of);
}

template <class KeyOf>
int64_t Graph::flat_find(const FlatIndex& t, std::string_view key, uint64_t h, KeyOf&& key_of) {
  if (t.slots.empty()) return -1;
  const size_t mask = t.slots.size() - 1;
  const uint64_t tag = tag_of(h);
  for (size_t i = home(t.slots.size(), h);; i = (i + 1) & mask) {
    const uint64_t v = t.slots[i];
    if (v == 0) return -1;
    const auto id = static_cast<uint32_t>(v) - 1;
    if (tag_of(v) == tag && same(key_of(id), key)) return id;
  }
}

template <class KeyOf>
void Graph::flat_rehash(FlatIndex& t, size_t capacity, KeyOf&& key_of) {
  std::vector<uint64_t> old = std::move(t.slots);
  t.slots.assign(capacity, 0);
  const size_t mask = capacity - 1;
  const bool tags_suffice = capacity <= (uint64_t{1} << 32);
  for (uint64_t v : old) {
    if (v == 0) continue;
    size_t i = home(capacity, tags_suffice ? v : hash_of(key_of(static_cast<uint32_t>(v) - 1)));
    while (t.slots[i] != 0) i = (i + 1) & mask;
    t.slots[i] = v;
  }
}

template <class KeyOf>
void Graph::flat_insert(FlatIndex& t, uint32_t id, uint64_t hash, KeyOf&& key_of) {
  if (2 * (t.size + 1) > t.slots.size())
    flat_rehash(t, std::max<size_t>(16, t.slots.size() * 2), key_of);
  const size_t mask = t.slots.size() - 1;
  size_t i = home(t.slots.size(), hash);
  while (t.slots[i] != 0) i = (i + 1) & mask;
  t.slots[i] = tag_of(hash) | (static_cast<uint64_t>(id) + 1);
  ++t.size;
}

Graph::ChannelNames& Graph::ChannelNames::operator=(const ChannelNames& o) {
  if (this == &o) return *this;
  const std::lock_guard hold(o.lock);  // o may be making its names (a const use)
  column = o.column;
  index = o.index;
  pairs_live = o.pairs_live;
  pairs = o.pairs;
  pair_size = o.pair_size;
  made.store(o.made.load(std::memory_order_relaxed), std::memory_order_relaxed);
  return *this;
}

Graph::ChannelNames& Graph::ChannelNames::operator=(ChannelNames&& o) noexcept {
  if (this == &o) return *this;
  column = std::move(o.column);
  index = std::move(o.index);
  pairs_live = o.pairs_live;
  pairs = std::move(o.pairs);
  pair_size = o.pair_size;
  made.store(o.made.load(std::memory_order_relaxed), std::memory_order_relaxed);
  return *this;
}

void Graph::ChannelNames::pair_rehash(size_t capacity) {
  std::vector<PairCount> old = std::move(pairs);
  pairs.assign(capacity, PairCount{UINT64_MAX, 0});
  for (const PairCount& p : old) {
    if (p.key == UINT64_MAX) continue;
    size_t i = mix64(p.key) & (capacity - 1);
    while (pairs[i].key != UINT64_MAX) i = (i + 1) & (capacity - 1);
    pairs[i] = p;
  }
}

size_t Graph::ChannelNames::pair_slot(uint64_t pair) {
  if (2 * (pair_size + 1) > pairs.size()) pair_rehash(std::max<size_t>(16, pairs.size() * 2));
  const size_t mask = pairs.size() - 1;
  size_t i = mix64(pair) & mask;
  while (pairs[i].key != UINT64_MAX && pairs[i].key != pair) i = (i + 1) & mask;
  if (pairs[i].key == UINT64_MAX) {
    pairs[i].key = pair;
    ++pair_size;
  }
  return i;
}

void Graph::make_pairs_live() const {
  if (names_.pairs_live) return;
  names_.pairs_live = true;
  names_.pair_rehash(table_size_for(std::max(channels_.size(), channel_reserve_)));
  for (const Channel& c : channels_)
    ++names_.pairs[names_.pair_slot((static_cast<uint64_t>(c.src) << 32) | c.dst)].count;
}

bool Graph::defer_default_names() {
  if (!names_.made.load(std::memory_order_relaxed)) return true;
  if (!channels_.empty() || arrow_in_actor_name_) return false;
  names_.made.store(false, std::memory_order_relaxed);
  return true;
}

void Graph::note_actor_name(std::string_view actor) {
  if (arrow_in_actor_name_ || actor.find("->") == std::string_view::npos) return;
  arrow_in_actor_name_ = true;
  make_names();  // from now on default names could collide unless checked one by one
}

// Three passes over the channels, each with its misses overlapped by prefetching: the parallel
// index k of each (src, dst); the names; the index over them.
void Graph::make_default_names() const {
  const std::lock_guard hold(names_.lock);
  if (names_.made.load(std::memory_order_relaxed)) return;
  const size_t n = channels_.size();
  reserve_channel_tables(n);
  names_.pairs_live = true;
  names_.pair_rehash(table_size_for(std::max(n, channel_reserve_)));
  constexpr size_t kAhead = 8;
  auto pair_of = [&](size_t c) {
    return (static_cast<uint64_t>(channels_[c].src) << 32) | channels_[c].dst;
  };
  std::vector<uint64_t> scratch(n);  // k, then the names' hashes
  for (size_t c = 0; c < n; ++c) {
    if (c + kAhead < n)
      prefetch(names_.pairs.data() + (mix64(pair_of(c + kAhead)) & (names_.pairs.size() - 1)));
    scratch[c] = names_.pairs[names_.pair_slot(pair_of(c))].count++;
  }
  std::string made_name;
  for (size_t c = 0; c < n; ++c) {
    if (c + kAhead < n) {
      prefetch(&actor_names_[channels_[c + kAhead].src]);
      prefetch(&actor_names_[channels_[c + kAhead].dst]);
    }
    default_name(channels_[c].src, channels_[c].dst, scratch[c], made_name);
    names_.column.push_back(made_name);
    scratch[c] = hash_of(made_name);
  }
  auto name_of = [this](uint32_t c) -> std::string_view { return names_.column[c]; };
  const size_t size = names_.index.slots.size();
  for (size_t c = 0; c < n; ++c) {
    if (c + kAhead < n) prefetch(&names_.index.slots[home(size, scratch[c + kAhead])]);
    flat_insert(names_.index, static_cast<uint32_t>(c), scratch[c], name_of);
  }
  names_.made.store(true, std::memory_order_release);
}

void Graph::default_name(ActorId src, ActorId dst, uint64_t k, std::string& out) const {
  char digits[24];
  const char* end = std::to_chars(digits, digits + sizeof digits, k).ptr;
  out.clear();
  out += actor_names_[src];
  out += "->";
  out += actor_names_[dst];
  out += '#';
  out.append(digits, static_cast<size_t>(end - digits));
}

namespace {

void check_length(std::string_view s, const char* what) {
  if (s.size() > detail::NameColumn::kMaxLength)
    throw Error(Error::Kind::input, std::string(what) + " longer than 2^30 - 1 bytes");
}

}  // namespace

void Graph::reserve(size_t actors, size_t channels) {
  actor_names_.reserve(actors);
  channels_.reserve(channels);
  channel_reserve_ = channels;  // the channel tables wait: their names may never be made
  reserve_actor_table(actors);
}

int64_t Graph::actor_find(std::string_view key, uint64_t hash) const {
  const std::vector<ActorSlot>& slots = actor_index_.slots;
  if (slots.empty()) return -1;
  const size_t mask = slots.size() - 1;
  const uint64_t tag = tag_of(hash), word = short_word(key);
  for (size_t i = home(slots.size(), hash);; i = (i + 1) & mask) {
    const ActorSlot& s = slots[i];
    if (s.meta == 0) return -1;
    if (tag_of(s.meta) != tag || s.word != word) continue;
    const auto id = static_cast<uint32_t>(s.meta) - 1;
    if (short_name(word) || same(actor_names_[id], key)) return id;
  }
}

void Graph::actor_rehash(size_t capacity) {
  std::vector<ActorSlot> old = std::move(actor_index_.slots);
  actor_index_.slots.assign(capacity, ActorSlot{});
  const size_t mask = capacity - 1;
  const bool tags_suffice = capacity <= (uint64_t{1} << 32);
  for (const ActorSlot& s : old) {
    if (s.meta == 0) continue;
    const uint64_t h =
        tags_suffice ? s.meta : hash_of(actor_names_[static_cast<uint32_t>(s.meta) - 1]);
    size_t i = home(capacity, h);
    while (actor_index_.slots[i].meta != 0) i = (i + 1) & mask;
    actor_index_.slots[i] = s;
  }
}

void Graph::actor_insert(ActorId id, uint64_t hash, std::string_view key) {
  if (2 * (actor_index_.size + 1) > actor_index_.slots.size())
    actor_rehash(std::max<size_t>(16, actor_index_.slots.size() * 2));
  const size_t mask = actor_index_.slots.size() - 1;
  size_t i = home(actor_index_.slots.size(), hash);
  while (actor_index_.slots[i].meta != 0) i = (i + 1) & mask;
  actor_index_.slots[i] = {tag_of(hash) | (static_cast<uint64_t>(id) + 1), short_word(key)};
  ++actor_index_.size;
}

void Graph::reserve_actor_table(size_t actors) {
  if (table_size_for(actors) > actor_index_.slots.size()) actor_rehash(table_size_for(actors));
}

void Graph::reserve_channel_tables(size_t channels) const {
  channels = std::max(channels, channel_reserve_);
  auto channel_name = [this](uint32_t c) -> std::string_view { return names_.column[c]; };
  names_.column.reserve(channels, 0);
  if (table_size_for(channels) > names_.index.slots.size())
    flat_rehash(names_.index, table_size_for(channels), channel_name);
  if (names_.pairs_live && table_size_for(channels) > names_.pairs.size())
    names_.pair_rehash(table_size_for(channels));
}

ActorId Graph::add_actor(std::string actor_name) {
  if (actor_name.empty()) throw Error(Error::Kind::input, "actor name is empty");
  if (actor_names_.size() >= UINT32_MAX) throw Error(Error::Kind::input, "too many actors");
  const auto id = static_cast<ActorId>(actor_names_.size());
  const uint64_t h = hash_of(actor_name);
  if (actor_find(actor_name, h) >= 0)
    throw Error(Error::Kind::input, "duplicate actor name '" + actor_name + "'");
  note_actor_name(actor_name);
  actor_insert(id, h, actor_name);
  actor_names_.push_back(std::move(actor_name));
  return id;
}

size_t Graph::add_actors(std::span<const std::string_view> names) {
  reserve_actor_table(actor_names_.size() + names.size());  // no rehash below
  constexpr size_t kAhead = 8;
  uint64_t hashes[kAhead];
  auto ahead = [&](size_t i) {
    hashes[i % kAhead] = hash_of(names[i]);
    prefetch(&actor_index_.slots[home(actor_index_.slots.size(), hashes[i % kAhead])]);
  };
  for (size_t i = 0; i < std::min(names.size(), kAhead); ++i) ahead(i);
  for (size_t i = 0; i < names.size(); ++i) {
    const uint64_t h = hashes[i % kAhead];
    if (i + kAhead < names.size()) ahead(i + kAhead);
    if (names[i].empty() || actor_names_.size() >= UINT32_MAX || actor_find(names[i], h) >= 0)
      return i;
    const auto id = static_cast<ActorId>(actor_names_.size());
    note_actor_name(names[i]);
    actor_insert(id, h, names[i]);
    actor_names_.emplace_back(names[i]);
  }
  return names.size();
}

ChannelId Graph::add_channel(ActorId src, ActorId dst, uint64_t prd, uint64_t cns, uint64_t delay,
                             std::string channel_name) {
  if (src >= actor_count() || dst >= actor_count())
    throw Error(Error::Kind::input, "channel refers to an unknown actor");
  if (prd == 0 || cns == 0) throw Error(Error::Kind::input, "channel rates must be positive");
  if (channels_.size() >= UINT32_MAX) throw Error(Error::Kind::input, "too many channels");
  const uint64_t pair = (static_cast<uint64_t>(src) << 32) | dst;
  check_length(channel_name, "channel name");
  const auto id = static_cast<ChannelId>(channels_.size());
  if (channel_name.empty() && defer_default_names()) {
    channels_.push_back({src, dst, prd, cns, delay});
    return id;
  }
  make_names();
  if (channel_name.empty()) make_pairs_live();
  const size_t slot = names_.pairs_live ? names_.pair_slot(pair) : 0;
  if (channel_name.empty()) default_name(src, dst, names_.pairs[slot].count, channel_name);
  auto name_of = [this](uint32_t c) -> std::string_view { return names_.column[c]; };
  const uint64_t h = hash_of(channel_name);
  if (flat_find(names_.index, channel_name, h, name_of) >= 0)
    throw Error(Error::Kind::input, "duplicate channel name '" + channel_name + "'");
  if (names_.pairs_live) ++names_.pairs[slot].count;
  channels_.push_back({src, dst, prd, cns, delay});
  names_.column.push_back(channel_name);
  flat_insert(names_.index, id, h, name_of);
  return id;
}

size_t Graph::add_channels(std::span<const NewChannel> cs) {
  auto valid = [&](const NewChannel& c) {
    return c.src < actor_count() && c.dst < actor_count() && c.prd != 0 && c.cns != 0 &&
           c.name.size() <= detail::NameColumn::kMaxLength;
  };
  const bool all_default =
      std::all_of(cs.begin(), cs.end(), [](const NewChannel& c) { return c.name.empty(); });
  if (all_default && defer_default_names()) {
    for (size_t i = 0; i < cs.size(); ++i) {
      if (!valid(cs[i]) || channels_.size() >= UINT32_MAX) return i;
      channels_.push_back({cs[i].src, cs[i].dst, cs[i].prd, cs[i].cns, cs[i].delay});
    }
    return cs.size();
  }
  make_names();
  if (!names_.pairs_live &&
      std::any_of(cs.begin(), cs.end(), [](const NewChannel& c) { return c.name.empty(); }))
    make_pairs_live();
  reserve_channel_tables(channels_.size() + cs.size());  // no rehash below
  // The pair table too: a refused channel leaves its pair's slot behind (count 0), so the pairs
  // can outnumber the channels, and a rehash would move the slots the undo below decrements.
  if (names_.pairs_live && 2 * (names_.pair_size + cs.size()) > names_.pairs.size())
    names_.pair_rehash(table_size_for(names_.pair_size + cs.size()));
  auto name_of = [this](uint32_t c) -> std::string_view { return names_.column[c]; };
  // Three stages kAhead channels apart, each in channel order: prefetch the (src, dst) slot;
  // take the parallel index k from it (so the name is known), hash the name and prefetch its
  // slot; insert. A channel that fails is reached by the last stage after the middle stage has
  // counted up to kAhead later channels: those counts are taken back.
  constexpr size_t kAhead = 8, kRing = 2 * kAhead;
  struct Pending {
    std::string name;
    uint64_t hash = 0;
    size_t pair_slot = 0;
  };
  Pending ring[kRing];
  const size_t n = cs.size();
  auto pair_of = [](const NewChannel& c) { return (static_cast<uint64_t>(c.src) << 32) | c.dst; };
  auto stage1 = [&](size_t i) {
    if (!valid(cs[i])) return;
    if (names_.pairs_live)
      prefetch(names_.pairs.data() + (mix64(pair_of(cs[i])) & (names_.pairs.size() - 1)));
    if (cs[i].name.empty()) {  // the default name is made of the two actor names
      prefetch(&actor_names_[cs[i].src]);
      prefetch(&actor_names_[cs[i].dst]);
    }
  };
  size_t counted = 0;  // channels [0, counted) went through stage 2
  auto stage2 = [&](size_t i) {
    // Stops at an invalid channel: stage 3 returns there, and nothing after it is counted.
    if (!valid(cs[i])) return false;
    Pending& p = ring[i % kRing];
    uint64_t k = 0;
    if (names_.pairs_live) {
      p.pair_slot = names_.pair_slot(pair_of(cs[i]));
      k = names_.pairs[p.pair_slot].count++;
    }
    counted = i + 1;
    if (cs[i].name.empty()) {
      default_name(cs[i].src, cs[i].dst, k, p.name);
    } else {
      p.name.assign(cs[i].name);
    }
    p.hash = hash_of(p.name);
    prefetch(&names_.index.slots[home(names_.index.slots.size(), p.hash)]);
    return true;
  };
  auto undo = [&](size_t from) {
    if (names_.pairs_live)
      for (size_t j = from; j < counted; ++j) --names_.pairs[ring[j % kRing].pair_slot].count;
  };
  for (size_t i = 0; i < std::min(n, 2 * kAhead); ++i) stage1(i);
  bool stage2_open = true;
  for (size_t i = 0; i < std::min(n, kAhead) && stage2_open; ++i) stage2_open = stage2(i);
  for (size_t i = 0; i < n; ++i) {
    if (i >= counted || channels_.size() >= UINT32_MAX) {  // invalid: left to add_channel
      undo(i);
      return i;
    }
    Pending& p = ring[i % kRing];
    if (flat_find(names_.index, p.name, p.hash, name_of) >= 0) {
      undo(i);
      return i;
    }
    const auto id = static_cast<ChannelId>(channels_.size());
    channels_.push_back({cs[i].src, cs[i].dst, cs[i].prd, cs[i].cns, cs[i].delay});
    names_.column.push_back(p.name);
    flat_insert(names_.index, id, p.hash, name_of);
    if (i + 2 * kAhead < n) stage1(i + 2 * kAhead);
    if (stage2_open && i + kAhead < n) stage2_open = stage2(i + kAhead);
  }
  return n;
}

void Graph::set_rates(ChannelId c, uint64_t prd, uint64_t cns) {
  if (prd == 0 || cns == 0) throw Error(Error::Kind::input, "channel rates must be positive");
  channels_[c].prd = prd;
  channels_[c].cns = cns;
}

std::string_view Graph::actor_type(ActorId a) const {
  return a < actor_types_.size() ? actor_types_[a] : std::string_view{};
}

void Graph::set_actor_type(ActorId a, std::string_view actor_type) {
  if (a >= actor_count()) throw Error(Error::Kind::input, "set_actor_type: unknown actor");
  check_length(actor_type, "actor type");
  if (actor_types_.size() < actor_count()) actor_types_.resize(actor_count());
  actor_types_.set(a, actor_type);
}

std::optional<uint64_t> Graph::actor_time(ActorId a) const {
  if (a >= actor_times_.size() || actor_times_[a] == kNoTime) return std::nullopt;
  return actor_times_[a];
}

void Graph::set_actor_time(ActorId a, std::optional<uint64_t> time) {
  if (a >= actor_count()) throw Error(Error::Kind::input, "set_actor_time: unknown actor");
  if (time && *time >= (uint64_t{1} << 63))
    throw Error(Error::Kind::input, "execution time of actor '" + actor_names_[a] +
                                        "' must be below 2^63 (got " + std::to_string(*time) + ")");
  if (actor_times_.size() < actor_count()) actor_times_.resize(actor_count(), kNoTime);
  actor_times_[a] = time ? *time : kNoTime;
}

void Graph::set_port_names(ChannelId c, std::string_view src_port, std::string_view dst_port) {
  check_length(src_port, "port name");
  check_length(dst_port, "port name");
  if (src_port.empty() && dst_port.empty() && c >= src_ports_.size()) return;
  if (src_ports_.size() < channels_.size()) {
    src_ports_.resize(channels_.size());
    dst_ports_.resize(channels_.size());
  }
  src_ports_.set(c, src_port);
  dst_ports_.set(c, dst_port);
}

std::optional<ActorId> Graph::find_actor(std::string_view actor) const {
  const int64_t a = actor_find(actor, hash_of(actor));
  if (a < 0) return std::nullopt;
  return static_cast<ActorId>(a);
}

void Graph::find_actors(std::span<const std::string_view> names, std::span<int64_t> ids) const {
  if (actor_index_.slots.empty()) {
    std::fill(ids.begin(), ids.end(), -1);
    return;
  }
  // Three stages, kAhead names apart: hash and prefetch the slot; read the slot and prefetch the
  // name it points to, if the name is too long to be in the slot; probe (now mostly from cache).
  constexpr size_t kAhead = 8, kRing = 32;
  uint64_t hashes[kRing];
  const size_t n = names.size(), size = actor_index_.slots.size();
  auto stage1 = [&](size_t i) {
    hashes[i % kRing] = hash_of(names[i]);
    prefetch(&actor_index_.slots[home(size, hashes[i % kRing])]);
  };
  auto stage2 = [&](size_t i) {
    if (names[i].size() <= 7) return;
    const uint64_t v = actor_index_.slots[home(size, hashes[i % kRing])].meta;
    if (v != 0) prefetch(&actor_names_[static_cast<uint32_t>(v) - 1]);
  };
  for (size_t i = 0; i < std::min(n, 2 * kAhead); ++i) stage1(i);
  for (size_t i = 0; i < std::min(n, kAhead); ++i) stage2(i);
  for (size_t i = 0; i < n; ++i) {
    if (i + 2 * kAhead < n) stage1(i + 2 * kAhead);
    if (i + kAhead < n) stage2(i + kAhead);
    ids[i] = actor_find(names[i], hashes[i % kRing]);
  }
}

std::optional<ChannelId> Graph::find_channel(std::string_view channel_name) const {
  make_names();
  const int64_t c = flat_find(names_.index, channel_name,
                              [this](uint32_t i) -> std::string_view { return names_.column[i]; });
  if (c < 0) return std::nullopt;
  return static_cast<ChannelId>(c);
}

std::vector<uint64_t> Graph::delays() const {
  std::vector<uint64_t> d(channels_.size());
  for (size_t c = 0; c < channels_.size(); ++c) d[c] = channels_[c].delay;
  return d;
}

Adjacency::Adjacency(const Graph& g) {
  const size_t n = g.actor_count();
  in_off_.assign(n + 1, 0);
  out_off_.assign(n + 1, 0);
  for (const Channel& c : g.channels()) {
    ++in_off_[c.dst + 1];
    ++out_off_[c.src + 1];
  }
  for (size_t a = 0; a < n; ++a) {
    in_off_[a + 1] += in_off_[a];
    out_off_[a + 1] += out_off_[a];
  }
  in_.resize(g.channel_count());
  out_.resize(g.channel_count());
  std::vector<uint32_t> in_fill(in_off_.begin(), in_off_.end() - 1);
  std::vector<uint32_t> out_fill(out_off_.begin(), out_off_.end() - 1);
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    in_[in_fill[g.channel(c).dst]++] = c;
    out_[out_fill[g.channel(c).src]++] = c;
  }
}

Components connected_components(const Graph& g, const Adjacency& adj) {
  Components comp;
  const size_t n = g.actor_count();
  comp.of_actor.assign(n, UINT32_MAX);
  std::vector<ActorId> stack;
  for (ActorId start = 0; start < n; ++start) {
    if (comp.of_actor[start] != UINT32_MAX) continue;
    const uint32_t id = comp.count++;
    comp.of_actor[start] = id;
    stack.push_back(start);
    while (!stack.empty()) {
      const ActorId a = stack.back();
      stack.pop_back();
      auto visit = [&](ActorId b) {
        if (comp.of_actor[b] == UINT32_MAX) {
          comp.of_actor[b] = id;
          stack.push_back(b);
        }
      };
      for (ChannelId c : adj.outputs(a)) visit(g.channel(c).dst);
      for (ChannelId c : adj.inputs(a)) visit(g.channel(c).src);
    }
  }
  return comp;
}

}  // namespace sdf
