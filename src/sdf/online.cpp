#include "sdf/online.hpp"

#include <algorithm>

#include "sdf/checked.hpp"

namespace sdf {

struct OnlineScheduler::Topology {
  std::vector<ActorId> src, dst;
  std::vector<char> self;  // per channel: a self-loop
  std::vector<uint32_t> in_off, out_off;
  std::vector<ChannelId> in, out;
};

namespace {

// Zobrist-style term of one (slot, value) pair; the state hash is the wrapping sum of the terms.
inline uint64_t term(uint64_t slot, uint64_t value) {
  uint64_t z = value + 0x9e3779b97f4a7c15ull * (slot + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
constexpr uint64_t kCountSalt = 0x632be59bd9b4e019ull;

}  // namespace

OnlineScheduler::OnlineScheduler(const Graph& g, std::span<const uint64_t> q, OnlineOptions options,
                                 std::span<const uint64_t> tokens)
    : opt_(options), n_(g.actor_count()) {
  auto topo = std::make_shared<Topology>();
  const size_t e = g.channel_count();
  const Adjacency adj(g);
  topo->src.resize(e);
  topo->dst.resize(e);
  topo->self.resize(e);
  prd_.resize(e);
  cns_.resize(e);
  for (ChannelId c = 0; c < e; ++c) {
    const Channel& ch = g.channel(c);
    topo->src[c] = ch.src;
    topo->dst[c] = ch.dst;
    topo->self[c] = ch.src == ch.dst;
    prd_[c] = ch.prd;
    cns_[c] = ch.cns;
  }
  topo->in_off.assign(n_ + 1, 0);
  topo->out_off.assign(n_ + 1, 0);
  for (ActorId a = 0; a < n_; ++a) {
    topo->in_off[a + 1] = topo->in_off[a] + static_cast<uint32_t>(adj.inputs(a).size());
    topo->out_off[a + 1] = topo->out_off[a] + static_cast<uint32_t>(adj.outputs(a).size());
    topo->in.insert(topo->in.end(), adj.inputs(a).begin(), adj.inputs(a).end());
    topo->out.insert(topo->out.end(), adj.outputs(a).begin(), adj.outputs(a).end());
  }
  topo_ = std::move(topo);
  tokens_ = tokens.empty() ? g.delays() : std::vector<uint64_t>(tokens.begin(), tokens.end());
  if (tokens_.size() != e) throw Error(Error::Kind::input, "token state has the wrong size");
  if (opt_.bounded && q.size() != n_)
    throw Error(Error::Kind::input, "online-bounded needs the repetitions vector");
  q_ = opt_.bounded ? std::vector<uint64_t>(q.begin(), q.end()) : std::vector<uint64_t>(n_, 1);
  count_.assign(n_, 0);
  for (ChannelId c = 0; c < e; ++c) token_hash_ += term(c, tokens_[c]);
  for (ActorId a = 0; a < n_; ++a) count_hash_ += term(a ^ kCountSalt, 0);
  key_num_.assign(n_, 1);
  key_den_.assign(n_, 1);
  stamp_.assign(n_, 0);
  pos_.assign(n_, UINT32_MAX);
  has_fired_.assign(n_, 0);
  owing_ = n_;
  for (ActorId a = 0; a < n_; ++a) {
    recompute_key(a);
    if (eligible(a)) heap_push(a);
  }
}

void OnlineScheduler::reset_fired() {
  std::fill(has_fired_.begin(), has_fired_.end(), 0);
  actors_fired_ = 0;
}

void OnlineScheduler::set_caps(std::vector<uint64_t> caps) {
  caps_ = std::move(caps);
}

std::optional<ChannelId> OnlineScheduler::exceeded_channel() const {
  if (exceeded_ < 0) return std::nullopt;
  return static_cast<ChannelId>(exceeded_);
}

// key = min over inputs of tokens/cns, kept as the minimising fraction; 1/1 without inputs.
void OnlineScheduler::recompute_key(ActorId a) {
  const Topology& t = *topo_;
  const uint32_t lo = t.in_off[a], hi = t.in_off[a + 1];
  if (lo == hi) {
    key_num_[a] = key_den_[a] = 1;
    return;
  }
  uint64_t num = tokens_[t.in[lo]], den = cns_[t.in[lo]];
  for (uint32_t i = lo + 1; i < hi; ++i) {
    const ChannelId c = t.in[i];
    if (static_cast<detail::u128>(tokens_[c]) * den < static_cast<detail::u128>(num) * cns_[c]) {
      num = tokens_[c];
      den = cns_[c];
    }
  }
  key_num_[a] = num;
  key_den_[a] = den;
}

bool OnlineScheduler::eligible(ActorId a) const {
  return key_num_[a] >= key_den_[a] && count_[a] < q_[a];
}

// Larger key first; then earlier eligibility; then lower id.
bool OnlineScheduler::better(ActorId a, ActorId b) const {
  const detail::u128 l = static_cast<detail::u128>(key_num_[a]) * key_den_[b];
  const detail::u128 r = static_cast<detail::u128>(key_num_[b]) * key_den_[a];
  if (l != r) return l > r;
  if (stamp_[a] != stamp_[b]) return stamp_[a] < stamp_[b];
  return a < b;
}

void OnlineScheduler::sift_up(uint32_t i) {
  const ActorId a = heap_[i];
  while (i > 0) {
    const uint32_t parent = (i - 1) / 2;
    if (!better(a, heap_[parent])) break;
    heap_[i] = heap_[parent];
    pos_[heap_[i]] = i;
    i = parent;
  }
  heap_[i] = a;
  pos_[a] = i;
}

void OnlineScheduler::sift_down(uint32_t i) {
  const ActorId a = heap_[i];
  const auto size = static_cast<uint32_t>(heap_.size());
  for (;;) {
    uint32_t child = 2 * i + 1;
    if (child >= size) break;
    if (child + 1 < size && better(heap_[child + 1], heap_[child])) ++child;
    if (!better(heap_[child], a)) break;
    heap_[i] = heap_[child];
    pos_[heap_[i]] = i;
    i = child;
  }
  heap_[i] = a;
  pos_[a] = i;
}

void OnlineScheduler::heap_push(ActorId a) {
  heap_.push_back(a);
  sift_up(static_cast<uint32_t>(heap_.size() - 1));
}

void OnlineScheduler::heap_remove(ActorId a) {
  const uint32_t i = pos_[a];
  pos_[a] = UINT32_MAX;
  const ActorId last = heap_.back();
  heap_.pop_back();
  if (last == a) return;
  heap_[i] = last;
  pos_[last] = i;
  sift_up(i);
  sift_down(pos_[last]);
}

void OnlineScheduler::heap_fix(ActorId a) {
  sift_up(pos_[a]);
  sift_down(pos_[a]);
}

void OnlineScheduler::set_tokens(ChannelId c, uint64_t value) {
  token_hash_ += term(c, value) - term(c, tokens_[c]);
  tokens_[c] = value;
}

void OnlineScheduler::set_count(ActorId a, uint64_t value) {
  count_hash_ += term(a ^ kCountSalt, value) - term(a ^ kCountSalt, count_[a]);
  count_[a] = value;
}

// Re-evaluates an actor whose inputs or count changed without it firing: it joins the heap
// (stamped now) when it became eligible, leaves when it no longer is, and moves otherwise.
void OnlineScheduler::refresh(ActorId a) {
  recompute_key(a);
  const bool in_heap = pos_[a] != UINT32_MAX;
  if (eligible(a)) {
    if (in_heap) {
      heap_fix(a);
    } else {
      stamp_[a] = decisions_;
      heap_push(a);
    }
  } else if (in_heap) {
    heap_remove(a);
  }
}

void OnlineScheduler::start_iteration() {
  ++iterations_;
  owing_ = n_;
  for (ActorId a = 0; a < n_; ++a) set_count(a, 0);
  for (ActorId a = 0; a < n_; ++a) refresh(a);
}

std::optional<Run> OnlineScheduler::step(uint64_t max_firings) {
  if (heap_.empty() || max_firings == 0) return std::nullopt;
  const Topology& t = *topo_;
  const ActorId a = heap_[0];
  uint64_t k = 1;
  if (opt_.firings == FiringRule::floor_key) k = key_num_[a] / key_den_[a];
  if (opt_.bounded) k = std::min(k, q_[a] - count_[a]);
  k = std::min(k, max_firings);
  // Fire k times. ⌊key⌋ firings are admissible in a row: on a plain input k·cns <= tokens; on
  // a self-loop losing cns - prd per firing the k-th needs cns + (k-1)(cns-prd) <= k·cns.
  for (uint32_t i = t.in_off[a]; i < t.in_off[a + 1]; ++i) {
    const ChannelId c = t.in[i];
    if (!t.self[c]) set_tokens(c, tokens_[c] - k * cns_[c]);
  }
  for (uint32_t i = t.out_off[a]; i < t.out_off[a + 1]; ++i) {
    const ChannelId c = t.out[i];
    uint64_t v;
    if (t.self[c] && prd_[c] < cns_[c]) {
      v = tokens_[c] - k * (cns_[c] - prd_[c]);
    } else {
      const uint64_t gain = t.self[c] ? prd_[c] - cns_[c] : prd_[c];
      v = detail::add(tokens_[c], detail::mul(k, gain, "a token count"), "a token count");
    }
    set_tokens(c, v);
    if (!caps_.empty() && v > caps_[c] && exceeded_ < 0) exceeded_ = c;
  }
  ++decisions_;
  firings_ = detail::add_sat(firings_, k);
  if (!has_fired_[a]) {
    has_fired_[a] = 1;
    ++actors_fired_;
  }
  if (opt_.bounded) {
    set_count(a, count_[a] + k);
    if (count_[a] == q_[a]) --owing_;
  }
  // The winner: still eligible counts as newly eligible.
  recompute_key(a);
  if (eligible(a)) {
    stamp_[a] = decisions_;
    sift_down(0);
  } else {
    heap_remove(a);
  }
  // Its consumers' keys can only have grown.
  for (uint32_t i = t.out_off[a]; i < t.out_off[a + 1]; ++i) {
    const ActorId b = t.dst[t.out[i]];
    if (b == a) continue;
    recompute_key(b);
    if (pos_[b] != UINT32_MAX) {
      sift_up(pos_[b]);
    } else if (eligible(b)) {
      stamp_[b] = decisions_;
      heap_push(b);
    }
  }
  if (opt_.bounded && owing_ == 0) start_iteration();
  return Run{a, k};
}

void OnlineScheduler::change_rates(ActorId a, uint64_t prd, uint64_t cns,
                                   std::span<const uint64_t> q_new) {
  if (prd == 0 || cns == 0) throw Error(Error::Kind::input, "rates must be positive");
  const Topology& t = *topo_;
  for (uint32_t i = t.out_off[a]; i < t.out_off[a + 1]; ++i) prd_[t.out[i]] = prd;
  for (uint32_t i = t.in_off[a]; i < t.in_off[a + 1]; ++i) cns_[t.in[i]] = cns;
  if (opt_.bounded) {
    if (q_new.size() != n_)
      throw Error(Error::Kind::input, "online-bounded needs the new repetitions vector");
    q_.assign(q_new.begin(), q_new.end());
    --iterations_;  // start_iteration counts the one it begins; this one was cut short
    start_iteration();
  } else {
    refresh(a);  // only a's key depends on the cns it consumes
  }
}

std::vector<ActorId> OnlineScheduler::eligibility_order() const {
  std::vector<ActorId> order(heap_.begin(), heap_.end());
  std::sort(order.begin(), order.end(), [&](ActorId x, ActorId y) {
    return stamp_[x] != stamp_[y] ? stamp_[x] < stamp_[y] : x < y;
  });
  return order;
}

bool OnlineScheduler::same_state(const OnlineScheduler& other) const {
  return state_hash() == other.state_hash() && tokens_ == other.tokens_ && count_ == other.count_ &&
         heap_.size() == other.heap_.size() && eligibility_order() == other.eligibility_order();
}

const char* outcome_name(Outcome o) {
  switch (o) {
    case Outcome::returns:
      return "returns";
    case Outcome::periodic:
      return "periodic";
    case Outcome::unbounded:
      return "unbounded";
    case Outcome::deadlock:
      return "deadlock";
    case Outcome::limit:
      return "limit";
  }
  return "?";
}

OnlineRun run_online(const Graph& g, std::span<const uint64_t> q, const OnlineRunOptions& options) {
  return run_online(g, q, OnlineScheduler(g, q, options.scheduler), options);
}

OnlineRun run_online(const Graph& g, std::span<const uint64_t> q, const OnlineScheduler& start,
                     const OnlineRunOptions& options) {
  const size_t n = g.actor_count();
  std::vector<uint64_t> caps(g.channel_count());
  for (ChannelId c = 0; c < g.channel_count(); ++c) {
    const Channel& ch = g.channel(c);
    caps[c] = detail::add_sat(
        start.tokens()[c],
        detail::mul_sat(options.growth_periods, detail::mul_sat(q[ch.src], ch.prd)));
  }
  const std::vector<uint64_t> tokens0(start.tokens().begin(), start.tokens().end());
  const uint64_t hash0 = start.state_hash();
  // Every actor must have fired for a return to the start tokens to be a period; in a connected
  // graph a return implies it, in a disconnected one a component may not have moved yet.
  const std::vector<uint64_t> counts0(start.iteration_counts().begin(),
                                      start.iteration_counts().end());
  auto returned = [&](const OnlineScheduler& s) {
    return s.actors_fired() == n && s.state_hash() == hash0 &&
           std::equal(tokens0.begin(), tokens0.end(), s.tokens().begin()) &&
           std::equal(counts0.begin(), counts0.end(), s.iteration_counts().begin());
  };

  OnlineRun out;
  // Pass 1: detection (Brent). `check` is the tortoise, saved at power-of-two distances.
  OnlineScheduler s = start;
  s.set_caps(caps);
  s.reset_fired();
  OnlineScheduler check = s;
  uint64_t power = 1, lam = 0;
  bool periodic = false;
  for (;;) {
    if (s.decisions() - start.decisions() >= options.max_decisions) {
      out.outcome = Outcome::limit;
      break;
    }
    if (!s.step()) {
      out.outcome = Outcome::deadlock;
      break;
    }
    if (s.exceeded_channel()) {
      out.outcome = Outcome::unbounded;
      out.channel = s.exceeded_channel();
      break;
    }
    if (returned(s)) {
      out.outcome = Outcome::returns;
      break;
    }
    ++lam;
    if (s.state_hash() == check.state_hash() && s.same_state(check)) {
      periodic = true;
      break;
    }
    if (lam == power) {
      check = s;
      power *= 2;
      lam = 0;
    }
  }
  if (periodic) {
    // Every state of the cycle has been seen once with all its actors fired; a return to the
    // start tokens could still lie ahead within one more cycle (disconnected graphs only).
    out.outcome = Outcome::periodic;
    for (uint64_t i = 0; i < lam; ++i) {
      s.step();
      if (returned(s)) {
        out.outcome = Outcome::returns;
        break;
      }
    }
  }
  out.decisions_explored = s.decisions() - start.decisions();
  if (out.outcome == Outcome::periodic) {
    // Pass 2: a scheduler λ decisions ahead; the first decision count at which the two agree is
    // the transient's length μ.
    OnlineScheduler ahead = start, behind = start;
    for (uint64_t i = 0; i < lam; ++i) ahead.step();
    uint64_t mu = 0;
    while (!(ahead.state_hash() == behind.state_hash() && ahead.same_state(behind))) {
      ahead.step();
      behind.step();
      ++mu;
    }
    out.transient_decisions = mu;
    out.cycle_decisions = lam;
  } else {
    out.transient_decisions = out.decisions_explored;
    if (out.outcome == Outcome::returns) {
      out.cycle_decisions = out.transient_decisions;
      out.transient_decisions = 0;
    }
  }
  // Pass 3: replay the window, listing the runs (if not too many) and measuring.
  const uint64_t total = out.transient_decisions + out.cycle_decisions;
  out.runs_listed = total <= options.max_listed_runs;
  const Eligibility model = options.scheduler.bounded ? Eligibility::owing : Eligibility::fireable;
  Meter meter(g, q, model, start.tokens(),
              options.scheduler.bounded ? start.iteration_counts() : std::span<const uint64_t>{});
  OnlineScheduler r = start;
  out.cycle_fired.assign(n, 0);
  for (uint64_t i = 0; i < total; ++i) {
    const std::optional<Run> run = r.step();
    if (!run) break;  // cannot happen: the same deterministic run as pass 1
    meter.record(*run);
    if (out.runs_listed) out.runs.push_back(*run);
    if (i < out.transient_decisions) {
      out.transient_firings = detail::add_sat(out.transient_firings, run->count);
    } else {
      out.cycle_firings = detail::add_sat(out.cycle_firings, run->count);
      out.cycle_fired[run->actor] = detail::add_sat(out.cycle_fired[run->actor], run->count);
    }
  }
  out.metrics = meter.metrics();
  return out;
}

}  // namespace sdf
