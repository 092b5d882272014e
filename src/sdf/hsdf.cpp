// The HSDF expansion (Sriram and Bhattacharyya, "Embedded Multiprocessors", ch. 3): one actor
// per firing of an iteration, one edge per (producing firing, consuming firing) pair.
//
// Tokens on a channel are consumed in the order they were produced (FIFO), the `delay` initial
// tokens first. Token i (0-based) consumed on the channel is then produced by firing
// j = floor((i − delay) / prd) of the source, counted from the first iteration; j < 0 means an
// initial token, i.e. a firing of an earlier iteration in the periodic unrolling. Firing k of
// the destination consumes tokens k·cns .. (k+1)·cns − 1, so it depends on source firings
// floor((k·cns − delay) / prd) .. floor(((k+1)·cns − 1 − delay) / prd): firing j mod q[src],
// −floor(j / q[src]) iterations back, which is the edge's token count.
#include "hsdf.hpp"

#include <algorithm>
#include <numeric>

#include "sdf/repetitions.hpp"
#include "sdf/throughput.hpp"

namespace sdf {

namespace detail {

namespace {

__extension__ using i128 = __int128;

i128 floor_div(i128 a, i128 b) {  // b > 0
  const i128 q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

}  // namespace

std::vector<uint64_t> repetitions_or_throw(const Graph& g, const char* analysis) {
  Repetitions rep = compute_repetitions(g);
  if (!rep.consistent)
    throw Error(
        Error::Kind::input,
        std::string(analysis) + " needs a consistent graph: the balance equation of channel '" +
            std::string(g.channel_name(rep.channel)) + "' fails (" + std::to_string(rep.q_src) +
            "*" + std::to_string(g.channel(rep.channel).prd) + " != " + std::to_string(rep.q_dst) +
            "*" + std::to_string(g.channel(rep.channel).cns) + ")");
  return std::move(rep.q);
}

Hsdf expand(const Graph& g, const std::vector<uint64_t>& q, uint64_t max_size) {
  auto too_big = [&] {
    throw Error(Error::Kind::limit, "the HSDF expansion has more than " + std::to_string(max_size) +
                                        " firings and edges (the limit of this analysis)");
  };
  Hsdf h;
  h.first.resize(g.actor_count() + 1);
  uint64_t firings = 0;
  for (ActorId a = 0; a < g.actor_count(); ++a) {
    h.first[a] = static_cast<uint32_t>(firings);
    firings += q[a];
    if (firings > max_size || firings >= UINT32_MAX) too_big();
  }
  h.first[g.actor_count()] = static_cast<uint32_t>(firings);
  h.actor.resize(firings);
  h.index.resize(firings);
  for (ActorId a = 0; a < g.actor_count(); ++a)
    for (uint64_t k = 0; k < q[a]; ++k) h.actor[h.first[a] + k] = a, h.index[h.first[a] + k] = k;
  for (const Channel& c : g.channels()) {
    const i128 qs = q[c.src], p = c.prd, cn = c.cns, d = c.delay;
    for (uint64_t k = 0; k < q[c.dst]; ++k) {
      const i128 lo = floor_div(static_cast<i128>(k) * cn - d, p);
      const i128 hi = floor_div((static_cast<i128>(k) + 1) * cn - 1 - d, p);
      // More than q[src] producers means every firing of src, some twice: keep the newest.
      for (i128 j = std::max(lo, hi - qs + 1); j <= hi; ++j) {
        const i128 back = -floor_div(j, qs);
        const auto from = static_cast<uint32_t>(h.first[c.src] +
                                                static_cast<uint64_t>(j - floor_div(j, qs) * qs));
        h.edges.push_back(
            {from, static_cast<uint32_t>(h.first[c.dst] + k), static_cast<uint64_t>(back)});
        if (h.edges.size() + firings > max_size) too_big();
      }
    }
  }
  std::sort(h.edges.begin(), h.edges.end(), [](const HsdfEdge& a, const HsdfEdge& b) {
    return a.src != b.src ? a.src < b.src : a.dst != b.dst ? a.dst < b.dst : a.tokens < b.tokens;
  });
  h.edges.erase(std::unique(h.edges.begin(), h.edges.end(),
                            [](const HsdfEdge& a, const HsdfEdge& b) {
                              return a.src == b.src && a.dst == b.dst;
                            }),
                h.edges.end());
  return h;
}

}  // namespace detail

std::vector<uint64_t> execution_times(const Graph& g, std::optional<uint64_t> default_time) {
  std::vector<uint64_t> t(g.actor_count());
  for (ActorId a = 0; a < g.actor_count(); ++a) {
    const std::optional<uint64_t> v = g.actor_time(a) ? g.actor_time(a) : default_time;
    if (!v)
      throw Error(Error::Kind::input,
                  "actor '" + g.actor_name(a) +
                      "' has no execution time (SDF3 <sdfProperties>, the JSON form's \"time\", "
                      "or a default time)");
    t[a] = *v;
  }
  return t;
}

Graph to_hsdf(const Graph& g, uint64_t max_size) {
  const std::vector<uint64_t> q = detail::repetitions_or_throw(g, "the HSDF expansion");
  const detail::Hsdf h = detail::expand(g, q, max_size);
  Graph out;
  out.name = g.name;
  out.reserve(h.actor.size(), h.edges.size());
  for (uint32_t f = 0; f < h.actor.size(); ++f) {
    const ActorId a = h.actor[f];
    std::string name = g.actor_name(a) + "_" + std::to_string(h.index[f]);
    if (out.find_actor(name))
      throw Error(Error::Kind::input, "the HSDF expansion names two firings '" + name +
                                          "' (rename the actor that ends in _<number>)");
    const ActorId id = out.add_actor(std::move(name));
    out.set_actor_type(id, g.actor_type(a).empty() ? g.actor_name(a) : g.actor_type(a));
    if (const auto t = g.actor_time(a)) out.set_actor_time(id, *t);
  }
  for (const detail::HsdfEdge& e : h.edges) out.add_channel(e.src, e.dst, 1, 1, e.tokens);
  return out;
}

std::string Throughput::str() const {
  if (unbounded) return "unbounded";
  if (num == 0) return "0";
  return std::to_string(num) + "/" + std::to_string(den);
}

}  // namespace sdf
