// A small binary encoding for checkpoints: fixed-width little-endian integers and IEEE doubles
// (bit patterns, so a state read back is bit-identical), and length-prefixed vectors. The reader
// checks every length against the bytes left, so a damaged or hostile file costs at most its own
// size and ends in Error(input) naming the byte offset, never a crash.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "crowddb/error.hpp"
#include "util/hash.hpp"

namespace crowddb {

// A checksum of bytes (8 at a time through StateHasher's mix): a checkpoint ends with the
// checksum of everything before it, so damage anywhere is caught before anything is parsed.
// Taken in pieces (a record streamed out as it is written): whole words first, then the rest.
class Checksum {
 public:
  // Bytes whose count is a multiple of 8, in order.
  void add_words(std::string_view bytes) {
    for (std::size_t i = 0; i + 8 <= bytes.size(); i += 8) h_.add(word(bytes.data() + i, 8));
    count_ += bytes.size();
  }
  // The last bytes (any count) and the checksum of all.
  uint64_t finish(std::string_view rest) {
    const std::size_t whole = rest.size() & ~std::size_t{7};
    add_words(rest.substr(0, whole));
    h_.add(word(rest.data() + whole, rest.size() - whole));
    h_.add(static_cast<uint64_t>(count_ + rest.size() - whole));
    return h_.digest();
  }

 private:
  static uint64_t word(const char* p, std::size_t n) {
    uint64_t w = 0;
    for (std::size_t k = 0; k < n; ++k)
      w |= static_cast<uint64_t>(static_cast<uint8_t>(p[k])) << (8 * k);
    return w;
  }
  StateHasher h_;
  uint64_t count_ = 0;
};

inline uint64_t checksum(std::string_view bytes) {
  return Checksum().finish(bytes);
}

// Where a streamed record's bytes go, piece by piece, in order.
using ByteSink = std::function<void(std::string_view)>;

class ByteWriter {
 public:
  // A sealed record starts with `magic` and ends with seal(): ByteReader::open_sealed checks both.
  explicit ByteWriter(std::string_view magic = {}) {
    if (!magic.empty()) text(magic);
  }
  // Streams the record to `sink` instead of keeping it, so that it never sits whole in memory (a
  // checkpoint of 10^6 agents is 200 MB): from now on, each time `chunk` bytes are waiting they
  // go to the sink (a multiple of 8 bytes, the checksum kept as they pass), and seal() hands on
  // the rest and returns nothing. The sink sees exactly the bytes seal() would have returned.
  void stream_to(ByteSink sink, std::size_t chunk = std::size_t{1} << 20) {
    sink_ = std::move(sink);
    chunk_ = std::max<std::size_t>(chunk, 8);
    spill_if_full();
  }
  void u8(uint8_t v) {
    out_.push_back(static_cast<char>(v));
    if (out_.size() >= chunk_) spill_if_full();
  }
  void u32(uint32_t v) { uint_le(v); }
  void u64(uint64_t v) { uint_le(v); }
  void f64(double v) { u64(std::bit_cast<uint64_t>(v)); }
  void text(std::string_view s) {
    u64(s.size());
    out_.append(s);
    spill_if_full();
  }
  // A vector of integers, doubles or one-byte enums.
  template <class T>
  void vec(const std::vector<T>& v) {
    u64(v.size());
    for (const T& x : v) one(x);
  }
  const std::string& bytes() const { return out_; }
  std::string take() { return std::move(out_); }
  // The record with the checksum of every byte before it appended (streamed: handed on, and
  // the string returned is empty).
  std::string seal() {
    const uint64_t sum = spilled_.finish(out_);
    const std::size_t limit = std::exchange(chunk_, SIZE_MAX);  // the rest goes on in one piece
    u64(sum);
    if (sink_) {
      sink_(out_);
      out_.clear();
    }
    chunk_ = limit;
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
  // Hands the waiting whole words to the sink once `chunk_` bytes wait (never without a sink).
  void spill_if_full() {
    if (!sink_ || out_.size() < chunk_) return;
    const std::size_t whole = out_.size() & ~std::size_t{7};
    const std::string_view words(out_.data(), whole);
    spilled_.add_words(words);
    sink_(words);
    out_.erase(0, whole);
  }
  std::string out_;
  ByteSink sink_;
  std::size_t chunk_ = SIZE_MAX;  // no sink: everything stays in out_
  Checksum spilled_;              // of the bytes handed on so far
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
