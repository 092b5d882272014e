// A map from 64-bit keys to small values that only grows: open addressing with linear probing,
// at most half full, one value reserved to mark an empty slot. For tables of up to one entry
// per agent that are looked up once per agent and never erased (SteerBench's measured ids,
// PlacementGrid's cells): 12–16 bytes a slot where a node-based map costs 40 or more an entry and a
// cache miss or two a lookup.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace crowddb {

template <class V, V kEmpty>
class FlatMap {
 public:
  // The value of `key`, kEmpty when absent.
  V find(uint64_t key) const {
    if (keys_.empty()) return kEmpty;
    for (std::size_t s = home(key);; s = (s + 1) & (keys_.size() - 1)) {
      if (values_[s] == kEmpty) return kEmpty;
      if (keys_[s] == key) return values_[s];
    }
  }
  // The value of `key`, made (kEmpty) when absent; the caller stores a value other than kEmpty
  // into a made one before the next call.
  V& at(uint64_t key) {
    if (2 * (size_ + 1) > keys_.size()) reserve(size_ + 1);
    std::size_t s = home(key);
    while (values_[s] != kEmpty && keys_[s] != key) s = (s + 1) & (keys_.size() - 1);
    if (values_[s] == kEmpty) {
      keys_[s] = key;
      ++size_;
    }
    return values_[s];
  }
  // Room for `entries` without growing.
  void reserve(std::size_t entries) {
    std::size_t cap = 64;
    while (cap < 2 * entries) cap *= 2;
    if (cap <= keys_.size()) return;
    std::vector<uint64_t> keys(cap, 0);
    std::vector<V> values(cap, kEmpty);
    keys.swap(keys_);
    values.swap(values_);
    for (std::size_t s = 0; s < keys.size(); ++s) {
      if (values[s] == kEmpty) continue;
      std::size_t t = home(keys[s]);
      while (values_[t] != kEmpty) t = (t + 1) & (keys_.size() - 1);
      keys_[t] = keys[s];
      values_[t] = values[s];
    }
  }
  std::size_t size() const { return size_; }
  void clear() {
    keys_.clear();
    values_.clear();
    size_ = 0;
  }

 private:
  // A full mix (ids and cell keys are often consecutive or share their low bits).
  std::size_t home(uint64_t key) const {
    uint64_t z = key;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return static_cast<std::size_t>(z) & (keys_.size() - 1);
  }

  std::vector<uint64_t> keys_;
  std::vector<V> values_;  // kEmpty: an empty slot
  std::size_t size_ = 0;
};

}  // namespace crowddb
