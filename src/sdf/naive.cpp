#include "sdf/naive.hpp"

#include <algorithm>
#include <charconv>
#include <map>
#include <numeric>
#include <pugixml.hpp>
#include <sstream>

#include "hsdf.hpp"
#include "json_detail.hpp"
#include "sdf/checked.hpp"
#include "sdf/text.hpp"
#include "sdf/throughput.hpp"

namespace sdf::naive {

namespace {

__extension__ using u128 = unsigned __int128;

bool can_fire(const Graph& g, const std::vector<uint64_t>& tokens, ActorId a) {
  for (ChannelId c = 0; c < g.channel_count(); ++c)
    if (g.channel(c).dst == a && tokens[c] < g.channel(c).cns) return false;
  return true;
}

// One firing, exactly as the definition says: consume from every input, then produce.
void fire_once(const Graph& g, std::vector<uint64_t>& tokens, ActorId a) {
  for (ChannelId c = 0; c < g.channel_count(); ++c)
    if (g.channel(c).dst == a) tokens[c] -= g.channel(c).cns;
  for (ChannelId c = 0; c < g.channel_count(); ++c)
    if (g.channel(c).src == a) tokens[c] += g.channel(c).prd;
}

struct Fraction {
  uint64_t num = 0;  // 0 = not yet visited
  uint64_t den = 1;
};

// n/d · a/b with everything reduced first, so the result is reduced and every product is at
// most the reduced result's numerator or denominator (which are bounded by the final q).
Fraction scale(Fraction f, uint64_t a, uint64_t b) {
  const uint64_t g = std::gcd(a, b);
  a /= g;
  b /= g;
  const uint64_t g1 = std::gcd(f.num, b);
  const uint64_t g2 = std::gcd(a, f.den);
  return {detail::mul(f.num / g1, a / g2, "a repetitions-vector entry"),
          detail::mul(f.den / g2, b / g1, "a repetitions-vector entry")};
}

}  // namespace

Repetitions repetitions(const Graph& g) {
  const size_t n = g.actor_count();
  const Adjacency adj(g);
  Repetitions r;
  r.q.assign(n, 0);
  std::vector<Fraction> frac(n);
  std::vector<ActorId> stack, members;
  for (ActorId start = 0; start < n; ++start) {
    if (frac[start].num != 0) continue;
    members.clear();
    frac[start] = {1, 1};
    stack.push_back(start);
    while (!stack.empty()) {
      const ActorId a = stack.back();
      stack.pop_back();
      members.push_back(a);
      for (ChannelId c : adj.outputs(a)) {
        const Channel& ch = g.channel(c);
        if (frac[ch.dst].num == 0) {
          frac[ch.dst] = scale(frac[a], ch.prd, ch.cns);
          stack.push_back(ch.dst);
        }
      }
      for (ChannelId c : adj.inputs(a)) {
        const Channel& ch = g.channel(c);
        if (frac[ch.src].num == 0) {
          frac[ch.src] = scale(frac[a], ch.cns, ch.prd);
          stack.push_back(ch.src);
        }
      }
    }
    // lcm of the denominators, then integers; the result is already primitive (see header) but
    // dividing by the gcd costs nothing and keeps that an invariant rather than a proof.
    uint64_t l = 1;
    for (ActorId a : members) {
      const uint64_t d = frac[a].den;
      l = detail::mul(l / std::gcd(l, d), d, "the lcm of repetitions denominators");
    }
    uint64_t common = 0;
    for (ActorId a : members) {
      r.q[a] = detail::mul(frac[a].num, l / frac[a].den, "a repetitions-vector entry");
      common = std::gcd(common, r.q[a]);
    }
    for (ActorId a : members) r.q[a] /= common;
  }
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    const detail::u128 lhs = static_cast<detail::u128>(r.q[ch.src]) * ch.prd;
    const detail::u128 rhs = static_cast<detail::u128>(r.q[ch.dst]) * ch.cns;
    if (lhs != rhs) {
      r.consistent = false;
      r.channel = c;
      r.q_src = r.q[ch.src];
      r.q_dst = r.q[ch.dst];
      r.q.clear();
      return r;
    }
  }
  r.consistent = true;
  return r;
}

std::vector<uint64_t> max_run(const Graph& g, std::span<const uint64_t> q, crowddb::Rng& rng) {
  std::vector<uint64_t> tokens = g.delays(), count(g.actor_count(), 0);
  for (;;) {
    std::vector<ActorId> ready;
    for (ActorId a = 0; a < g.actor_count(); ++a)
      if (count[a] < q[a] && can_fire(g, tokens, a)) ready.push_back(a);
    if (ready.empty()) return count;
    const ActorId a = ready[rng.below(ready.size())];
    fire_once(g, tokens, a);
    ++count[a];
  }
}

NaiveOnline online(const Graph& g, std::span<const uint64_t> q, const OnlineRunOptions& options) {
  const size_t n = g.actor_count();
  const bool bounded = options.scheduler.bounded;
  std::vector<uint64_t> tokens = g.delays(), count(n, 0), stamp(n, 0);
  const std::vector<uint64_t> tokens0 = tokens;
  std::vector<uint64_t> cap(g.channel_count());
  for (ChannelId c = 0; c < g.channel_count(); ++c)
    cap[c] = tokens0[c] + options.growth_periods * q[g.channel(c).src] * g.channel(c).prd;
  auto eligible = [&](ActorId a) {
    return (!bounded || count[a] < q[a]) && can_fire(g, tokens, a);
  };
  // key as a fraction: min over inputs of tokens/cns, 1/1 without inputs.
  auto key = [&](ActorId a) {
    std::pair<uint64_t, uint64_t> k{1, 1};
    bool any = false;
    for (ChannelId c = 0; c < g.channel_count(); ++c) {
      if (g.channel(c).dst != a) continue;
      const std::pair<uint64_t, uint64_t> f{tokens[c], g.channel(c).cns};
      if (!any || static_cast<u128>(f.first) * k.second < static_cast<u128>(k.first) * f.second)
        k = f;
      any = true;
    }
    return k;
  };
  std::vector<char> was(n);
  for (ActorId a = 0; a < n; ++a) was[a] = eligible(a);
  auto state = [&]() {
    std::vector<uint64_t> s = tokens;
    s.insert(s.end(), count.begin(), count.end());
    std::vector<ActorId> order;
    for (ActorId a = 0; a < n; ++a)
      if (was[a]) order.push_back(a);
    std::sort(order.begin(), order.end(), [&](ActorId x, ActorId y) {
      return stamp[x] != stamp[y] ? stamp[x] < stamp[y] : x < y;
    });
    s.push_back(UINT64_MAX);
    s.insert(s.end(), order.begin(), order.end());
    return s;
  };
  std::map<std::vector<uint64_t>, uint64_t> seen;
  seen[state()] = 0;
  std::vector<char> fired(n, 0);
  NaiveOnline out;
  uint64_t extra = 0;  // after a repeat: decisions left to look for a return
  bool periodic = false;
  for (uint64_t t = 0;; ++t) {
    if (!periodic && t >= options.max_decisions) {
      out.outcome = Outcome::limit;
      return out;
    }
    int64_t best = -1;
    std::pair<uint64_t, uint64_t> bk;
    for (ActorId a = 0; a < n; ++a) {
      if (!was[a]) continue;
      const auto k = key(a);
      const u128 l = static_cast<u128>(k.first) * bk.second;
      const u128 r = static_cast<u128>(bk.first) * k.second;
      if (best < 0 || l > r || (l == r && stamp[a] < stamp[best])) {
        best = a;
        bk = k;
      }
    }
    if (best < 0) {
      out.outcome = Outcome::deadlock;
      return out;
    }
    const auto a = static_cast<ActorId>(best);
    uint64_t k = options.scheduler.firings == FiringRule::one ? 1 : bk.first / bk.second;
    if (bounded) k = std::min(k, q[a] - count[a]);
    out.runs.push_back({a, k});
    out.waits.push_back(t - stamp[a]);
    for (uint64_t i = 0; i < k; ++i) fire_once(g, tokens, a);
    fired[a] = 1;
    if (bounded) {
      count[a] += k;
      bool all = true;
      for (ActorId b = 0; b < n; ++b) all = all && count[b] >= q[b];
      if (all) std::fill(count.begin(), count.end(), 0);
    }
    for (ActorId b = 0; b < n; ++b) {
      const bool now = eligible(b);
      if (now && (!was[b] || b == a)) stamp[b] = t + 1;
      was[b] = now;
    }
    if (periodic) {
      if (--extra == 0) {  // no return within one more cycle
        out.runs.resize(out.transient + out.cycle);
        out.waits.resize(out.transient + out.cycle);
        return out;
      }
    } else {
      for (ChannelId c = 0; c < g.channel_count(); ++c) {
        if (tokens[c] > cap[c]) {
          out.outcome = Outcome::unbounded;
          out.channel = c;
          return out;
        }
      }
    }
    const bool all_fired = std::all_of(fired.begin(), fired.end(), [](char f) { return f; });
    bool zero_counts = std::all_of(count.begin(), count.end(), [](uint64_t c) { return c == 0; });
    if (all_fired && zero_counts && tokens == tokens0) {
      out.outcome = Outcome::returns;
      out.transient = 0;
      out.cycle = t + 1;
      out.runs.resize(t + 1);
      out.waits.resize(t + 1);
      return out;
    }
    if (!periodic) {
      auto [it, inserted] = seen.try_emplace(state(), t + 1);
      if (!inserted) {
        periodic = true;
        out.outcome = Outcome::periodic;
        out.transient = it->second;
        out.cycle = t + 1 - it->second;
        extra = out.cycle;
      }
    }
  }
}

namespace {

// Calls f(d) for every distribution of the given size with d[c] ≥ floor[c] (default: the delay
// of c).
template <class F>
void for_each_distribution(const Graph& g, uint64_t size, std::span<const uint64_t> floor_of,
                           F&& f) {
  const size_t m = g.channel_count();
  std::vector<uint64_t> d(m), base(m);
  uint64_t floor = 0;
  for (ChannelId c = 0; c < m; ++c)
    floor += d[c] = base[c] = floor_of.empty() ? g.channel(c).delay : floor_of[c];
  if (size < floor) return;
  if (m == 0) {
    if (size == 0) f(d);
    return;
  }
  // Spread `left` over channels c.. (the last takes the rest).
  auto spread = [&](auto& self, size_t c, uint64_t left) -> void {
    if (c + 1 == m) {
      d[c] = base[c] + left;
      f(d);
      return;
    }
    for (uint64_t x = 0; x <= left; ++x) {
      d[c] = base[c] + x;
      self(self, c + 1, left - x);
    }
  };
  spread(spread, 0, size - floor);
}

uint64_t floor_sum(const Graph& g, std::span<const uint64_t> floor) {
  uint64_t s = 0;
  for (ChannelId c = 0; c < g.channel_count(); ++c)
    s += floor.empty() ? g.channel(c).delay : floor[c];
  return s;
}

}  // namespace

StorageSearch minimal_storage(const Graph& g, uint64_t max_size) {
  const Repetitions rep = compute_repetitions(g);
  StorageSearch r;
  if (!rep.consistent) return r;
  for (uint64_t size = floor_sum(g, {}); size <= max_size; ++size) {
    for_each_distribution(g, size, {}, [&](const std::vector<uint64_t>& d) {
      ++r.explored;
      if (static_schedule(bounded_graph(g, d), rep.q).complete) r.distributions.push_back(d);
    });
    if (!r.distributions.empty()) {
      r.size = size;
      std::sort(r.distributions.begin(), r.distributions.end());
      return r;
    }
  }
  return r;
}

ParetoSearch pareto(const Graph& g, uint64_t max_size, std::span<const uint64_t> floor) {
  ParetoSearch r;
  r.max_throughput = throughput_mcm(g);
  auto less = [](const Throughput& a, const Throughput& b) {
    if (a.unbounded || b.unbounded) return !a.unbounded && b.unbounded;
    return detail::compare_fractions(a.num, a.den, b.num, b.den) < 0;
  };
  Throughput best;
  for (uint64_t size = floor_sum(g, floor); size <= max_size; ++size) {
    std::vector<std::pair<std::vector<uint64_t>, Throughput>> all;
    Throughput top;
    for_each_distribution(g, size, floor, [&](const std::vector<uint64_t>& d) {
      ++r.explored;
      const Graph b = bounded_graph(g, d);
      const Throughput ss = throughput_state_space(b), mcm = throughput_mcm(b);
      if (ss.str() != mcm.str())
        throw std::logic_error("naive pareto: the two methods disagree: " + ss.str() + " and " +
                               mcm.str());
      all.push_back({d, ss});
      if (less(top, ss)) top = ss;
    });
    if (!less(best, top)) continue;
    ParetoPoint p;
    p.size = size;
    p.throughput = top;
    p.throughput.states = 0;
    for (const auto& [d, t] : all)
      if (!less(t, top)) p.distributions.push_back(d);
    std::sort(p.distributions.begin(), p.distributions.end());
    r.points.push_back(std::move(p));
    best = top;
    if (!less(best, r.max_throughput)) {
      r.complete = true;
      return r;
    }
  }
  return r;
}

Latency latency(const Graph& g, const LatencyOptions& o, std::optional<uint64_t> default_time) {
  if (o.from.has_value() != o.to.has_value() || o.iterations == 0 || g.actor_count() == 0)
    throw Error(Error::Kind::input, "naive latency: bad options or no actors");
  const std::vector<uint64_t> q = detail::repetitions_or_throw(g, "latency");
  const std::vector<uint64_t> times = execution_times(g, default_time);
  const detail::Hsdf h = detail::expand(g, q, UINT32_MAX - 1);
  const size_t f_count = h.actor.size(), k = o.iterations, n = g.actor_count();
  Latency r;
  // Deadlock: the token-free edges have a cycle.
  std::vector<size_t> indegree(f_count, 0);
  for (const detail::HsdfEdge& e : h.edges)
    if (e.tokens == 0) ++indegree[e.dst];
  std::vector<uint32_t> ready;
  for (uint32_t f = 0; f < f_count; ++f)
    if (indegree[f] == 0) ready.push_back(f);
  size_t sorted = 0;
  while (!ready.empty()) {
    const uint32_t f = ready.back();
    ready.pop_back();
    ++sorted;
    for (const detail::HsdfEdge& e : h.edges)
      if (e.tokens == 0 && e.src == f && --indegree[e.dst] == 0) ready.push_back(e.dst);
  }
  if (sorted < f_count) {
    r.deadlock = true;
    return r;
  }
  // start[i][f], end[i][f]; relaxed iteration by iteration.
  std::vector<std::vector<uint64_t>> start(k, std::vector<uint64_t>(f_count, 0)), end = start;
  for (size_t i = 0; i < k; ++i) {
    for (size_t f = 0; f < f_count; ++f) end[i][f] = times[h.actor[f]];
    for (bool changed = true; changed;) {
      changed = false;
      for (const detail::HsdfEdge& e : h.edges) {
        if (e.tokens > i) continue;
        const uint64_t ready_at = end[i - e.tokens][e.src];
        if (ready_at > start[i][e.dst]) start[i][e.dst] = ready_at, changed = true;
      }
      for (size_t f = 0; f < f_count; ++f)
        end[i][f] = detail::add(start[i][f], times[h.actor[f]], "a time");
    }
  }
  // The definitions read off the expansion: firing i·q[a] + 1 of a is a_0 of iteration i,
  // firing (i + 1)·q[a] is a_{q[a]−1}.
  __extension__ using i128 = __int128;
  auto first_start = [&](size_t i, ActorId a) -> i128 { return start[i][h.first[a]]; };
  auto last_end = [&](size_t i, ActorId a) -> i128 { return end[i][h.first[a + 1] - 1]; };
  for (size_t i = 0; i < k; ++i) {
    i128 from = first_start(i, 0), to = last_end(i, 0);
    if (o.from) {
      from = first_start(i, *o.from);
      to = last_end(i, *o.to);
    } else {
      for (ActorId a = 1; a < n; ++a)
        from = std::min(from, first_start(i, a)), to = std::max(to, last_end(i, a));
    }
    if (to - from > INT64_MAX || to - from < INT64_MIN) detail::overflow("a latency");
    r.per_iteration.push_back(static_cast<int64_t>(to - from));
  }
  const auto top = std::max_element(r.per_iteration.begin(), r.per_iteration.end());
  r.max = *top;
  r.iteration = static_cast<uint64_t>(top - r.per_iteration.begin());  // the first largest
  for (ActorId a = 0; a < n; ++a)
    r.makespan = std::max(r.makespan, static_cast<uint64_t>(last_end(k - 1, a)));
  return r;
}

GraphStats stats(const Graph& g) {
  GraphStats st;
  const size_t n = g.actor_count();
  st.actors = n;
  st.channels = g.channel_count();
  u128 tokens = 0;
  for (const Channel& c : g.channels()) {
    if (c.src == c.dst) ++st.self_loops;
    tokens += c.delay;
  }
  if (tokens <= UINT64_MAX) st.initial_tokens = static_cast<uint64_t>(tokens);
  try {
    const Repetitions rep = repetitions(g);
    st.consistent = rep.consistent;
    if (rep.consistent) {
      u128 sum = 0;
      uint64_t max = 0;
      for (uint64_t v : rep.q) sum += v, max = std::max(max, v);
      if (sum <= UINT64_MAX) st.repetitions_sum = static_cast<uint64_t>(sum);
      st.repetitions_max = max;
    }
  } catch (const Error& e) {
    if (e.kind() != Error::Kind::overflow) throw;
    st.repetitions_overflow = true;
  }
  // reach[u][v]: a path of channels from u to v (of length ≥ 0).
  auto bfs = [&](ActorId from, bool undirected) {
    std::vector<char> seen(n, 0);
    std::vector<ActorId> work{from};
    seen[from] = 1;
    while (!work.empty()) {
      const ActorId u = work.back();
      work.pop_back();
      for (const Channel& c : g.channels()) {
        size_t next = n;
        if (c.src == u) next = c.dst;
        if (undirected && c.dst == u) next = c.src;
        if (next < n && !seen[next]) seen[next] = 1, work.push_back(static_cast<ActorId>(next));
      }
    }
    return seen;
  };
  std::vector<std::vector<char>> reach(n);
  for (ActorId a = 0; a < n; ++a) reach[a] = bfs(a, false);
  std::vector<char> done(n, 0);
  for (ActorId a = 0; a < n; ++a) {
    if (done[a]) continue;
    ++st.sccs;
    uint32_t size = 0;
    bool cyclic = false;
    for (ActorId b = 0; b < n; ++b) {
      if (!(reach[a][b] && reach[b][a])) continue;
      done[b] = 1;
      ++size;
    }
    for (const Channel& c : g.channels())
      cyclic = cyclic || (reach[a][c.src] && reach[c.src][a] && reach[a][c.dst] && reach[c.dst][a]);
    st.largest_scc = std::max(st.largest_scc, size);
    st.cyclic_sccs += cyclic;
  }
  std::vector<char> seen(n, 0);
  for (ActorId a = 0; a < n; ++a) {
    if (seen[a]) continue;
    ++st.components;
    const std::vector<char> part = bfs(a, true);
    for (ActorId b = 0; b < n; ++b) seen[b] = seen[b] || part[b];
  }
  // Every simple cycle once, from its smallest actor.
  std::vector<char> on_path(n, 0);
  auto walk = [&](auto& self, ActorId s, ActorId v) -> void {
    for (const Channel& c : g.channels()) {
      if (c.src != v) continue;
      if (c.dst == s) {
        ++st.simple_cycles;
      } else if (c.dst > s && !on_path[c.dst]) {
        on_path[c.dst] = 1;
        self(self, s, c.dst);
        on_path[c.dst] = 0;
      }
    }
  };
  for (ActorId s = 0; s < n; ++s) {
    on_path[s] = 1;
    walk(walk, s, s);
    on_path[s] = 0;
  }
  return st;
}

namespace {

// The SDF3 reader as it was before the streaming one (a pugixml document, two passes over
// <sdf>), kept as its twin.
struct DomPort {
  ActorId actor;
  std::string_view name;
  bool out;
  uint64_t rate;
  size_t offset;  // of the <port> element; its line is computed only for an error message
  int64_t channel = -1;
};

class DomReader {
 public:
  DomReader(std::string_view text, const std::string& source) : text_(text), source_(source) {}

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
    std::sort(ports_.begin(), ports_.end(), [](const DomPort& a, const DomPort& b) {
      return a.actor != b.actor ? a.actor < b.actor : a.name < b.name;
    });
    for (size_t i = 1; i < ports_.size(); ++i)
      if (ports_[i].actor == ports_[i - 1].actor && ports_[i].name == ports_[i - 1].name)
        fail(std::max(ports_[i].offset, ports_[i - 1].offset),
             "duplicate port '" + std::string(ports_[i].name) + "' on actor '" +
                 g.actor_name(ports_[i].actor) + "'");
    port_begin_.assign(g.actor_count() + 1, 0);
    for (const DomPort& p : ports_) ++port_begin_[p.actor + 1];
    for (size_t a = 0; a < g.actor_count(); ++a) port_begin_[a + 1] += port_begin_[a];
    for (pugi::xml_node ch : sdf.children("channel")) read_channel(g, ch);
    for (const DomPort& p : ports_)
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
      fail(node, not_an_integer(attr, text, positive));
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
      DomPort p;
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

  // Times and the kept text through the JSON form's path (its messages differ; the test
  // compares graphs and whether reading fails).
  void read_properties(Graph& g, pugi::xml_node props) {
    std::ostringstream out;
    props.print(out, "", pugi::format_raw, pugi::encoding_utf8);
    detail::read_sdf3_properties(g, out.str(), source_);
  }

  DomPort& find_port(const Graph& g, pugi::xml_node ch, ActorId actor, std::string_view name) {
    // The actor's ports are ports_[port_begin_[actor], port_begin_[actor + 1]), sorted by name.
    const auto first = ports_.begin() + static_cast<ptrdiff_t>(port_begin_[actor]);
    const auto last = ports_.begin() + static_cast<ptrdiff_t>(port_begin_[actor + 1]);
    auto it = std::lower_bound(first, last, name,
                               [](const DomPort& p, std::string_view k) { return p.name < k; });
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
    DomPort& sp = find_port(g, ch, src, required(ch, "srcPort"));
    DomPort& dp = find_port(g, ch, dst, required(ch, "dstPort"));
    if (!sp.out) fail(ch, "srcPort '" + std::string(sp.name) + "' is an input port");
    if (dp.out) fail(ch, "dstPort '" + std::string(dp.name) + "' is an output port");
    for (DomPort* p : {&sp, &dp})
      if (p->channel >= 0)
        fail(ch, "port '" + std::string(p->name) + "' of actor '" + g.actor_name(p->actor) +
                     "' is already connected to channel '" +
                     std::string(g.channel_name(static_cast<ChannelId>(p->channel))) + "'");
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
  std::vector<DomPort> ports_;
  std::vector<size_t> port_begin_;  // per actor, into ports_ (sorted by actor, then name)
};

}  // namespace

Graph read_sdf3(std::string_view text, const std::string& source) {
  DomReader reader(text, source);
  return reader.read(text);
}

}  // namespace sdf::naive
