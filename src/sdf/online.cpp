#include "sdf/online.hpp"

#include <algorithm>

#include "sdf/checked.hpp"

namespace sdf {

struct OnlineScheduler::Topology {
  std::vector<ActorId> src, dst;
  std::vector<char> self;      // per channel: a self-loop
  std::vector<char> has_loop;  // per actor: one of its channels is a self-loop
  std::vector<uint32_t> in_off, out_off;
  std::vector<ChannelId> in, out;
  std::vector<ActorId> out_dst;   // dst of out[i], beside it
  std::vector<std::string> name;  // per channel, for messages
};

namespace {

// The salt of hash slot `slot` (channels, then per-actor counts): fixed, odd, well mixed.
inline uint64_t salt_of(uint64_t slot) {
  uint64_t z = 0x9e3779b97f4a7c15ull * (slot + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return (z ^ (z >> 31)) | 1;
}
// ⌊num / den⌋ (den > 0). A 64-bit integer division has a long latency on the critical path of
// a decision; below 2^52 a double division gives the quotient or one off, corrected exactly.
inline uint64_t floor_div(uint64_t num, uint64_t den) {
  if (den == 1) return num;
  constexpr uint64_t kExact = uint64_t{1} << 52;
  if (num >= kExact || den >= kExact) return num / den;
  auto k = static_cast<uint64_t>(static_cast<double>(num) / static_cast<double>(den));
  if (k * den > num) --k;
  if ((k + 1) * den <= num) ++k;
  return k;
}

constexpr uint64_t kCountSalt = 0x632be59bd9b4e019ull;
constexpr uint64_t kSmall = uint64_t{1} << 21;

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
  topo->has_loop.assign(n_, 0);
  prd_.resize(e);
  cns_.resize(e);
  for (ChannelId c = 0; c < e; ++c) {
    const Channel& ch = g.channel(c);
    topo->src[c] = ch.src;
    topo->dst[c] = ch.dst;
    topo->self[c] = ch.src == ch.dst;
    topo->name.emplace_back(g.channel_name(c));
    if (ch.src == ch.dst) topo->has_loop[ch.src] = 1;
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
  topo->out_dst.resize(topo->out.size());
  for (size_t i = 0; i < topo->out.size(); ++i) topo->out_dst[i] = topo->dst[topo->out[i]];
  topo_ = std::move(topo);
  tokens_ = tokens.empty() ? g.delays() : std::vector<uint64_t>(tokens.begin(), tokens.end());
  if (tokens_.size() != e) throw Error(Error::Kind::input, "token state has the wrong size");
  if (opt_.bounded && q.size() != n_)
    throw Error(Error::Kind::input, "online-bounded needs the repetitions vector");
  q_ = opt_.bounded ? std::vector<uint64_t>(q.begin(), q.end()) : std::vector<uint64_t>(n_, 1);
  count_.assign(n_, 0);
  salt_.resize(e);
  for (ChannelId c = 0; c < e; ++c) {
    salt_[c] = salt_of(c);
    token_hash_ += tokens_[c] * salt_[c];
  }
  key_num_.assign(n_, 1);
  key_arg_.assign(n_, kNone);
  key_den_.assign(n_, 1);
  stamp_.assign(n_, 0);
  pos_.assign(n_, UINT32_MAX);
  prev_.assign(n_, kNone);
  next_.assign(n_, kNone);
  in_list_.assign(n_, 0);
  has_fired_.assign(n_, 0);
  owing_ = n_;
  for (ActorId a = 0; a < n_; ++a) {
    recompute_key(a);
    if (eligible(a)) insert_eligible(a);
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
    key_arg_[a] = kNone;
    return;
  }
  ChannelId arg = t.in[lo];
  uint64_t num = tokens_[arg], den = cns_[arg];
  for (uint32_t i = lo + 1; i < hi; ++i) {
    const ChannelId c = t.in[i];
    if (static_cast<detail::u128>(tokens_[c]) * den < static_cast<detail::u128>(num) * cns_[c]) {
      num = tokens_[c];
      den = cns_[c];
      arg = c;
    }
  }
  key_num_[a] = num;
  key_den_[a] = den;
  key_arg_[a] = arg;
}

bool OnlineScheduler::eligible(ActorId a) const {
  return key_num_[a] >= key_den_[a] && count_[a] < q_[a];
}

OnlineScheduler::Entry OnlineScheduler::entry(ActorId a) const {
  const uint64_t num = key_num_[a], den = key_den_[a];
  return {static_cast<double>(num) / static_cast<double>(den), stamp_[a], a,
          num < kSmall && den < kSmall};
}

// Larger key first; then earlier eligibility; then lower id. With both keys small the doubles
// decide exactly and the whole comparison is computed without branches (in the heap's sifts
// it is a coin toss, and mispredicted branches dominated a decision's cost).
inline bool OnlineScheduler::better(const Entry& x, const Entry& y) const {
  if (__builtin_expect(x.small & y.small, 1))
    return (x.key > y.key) | ((x.key == y.key) &
                              ((x.stamp < y.stamp) | ((x.stamp == y.stamp) & (x.actor < y.actor))));
  return better_exact(x, y);
}

bool OnlineScheduler::better_exact(const Entry& x, const Entry& y) const {
  const double gap = (x.key > y.key ? x.key : y.key) * 1e-12;
  if (x.key - y.key > gap) return true;
  if (y.key - x.key > gap) return false;
  const int c = detail::compare_fractions(key_num_[x.actor], key_den_[x.actor], key_num_[y.actor],
                                          key_den_[y.actor]);
  if (c != 0) return c > 0;
  if (x.stamp != y.stamp) return x.stamp < y.stamp;
  return x.actor < y.actor;
}

void OnlineScheduler::sift_up(uint32_t i) {
  const Entry e = heap_[i];
  while (i > 0) {
    const uint32_t parent = (i - 1) / 2;
    if (!better(e, heap_[parent])) break;
    heap_[i] = heap_[parent];
    pos_[heap_[i].actor] = i;
    i = parent;
  }
  heap_[i] = e;
  pos_[e.actor] = i;
}

void OnlineScheduler::sift_down(uint32_t i) {
  const Entry e = heap_[i];
  const auto size = static_cast<uint32_t>(heap_.size());
  for (;;) {
    uint32_t child = 2 * i + 1;
    if (child >= size) break;
    if (child + 1 < size) child += better(heap_[child + 1], heap_[child]);
    if (!better(heap_[child], e)) break;
    heap_[i] = heap_[child];
    pos_[heap_[i].actor] = i;
    i = child;
  }
  heap_[i] = e;
  pos_[e.actor] = i;
}

void OnlineScheduler::heap_push(ActorId a) {
  heap_.push_back(entry(a));
  sift_up(static_cast<uint32_t>(heap_.size() - 1));
}

// Floyd's bottom-up deletion: the hole walks down to a leaf along the better children (one
// comparison per level instead of two), the last entry fills it and sifts up, usually little.
void OnlineScheduler::heap_remove(ActorId a) {
  uint32_t i = pos_[a];
  pos_[a] = UINT32_MAX;
  const Entry last = heap_.back();
  heap_.pop_back();
  if (last.actor == a) return;
  const auto size = static_cast<uint32_t>(heap_.size());
  for (;;) {
    uint32_t child = 2 * i + 1;
    if (child >= size) break;
    if (child + 1 < size) child += better(heap_[child + 1], heap_[child]);
    heap_[i] = heap_[child];
    pos_[heap_[i].actor] = i;
    i = child;
  }
  heap_[i] = last;
  pos_[last.actor] = i;
  sift_up(i);
}

void OnlineScheduler::set_tokens(ChannelId c, uint64_t value) {
  token_hash_ += (value - tokens_[c]) * salt_[c];  // wrapping arithmetic: exact mod 2^64
  tokens_[c] = value;
}

void OnlineScheduler::set_count(ActorId a, uint64_t value) {
  count_hash_ += (value - count_[a]) * (salt_of(a) ^ kCountSalt);
  count_[a] = value;
}

// Eligible actors with key exactly 1 wait in a list in (stamp, id) order; those with a larger
// key in the heap, where any of them beats every list member. Insertion scans back from the
// tail, which in a decision only passes actors stamped in the same decision.
void OnlineScheduler::list_insert(ActorId a) {
  uint32_t after = tail_;
  while (after != kNone && (stamp_[after] > stamp_[a] || (stamp_[after] == stamp_[a] && after > a)))
    after = prev_[after];
  const uint32_t before = after == kNone ? head_ : next_[after];
  prev_[a] = after;
  next_[a] = before;
  (after == kNone ? head_ : next_[after]) = a;
  (before == kNone ? tail_ : prev_[before]) = a;
  in_list_[a] = 1;
  ++listed_;
}

void OnlineScheduler::list_remove(ActorId a) {
  (prev_[a] == kNone ? head_ : next_[prev_[a]]) = next_[a];
  (next_[a] == kNone ? tail_ : prev_[next_[a]]) = prev_[a];
  in_list_[a] = 0;
  --listed_;
}

void OnlineScheduler::insert_eligible(ActorId a) {
  if (key_num_[a] == key_den_[a]) {
    list_insert(a);
  } else {
    heap_push(a);
  }
}

void OnlineScheduler::remove_eligible(ActorId a) {
  if (in_list_[a]) {
    list_remove(a);
  } else if (pos_[a] != UINT32_MAX) {
    heap_remove(a);
  }
}

// Re-evaluates an actor whose inputs or count changed without it firing: it joins (stamped
// now) when it became eligible, leaves when it no longer is, and moves otherwise.
void OnlineScheduler::refresh(ActorId a) {
  const bool was = in_list_[a] || pos_[a] != UINT32_MAX;
  remove_eligible(a);
  recompute_key(a);
  if (eligible(a)) {
    if (!was) stamp_[a] = decisions_;
    insert_eligible(a);
  }
}

void OnlineScheduler::start_iteration() {
  ++iterations_;
  owing_ = n_;
  for (ActorId a = 0; a < n_; ++a) set_count(a, 0);
  for (ActorId a = 0; a < n_; ++a) refresh(a);
}

std::optional<Run> OnlineScheduler::step(uint64_t max_firings) {
  if ((heap_.empty() && head_ == kNone) || max_firings == 0) return std::nullopt;
  const Topology& t = *topo_;
  const bool from_heap = !heap_.empty();
  const ActorId a = from_heap ? heap_[0].actor : head_;
  uint64_t k = 1;
  if (opt_.firings == FiringRule::floor_key) k = floor_div(key_num_[a], key_den_[a]);
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
      v = detail::add_tokens(tokens_[c], k, gain, t.name[c]);
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
  // The winner's key. Every input that is not a self-loop lost exactly k·cns tokens, so each
  // tokens/cns dropped by exactly k and the minimising input (the first of the least) is still
  // the same one: its new tokens/cns is the key, as recompute_key would find. A self-loop input
  // changes by another amount, and an actor without inputs keeps 1/1.
  if (t.has_loop[a]) {
    recompute_key(a);
  } else if (key_arg_[a] != kNone) {
    key_num_[a] = tokens_[key_arg_[a]];
  }
  // Still eligible counts as newly eligible.
  if (eligible(a)) {
    stamp_[a] = decisions_;
    if (from_heap && key_num_[a] != key_den_[a]) {
      heap_[0] = entry(a);
      sift_down(0);
    } else {
      remove_eligible(a);
      insert_eligible(a);
    }
  } else {
    remove_eligible(a);
  }
  // Its consumers' keys can only have grown, and only if the channel that grew was the one
  // setting the key (the first input with the least tokens/cns): otherwise nothing changes.
  for (uint32_t i = t.out_off[a]; i < t.out_off[a + 1]; ++i) {
    const ChannelId c = t.out[i];
    const ActorId b = t.out_dst[i];
    if (b == a || key_arg_[b] != c) continue;
    recompute_key(b);
    if (pos_[b] != UINT32_MAX) {
      heap_[pos_[b]] = entry(b);  // same stamp, larger key
      sift_up(pos_[b]);
    } else if (in_list_[b]) {
      if (key_num_[b] != key_den_[b]) {  // rose above 1: to the heap, same stamp
        list_remove(b);
        heap_push(b);
      }
    } else if (eligible(b)) {
      stamp_[b] = decisions_;
      insert_eligible(b);
    }
  }
  if (opt_.bounded && owing_ == 0) start_iteration();
  return Run{a, k};
}

void OnlineScheduler::change_rates(ActorId a, std::span<const ChannelRates> rates,
                                   std::span<const uint64_t> q_new) {
  for (const ChannelRates& r : rates) {
    if (r.prd == 0 || r.cns == 0) throw Error(Error::Kind::input, "rates must be positive");
    if (r.channel >= prd_.size()) throw Error(Error::Kind::input, "change_rates: unknown channel");
  }
  for (const ChannelRates& r : rates) {
    prd_[r.channel] = r.prd;
    cns_[r.channel] = r.cns;
  }
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
  std::vector<ActorId> order;
  for (const Entry& e : heap_) order.push_back(e.actor);
  for (uint32_t a = head_; a != kNone; a = next_[a]) order.push_back(a);
  std::sort(order.begin(), order.end(), [&](ActorId x, ActorId y) {
    return stamp_[x] != stamp_[y] ? stamp_[x] < stamp_[y] : x < y;
  });
  return order;
}

bool OnlineScheduler::same_state(const OnlineScheduler& other) const {
  return state_hash() == other.state_hash() && tokens_ == other.tokens_ && count_ == other.count_ &&
         heap_.size() == other.heap_.size() && listed_ == other.listed_ &&
         eligibility_order() == other.eligibility_order();
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
      for (ActorId a = 0; a < g.actor_count(); ++a)
        if (s.iteration_counts()[a] < q[a]) out.stuck.push_back(a);
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
