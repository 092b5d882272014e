// ByteWriter streamed to a sink (checkpoints that never sit whole in memory) hands on exactly the
// bytes it would have returned, whatever the chunk size and wherever streaming starts.
#include "util/byte_codec.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

namespace crowddb {
namespace {

// A record of every kind of field, from a seed; `stream_after` fields in (at the end if there
// are fewer), `start` is called.
template <class Start>
std::string write_record(uint32_t seed, std::size_t fields, std::size_t stream_after,
                         ByteWriter& out, Start start) {
  std::mt19937_64 rng(seed);
  for (std::size_t f = 0; f < fields; ++f) {
    if (f == stream_after) start();
    switch (rng() % 6) {
      case 0:
        out.u8(static_cast<uint8_t>(rng()));
        break;
      case 1:
        out.u32(static_cast<uint32_t>(rng()));
        break;
      case 2:
        out.u64(rng());
        break;
      case 3:
        out.f64(std::uniform_real_distribution<double>(-1e9, 1e9)(rng));
        break;
      case 4:
        out.text(std::string(rng() % 3000, static_cast<char>('a' + rng() % 26)));
        break;
      default: {
        std::vector<double> v(rng() % 500);
        for (double& x : v) x = static_cast<double>(rng() % 1000) / 7;
        out.vec(v);
      }
    }
  }
  if (stream_after >= fields) start();
  return out.seal();
}

TEST(ByteWriter, AStreamedRecordIsTheRecordItWouldHaveReturned) {
  for (uint32_t seed = 1; seed <= 40; ++seed)
    for (std::size_t chunk : {1, 7, 8, 9, 64, 1000, 4096, 1 << 20}) {
      const std::size_t fields = seed % 7 == 0 ? 0 : seed * 11;
      ByteWriter whole("magic");
      const std::string expected = write_record(seed, fields, 0, whole, [] {});

      std::string got;
      std::vector<std::size_t> pieces;
      ByteWriter streamed("magic");
      const std::size_t after = seed % 3 == 0 ? 0 : seed % 5;  // at once, or a few fields in
      const std::string returned = write_record(seed, fields, after, streamed, [&] {
        streamed.stream_to(
            [&](std::string_view piece) {
              got.append(piece);
              pieces.push_back(piece.size());
            },
            chunk);
      });
      SCOPED_TRACE("seed " + std::to_string(seed) + ", chunk " + std::to_string(chunk));
      EXPECT_TRUE(returned.empty());
      ASSERT_EQ(got, expected);
      ASSERT_FALSE(pieces.empty());
      for (std::size_t i = 0; i + 1 < pieces.size(); ++i) EXPECT_EQ(pieces[i] % 8, 0u) << i;
      // Memory stays bounded: nothing waits much longer than a chunk (a text field is one append).
      if (chunk >= 4096) {
        for (std::size_t p : pieces) EXPECT_LE(p, chunk + 3000 + 8);
      }
      EXPECT_NO_THROW(ByteReader::open_sealed(got, "magic", "record", "test"));
    }
}

TEST(Checksum, InPiecesIsTheChecksumOfTheWhole) {
  std::mt19937_64 rng(7);
  for (int round = 0; round < 200; ++round) {
    std::string bytes(rng() % 200, '\0');
    for (char& c : bytes) c = static_cast<char>(rng());
    Checksum pieces;
    std::size_t at = 0;
    while (at + 8 <= bytes.size() && rng() % 3 != 0) {
      const std::size_t words = 1 + rng() % ((bytes.size() - at) / 8);
      pieces.add_words(std::string_view(bytes).substr(at, 8 * words));
      at += 8 * words;
    }
    EXPECT_EQ(pieces.finish(std::string_view(bytes).substr(at)), checksum(bytes)) << round;
  }
}

}  // namespace
}  // namespace crowddb
