#include "sdf/graph.hpp"

#include <algorithm>
#include <functional>

namespace sdf {

namespace {

size_t hash_of(std::string_view s) {
  return std::hash<std::string_view>{}(s);
}

uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace

template <class KeyOf>
int64_t Graph::flat_find(const FlatIndex& t, std::string_view key, KeyOf&& key_of) {
  if (t.slots.empty()) return -1;
  const size_t mask = t.slots.size() - 1;
  for (size_t i = hash_of(key) & mask;; i = (i + 1) & mask) {
    const uint32_t v = t.slots[i];
    if (v == 0) return -1;
    if (key_of(v - 1) == key) return v - 1;
  }
}

template <class KeyOf>
void Graph::flat_insert(FlatIndex& t, uint32_t id, KeyOf&& key_of) {
  if (2 * (t.size + 1) > t.slots.size()) {  // load factor at most 1/2
    std::vector<uint32_t> old = std::move(t.slots);
    t.slots.assign(std::max<size_t>(16, old.size() * 2), 0);
    const size_t mask = t.slots.size() - 1;
    for (uint32_t v : old) {
      if (v == 0) continue;
      size_t i = hash_of(key_of(v - 1)) & mask;
      while (t.slots[i] != 0) i = (i + 1) & mask;
      t.slots[i] = v;
    }
  }
  const size_t mask = t.slots.size() - 1;
  size_t i = hash_of(key_of(id)) & mask;
  while (t.slots[i] != 0) i = (i + 1) & mask;
  t.slots[i] = id + 1;
  ++t.size;
}

uint32_t Graph::next_parallel_index(uint64_t pair) {
  if (2 * (pair_size_ + 1) > pair_keys_.size()) {
    std::vector<uint64_t> keys = std::move(pair_keys_);
    std::vector<uint32_t> counts = std::move(pair_counts_);
    const size_t cap = std::max<size_t>(16, keys.size() * 2);
    pair_keys_.assign(cap, UINT64_MAX);  // (src, dst) never both 2^32 - 1: a free marker
    pair_counts_.assign(cap, 0);
    for (size_t j = 0; j < keys.size(); ++j) {
      if (keys[j] == UINT64_MAX) continue;
      size_t i = mix64(keys[j]) & (cap - 1);
      while (pair_keys_[i] != UINT64_MAX) i = (i + 1) & (cap - 1);
      pair_keys_[i] = keys[j];
      pair_counts_[i] = counts[j];
    }
  }
  const size_t mask = pair_keys_.size() - 1;
  size_t i = mix64(pair) & mask;
  while (pair_keys_[i] != UINT64_MAX && pair_keys_[i] != pair) i = (i + 1) & mask;
  if (pair_keys_[i] == UINT64_MAX) {
    pair_keys_[i] = pair;
    ++pair_size_;
  }
  return pair_counts_[i]++;
}

ActorId Graph::add_actor(std::string actor_name) {
  if (actor_name.empty()) throw Error(Error::Kind::input, "actor name is empty");
  if (actor_names_.size() >= UINT32_MAX) throw Error(Error::Kind::input, "too many actors");
  const auto id = static_cast<ActorId>(actor_names_.size());
  auto name_of = [this](uint32_t a) -> std::string_view { return actor_names_[a]; };
  if (flat_find(actor_index_, actor_name, name_of) >= 0)
    throw Error(Error::Kind::input, "duplicate actor name '" + actor_name + "'");
  actor_names_.push_back(std::move(actor_name));
  flat_insert(actor_index_, id, name_of);
  return id;
}

ChannelId Graph::add_channel(ActorId src, ActorId dst, uint64_t prd, uint64_t cns, uint64_t delay,
                             std::string channel_name) {
  if (src >= actor_count() || dst >= actor_count())
    throw Error(Error::Kind::input, "channel refers to an unknown actor");
  if (prd == 0 || cns == 0) throw Error(Error::Kind::input, "channel rates must be positive");
  if (channels_.size() >= UINT32_MAX) throw Error(Error::Kind::input, "too many channels");
  const uint64_t pair = (static_cast<uint64_t>(src) << 32) | dst;
  const uint32_t k = next_parallel_index(pair);
  if (channel_name.empty()) {
    channel_name.reserve(actor_names_[src].size() + actor_names_[dst].size() + 8);
    channel_name += actor_names_[src];
    channel_name += "->";
    channel_name += actor_names_[dst];
    channel_name += '#';
    channel_name += std::to_string(k);
  }
  const auto id = static_cast<ChannelId>(channels_.size());
  auto name_of = [this](uint32_t c) -> std::string_view { return channels_[c].name; };
  if (flat_find(channel_index_, channel_name, name_of) >= 0)
    throw Error(Error::Kind::input, "duplicate channel name '" + channel_name + "'");
  Channel c;
  c.src = src;
  c.dst = dst;
  c.prd = prd;
  c.cns = cns;
  c.delay = delay;
  c.name = std::move(channel_name);
  channels_.push_back(std::move(c));
  flat_insert(channel_index_, id, name_of);
  return id;
}

void Graph::set_rates(ChannelId c, uint64_t prd, uint64_t cns) {
  if (prd == 0 || cns == 0) throw Error(Error::Kind::input, "channel rates must be positive");
  channels_[c].prd = prd;
  channels_[c].cns = cns;
}

void Graph::set_port_names(ChannelId c, std::string src_port, std::string dst_port) {
  channels_[c].src_port = std::move(src_port);
  channels_[c].dst_port = std::move(dst_port);
}

std::optional<ActorId> Graph::find_actor(std::string_view actor) const {
  const int64_t a = flat_find(actor_index_, actor,
                              [this](uint32_t i) -> std::string_view { return actor_names_[i]; });
  if (a < 0) return std::nullopt;
  return static_cast<ActorId>(a);
}

std::optional<ChannelId> Graph::find_channel(std::string_view channel_name) const {
  const int64_t c = flat_find(channel_index_, channel_name,
                              [this](uint32_t i) -> std::string_view { return channels_[i].name; });
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
