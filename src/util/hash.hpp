// World-state hashing for the determinism contract: the same scenario and seed must give the
// same hash after every tick, on any thread count. Doubles are hashed by bit pattern, so -0.0
// and 0.0 differ and any last-bit difference shows.
#pragma once

#include <bit>
#include <cstdint>
#include <span>

namespace crowddb {

class StateHasher {
 public:
  void add(uint64_t word) {
    // Multiply-xorshift mix per word; order-dependent by construction.
    h_ = (h_ ^ word) * 0x100000001b3ull;
    h_ ^= h_ >> 29;
  }
  void add(double v) { add(std::bit_cast<uint64_t>(v)); }
  void add(std::span<const double> column) {
    for (double v : column) add(v);
  }
  uint64_t digest() const {
    uint64_t z = h_;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }

 private:
  uint64_t h_ = 0xcbf29ce484222325ull;
};

}  // namespace crowddb
