#include "self_timed.hpp"

namespace sdf::detail {

TimedPorts::TimedPorts(const Graph& g) {
  const Adjacency adj(g);
  const auto n = static_cast<ActorId>(g.actor_count());
  in_off.assign(n + 1, 0);
  out_off.assign(n + 1, 0);
  ports.reserve(2 * g.channel_count());
  for (ActorId a = 0; a < n; ++a) {
    for (ChannelId c : adj.inputs(a)) ports.push_back({c, g.channel(c).src, g.channel(c).cns});
    in_off[a + 1] = static_cast<uint32_t>(ports.size());
  }
  out_off[0] = static_cast<uint32_t>(ports.size());
  for (ActorId a = 0; a < n; ++a) {
    for (ChannelId c : adj.outputs(a)) ports.push_back({c, g.channel(c).dst, g.channel(c).prd});
    out_off[a + 1] = static_cast<uint32_t>(ports.size());
  }
  global.resize(g.channel_count());
  for (ChannelId c = 0; c < g.channel_count(); ++c) global[c] = c;
}

TimedPorts::TimedPorts(const Graph& g, std::span<const ActorId> actors,
                       std::span<const uint32_t> local) {
  const size_t n = actors.size();
  std::vector<uint32_t> ins(n + 1, 0), outs(n + 1, 0);
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    const uint32_t s = local[ch.src], d = local[ch.dst];
    if (s == UINT32_MAX || d == UINT32_MAX) continue;
    global.push_back(c);
    ++ins[d + 1];
    ++outs[s + 1];
  }
  in_off.assign(n + 1, 0);
  out_off.assign(n + 1, 0);
  for (size_t a = 0; a < n; ++a) in_off[a + 1] = in_off[a] + ins[a + 1];
  out_off[0] = in_off[n];
  for (size_t a = 0; a < n; ++a) out_off[a + 1] = out_off[a] + outs[a + 1];
  ports.resize(out_off[n]);
  std::vector<uint32_t> in_fill(in_off.begin(), in_off.end() - 1);
  std::vector<uint32_t> out_fill(out_off.begin(), out_off.end() - 1);
  for (uint32_t i = 0; i < global.size(); ++i) {
    const Channel& ch = g.channel(global[i]);
    const uint32_t s = local[ch.src], d = local[ch.dst];
    ports[in_fill[d]++] = {i, s, ch.cns};
    ports[out_fill[s]++] = {i, d, ch.prd};
  }
}

}  // namespace sdf::detail
