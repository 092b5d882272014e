#include "sdf/graph.hpp"

#include <algorithm>

namespace sdf {

ActorId Graph::add_actor(std::string actor_name) {
  if (actor_name.empty()) throw Error(Error::Kind::input, "actor name is empty");
  if (actor_names_.size() >= UINT32_MAX) throw Error(Error::Kind::input, "too many actors");
  const auto id = static_cast<ActorId>(actor_names_.size());
  auto [it, inserted] = actor_index_.try_emplace(actor_name, id);
  if (!inserted) throw Error(Error::Kind::input, "duplicate actor name '" + actor_name + "'");
  actor_names_.push_back(std::move(actor_name));
  return id;
}

ChannelId Graph::add_channel(ActorId src, ActorId dst, uint64_t prd, uint64_t cns, uint64_t delay,
                             std::string channel_name) {
  if (src >= actor_count() || dst >= actor_count())
    throw Error(Error::Kind::input, "channel refers to an unknown actor");
  if (prd == 0 || cns == 0) throw Error(Error::Kind::input, "channel rates must be positive");
  if (channels_.size() >= UINT32_MAX) throw Error(Error::Kind::input, "too many channels");
  const uint64_t pair = (static_cast<uint64_t>(src) << 32) | dst;
  const uint32_t k = parallel_count_[pair]++;
  if (channel_name.empty())
    channel_name = actor_names_[src] + "->" + actor_names_[dst] + "#" + std::to_string(k);
  const auto id = static_cast<ChannelId>(channels_.size());
  auto [it, inserted] = channel_index_.try_emplace(channel_name, id);
  if (!inserted) throw Error(Error::Kind::input, "duplicate channel name '" + channel_name + "'");
  Channel c;
  c.src = src;
  c.dst = dst;
  c.prd = prd;
  c.cns = cns;
  c.delay = delay;
  c.name = std::move(channel_name);
  channels_.push_back(std::move(c));
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
  auto it = actor_index_.find(actor);
  if (it == actor_index_.end()) return std::nullopt;
  return it->second;
}

std::optional<ChannelId> Graph::find_channel(std::string_view channel_name) const {
  auto it = channel_index_.find(channel_name);
  if (it == channel_index_.end()) return std::nullopt;
  return it->second;
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
