// A record streamed rather than held (ByteWriter::stream_to): written twice when its size must
// be known first, once to count its bytes and once into room made for exactly that many (a
// checkpoint into an SQLite blob, Python's save_state into a bytes object).
#pragma once

#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string_view>

#include "util/byte_codec.hpp"

namespace crowddb {

// Writes a record to the sink it is given, the same bytes at every call.
using StreamedRecord = std::function<void(const ByteSink&)>;

// The bytes `record` hands on.
inline std::size_t streamed_size(const StreamedRecord& record) {
  std::size_t size = 0;
  record([&size](std::string_view piece) { size += piece.size(); });
  return size;
}

// `record` once more, each piece given to put(piece, offset) within room of `size` bytes.
// Throws std::logic_error when it hands on more or fewer than `size` (it changed in between).
template <class Put>
void stream_into(const StreamedRecord& record, std::size_t size, Put&& put) {
  std::size_t at = 0;
  record([&](std::string_view piece) {
    if (piece.size() > size - at) throw std::logic_error("a streamed record grew between passes");
    put(piece, at);
    at += piece.size();
  });
  if (at != size) throw std::logic_error("a streamed record shrank between passes");
}

}  // namespace crowddb
