// Deterministic random numbers. std::uniform_*_distribution is avoided on purpose: its output
// differs between standard libraries, and scenario generation must give the same world everywhere.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace crowddb {

// SplitMix64: used to expand one 64-bit seed into generator state.
inline uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// xoshiro256** (Blackman & Vigna): fast, 256-bit state, passes BigCrush.
class Rng {
 public:
  explicit Rng(uint64_t seed = 0) { reseed(seed); }

  void reseed(uint64_t seed) {
    uint64_t sm = seed;
    for (auto& w : s_) w = splitmix64(sm);
  }

  // An independent stream derived from this generator's seed and a stream number, so that
  // adding draws to one part of a scenario does not shift the numbers another part gets.
  static Rng stream(uint64_t seed, uint64_t stream_id) {
    uint64_t sm = seed ^ (0xd1b54a32d192ed03ull * (stream_id + 1));
    return Rng(splitmix64(sm));
  }

  // The generator's whole state (checkpoints save it and set it back).
  std::array<uint64_t, 4> state() const { return {s_[0], s_[1], s_[2], s_[3]}; }
  void set_state(const std::array<uint64_t, 4>& s) {
    for (int i = 0; i < 4; ++i) s_[i] = s[static_cast<std::size_t>(i)];
  }

  uint64_t next() {
    const uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

  // Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

  // A direction uniform on the circle, (x, y) of unit length, without a sine or a cosine (glibc's
  // sincos was 2 % of an ORCA tick at 2 * 10^4 agents, drawing every wish's perturbation): a
  // point uniform in the unit disc, by rejection from the square (1.27 tries on average; should
  // 64 in a row fail, a chance of 10^-43, it gives (1, 0)), scaled to unit length.
  void direction(double& x, double& y) {
    for (int k = 0; k < 64; ++k) {
      const double u = uniform(-1, 1), v = uniform(-1, 1), r2 = u * u + v * v;
      if (r2 > 1e-12 && r2 <= 1) {
        const double r = std::sqrt(r2);
        x = u / r;
        y = v / r;
        return;
      }
    }
    x = 1;
    y = 0;
  }

  // Uniform integer in [0, n), unbiased (Lemire's multiply-and-reject), n > 0.
  uint64_t below(uint64_t n) {
    __extension__ using u128 = unsigned __int128;
    u128 m = static_cast<u128>(next()) * n;
    auto low = static_cast<uint64_t>(m);
    if (low < n) {
      const uint64_t threshold = (0 - n) % n;
      while (low < threshold) {
        m = static_cast<u128>(next()) * n;
        low = static_cast<uint64_t>(m);
      }
    }
    return static_cast<uint64_t>(m >> 64);
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t s_[4];
};

}  // namespace crowddb
