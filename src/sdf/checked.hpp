// Checked 64-bit arithmetic for counts (repetitions, tokens, firings). Every overflow becomes an
// Error(overflow) naming what was being computed: a wrapped number is never returned.
#pragma once

#include <cstdint>
#include <numeric>
#include <string>
#include <string_view>

#include "sdf/graph.hpp"

namespace sdf::detail {

__extension__ using u128 = unsigned __int128;

[[noreturn]] inline void overflow(const std::string& what) {
  throw Error(Error::Kind::overflow, what + " does not fit in 64 bits");
}

inline uint64_t mul(uint64_t a, uint64_t b, const char* what) {
  uint64_t r;
  if (__builtin_mul_overflow(a, b, &r)) overflow(what);
  return r;
}

inline uint64_t add(uint64_t a, uint64_t b, const char* what) {
  uint64_t r;
  if (__builtin_add_overflow(a, b, &r)) overflow(what);
  return r;
}

// tokens + k·gain on channel `name`; an overflow names the channel.
[[noreturn]] inline void token_overflow(std::string_view name) {
  overflow("the token count on channel '" + std::string(name) + "'");
}
inline uint64_t add_tokens(uint64_t tokens, uint64_t k, uint64_t gain, std::string_view name) {
  uint64_t r;
  if (__builtin_mul_overflow(k, gain, &r) || __builtin_add_overflow(tokens, r, &r))
    token_overflow(name);
  return r;
}
// The same naming channel c of g, whose name is looked up only on overflow (hot loops).
inline uint64_t add_tokens(uint64_t tokens, uint64_t k, uint64_t gain, const Graph& g,
                           ChannelId c) {
  uint64_t r;
  if (__builtin_mul_overflow(k, gain, &r) || __builtin_add_overflow(tokens, r, &r))
    token_overflow(g.channel_name(c));
  return r;
}

// Saturating forms, for caps and limits where "at least 2^64 - 1" is all that matters.
inline uint64_t mul_sat(uint64_t a, uint64_t b) {
  uint64_t r;
  return __builtin_mul_overflow(a, b, &r) ? UINT64_MAX : r;
}
inline uint64_t add_sat(uint64_t a, uint64_t b) {
  uint64_t r;
  return __builtin_add_overflow(a, b, &r) ? UINT64_MAX : r;
}

// Compares a/b with c/d exactly (b, d > 0): negative, zero or positive.
inline int compare_fractions(uint64_t a, uint64_t b, uint64_t c, uint64_t d) {
  const u128 l = static_cast<u128>(a) * d;
  const u128 r = static_cast<u128>(c) * b;
  return l < r ? -1 : (l > r ? 1 : 0);
}

// Firings of one actor in a row that a channel into it allows, from `tokens` on it. For an
// ordinary input that is tokens / cns. A self-loop gives back prd per firing: with prd >= cns it
// never runs dry once it holds cns tokens (returns UINT64_MAX); with prd < cns each firing
// after the first needs cns - prd more.
inline uint64_t firings_allowed(uint64_t tokens, uint64_t prd, uint64_t cns, bool self_loop) {
  if (tokens < cns) return 0;
  if (!self_loop) return tokens / cns;
  if (prd >= cns) return UINT64_MAX;
  return 1 + (tokens - cns) / (cns - prd);
}

}  // namespace sdf::detail
