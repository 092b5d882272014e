// A small binary encoding for checkpoints: fixed-width little-endian integers and IEEE doubles
// (bit patterns, so a state read back is bit-identical), and length-prefixed vectors. The reader
// checks every length against the bytes left, so a damaged or hostile file costs at most its own
// size and ends in Error(input) naming the byte offset, never a crash.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "crowddb/error.hpp"
#include "util/hash.hpp"

namespace crowddb {

// A checksum of bytes (8 at a time through StateHasher's mix): a checkpoint ends with the
// checksum of everything before it, so damage anywhere is caught before anything is parsed.
inline uint64_t checksum(std::string_view bytes) {
  StateHasher h;
  std::size_t i = 0;
  for (; i + 8 <= bytes.size(); i += 8) {
    uint64_t w = 0;
    for (int k = 0; k < 8; ++k)
      w |= static_cast<uint64_t>(static_cast<uint8_t>(bytes[i + k])) << (8 * k);
    h.add(w);
  }
  uint64_t tail = 0;
  for (int k = 0; i < bytes.size(); ++i, ++k)
    tail |= static_cast<uint64_t>(static_cast<uint8_t>(bytes[i])) << (8 * k);
  h.add(tail);
  h.add(static_cast<uint64_t>(bytes.size()));
  return h.digest();
}

class ByteWriter {
 public:
  // A sealed record starts with `magic` and ends with seal(): ByteReader::open_sealed checks both.
  explicit ByteWriter(std::string_view magic = {}) {
    if (!magic.empty()) text(magic);
  }
  void u8(uint8_t v) { out_.push_back(static_cast<char>(v)); }
  void u32(uint32_t v) { uint_le(v); }
  void u64(uint64_t v) { uint_le(v); }
  void f64(double v) { u64(std::bit_cast<uint64_t>(v)); }
  void text(std::string_view s) {
    u64(s.size());
    out_.append(s);
  }
  // A vector of integers, doubles or one-byte enums.
  template <class T>
  void vec(const std::vector<T>& v) {
    u64(v.size());
    for (const T& x : v) one(x);
  }
  const std::string& bytes() const { return out_; }
  std::string take() { return std::move(out_); }
  // The record with the checksum of every byte before it appended.
  std::string seal() {
    u64(checksum(out_));
    return take();
  }

 private:
  template <class U>
  void uint_le(U v) {
    for (std::size_t i = 0; i < sizeof(U); ++i) u8(static_cast<uint8_t>(v >> (8 * i)));
  }
  template <class T>
  void one(T x) {
    if constexpr (std::is_same_v<T, double>) {
      f64(x);
    } else if constexpr (std::is_enum_v<T>) {
      u8(static_cast<uint8_t>(x));
    } else if constexpr (sizeof(T) == 8) {
      u64(static_cast<uint64_t>(x));
    } else if constexpr (sizeof(T) == 4) {
      u32(static_cast<uint32_t>(x));
    } else {
      static_assert(sizeof(T) == 1);
      u8(static_cast<uint8_t>(x));
    }
  }
  std::string out_;
};

class ByteReader {
 public:
  // `what` names the data in messages ("run.sqlite.partial: checkpoint").
  ByteReader(std::string_view bytes, std::string what) : in_(bytes), what_(std::move(what)) {}

  // A reader over the body of a record written by ByteWriter(magic) ... seal(), after checking its
  // magic ("not a <kind>") and its checksum ("damaged"), before anything else is parsed.
  static ByteReader open_sealed(std::string_view bytes, std::string_view magic,
                                const std::string& kind, std::string what) {
    if (bytes.size() < 8) ByteReader(bytes, what).fail("ends too early");
    const std::string_view body = bytes.substr(0, bytes.size() - 8);
    const uint64_t sum = ByteReader(bytes.substr(body.size()), what).u64();
    ByteReader in(body, std::move(what));
    if (in.text() != magic) in.fail("not a " + kind);
    if (sum != checksum(body)) in.fail("damaged (its checksum does not match)");
    return in;
  }

  uint8_t u8() {
    need(1);
    return static_cast<uint8_t>(in_[pos_++]);
  }
  uint32_t u32() { return uint_le<uint32_t>(); }
  uint64_t u64() { return uint_le<uint64_t>(); }
  double f64() { return std::bit_cast<double>(u64()); }
  std::string text() {
    const uint64_t n = count(1);
    std::string s(in_.substr(pos_, n));
    pos_ += n;
    return s;
  }
  // A length, checked against the bytes left at `bytes_each` per element.
  uint64_t count(uint64_t bytes_each) {
    const uint64_t n = u64();
    if (bytes_each > 0 && n > (in_.size() - pos_) / bytes_each)
      fail("a length of " + std::to_string(n) + " runs past the end");
    return n;
  }
  template <class T>
  void vec(std::vector<T>& v) {
    constexpr uint64_t each = std::is_enum_v<T> ? 1 : sizeof(T);
    v.resize(count(each));
    for (T& x : v) x = one<T>();
  }
  bool at_end() const { return pos_ == in_.size(); }
  std::size_t offset() const { return pos_; }
  [[noreturn]] void fail(const std::string& why) const {
    throw Error(Error::Kind::input, what_ + ": " + why + " (at byte " + std::to_string(pos_) + ")");
  }

 private:
  void need(std::size_t n) {
    if (in_.size() - pos_ < n) fail("ends too early");
  }
  template <class U>
  U uint_le() {
    need(sizeof(U));
    U v = 0;
    for (std::size_t i = 0; i < sizeof(U); ++i)
      v |= static_cast<U>(static_cast<U>(static_cast<uint8_t>(in_[pos_++])) << (8 * i));
    return v;
  }
  template <class T>
  T one() {
    if constexpr (std::is_same_v<T, double>) {
      return f64();
    } else if constexpr (std::is_enum_v<T>) {
      return static_cast<T>(u8());
    } else if constexpr (sizeof(T) == 8) {
      return static_cast<T>(u64());
    } else if constexpr (sizeof(T) == 4) {
      return static_cast<T>(u32());
    } else {
      static_assert(sizeof(T) == 1);
      return static_cast<T>(u8());
    }
  }
  std::string_view in_;
  std::size_t pos_ = 0;
  std::string what_;
};

}  // namespace crowddb
