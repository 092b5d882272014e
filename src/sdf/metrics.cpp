#include "sdf/metrics.hpp"

#include <algorithm>

#include "sdf/checked.hpp"

namespace sdf {

Meter::Meter(const Graph& g, std::span<const uint64_t> q, Eligibility model,
             std::span<const uint64_t> tokens, std::span<const uint64_t> counts)
    : g_(&g), adj_(g), q_(q.begin(), q.end()), model_(model) {
  const size_t n = g.actor_count();
  tokens_ = tokens.empty() ? g.delays() : std::vector<uint64_t>(tokens.begin(), tokens.end());
  count_ = counts.empty() ? std::vector<uint64_t>(n, 0)
                          : std::vector<uint64_t>(counts.begin(), counts.end());
  if (q_.empty()) q_.assign(n, UINT64_MAX);
  for (ActorId a = 0; a < n; ++a)
    if (count_[a] < q_[a]) ++owing_;
  m_.buffers = tokens_;
  stamp_.assign(n, 0);
  is_eligible_.assign(n, 0);
  for (ActorId a = 0; a < n; ++a) is_eligible_[a] = eligible(a) ? 1 : 0;
}

bool Meter::eligible(ActorId a) const {
  if (model_ == Eligibility::owing && count_[a] >= q_[a]) return false;
  for (ChannelId c : adj_.inputs(a))
    if (tokens_[c] < g_->channel(c).cns) return false;
  return true;
}

void Meter::update(ActorId a) {
  const bool now = eligible(a);
  if (now && !is_eligible_[a]) stamp_[a] = decision_;
  is_eligible_[a] = now ? 1 : 0;
}

void Meter::start_iteration() {
  std::fill(count_.begin(), count_.end(), 0);
  owing_ = count_.size();
  for (ActorId a = 0; a < count_.size(); ++a) update(a);
}

void Meter::record(const Run& run) {
  const ActorId a = run.actor;
  if (!is_eligible_[a]) m_.followed_model = false;
  const uint64_t wait = decision_ - stamp_[a];
  m_.fairness.max = std::max(m_.fairness.max, wait);
  sum_wait_ += wait;
  ++decision_;
  uint64_t allowed = run.count;
  if (model_ == Eligibility::owing) allowed = std::min(allowed, q_[a] - std::min(q_[a], count_[a]));
  for (ChannelId c : adj_.inputs(a)) {
    const Channel& ch = g_->channel(c);
    allowed =
        std::min(allowed, detail::firings_allowed(tokens_[c], ch.prd, ch.cns, ch.src == ch.dst));
  }
  if (allowed < run.count) {
    m_.followed_model = false;
    return;  // the rest of the replay would be meaningless; metrics stop here
  }
  const uint64_t k = run.count;
  for (ChannelId c : adj_.inputs(a)) {
    const Channel& ch = g_->channel(c);
    if (ch.src != ch.dst) tokens_[c] -= k * ch.cns;
  }
  for (ChannelId c : adj_.outputs(a)) {
    const Channel& ch = g_->channel(c);
    if (ch.src == ch.dst && ch.prd < ch.cns) {
      tokens_[c] -= k * (ch.cns - ch.prd);
    } else {
      const uint64_t gain = ch.src == ch.dst ? ch.prd - ch.cns : ch.prd;
      tokens_[c] = detail::add_tokens(tokens_[c], k, gain, *g_, c);
    }
    m_.buffers[c] = std::max(m_.buffers[c], tokens_[c]);
  }
  const bool owed = count_[a] < q_[a];
  count_[a] = detail::add_sat(count_[a], k);
  if (owed && count_[a] >= q_[a]) --owing_;
  is_eligible_[a] = 0;  // an actor that fired and is still eligible counts as newly eligible
  update(a);
  for (ChannelId c : adj_.outputs(a)) update(g_->channel(c).dst);
  if (model_ == Eligibility::owing && owing_ == 0) start_iteration();
}

const Metrics& Meter::metrics() {
  m_.fairness.decisions = decision_;
  m_.fairness.mean =
      decision_ == 0 ? 0.0 : static_cast<double>(sum_wait_) / static_cast<double>(decision_);
  return m_;
}

Metrics measure(const Graph& g, std::span<const uint64_t> q, Eligibility model,
                std::span<const Run> runs, std::span<const uint64_t> tokens) {
  Meter m(g, q, model, tokens);
  for (const Run& r : runs) m.record(r);
  return m.metrics();
}

}  // namespace sdf
