// Reading an input file whole, with bounded work: a directory, a device (/dev/zero, a terminal)
// or a socket is refused at once, and reading stops with an error past `limit` bytes, so no
// input can make a loader read until memory runs out. Regular files and pipes are read.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace crowddb {

inline constexpr uint64_t kMaxInputBytes = uint64_t{1} << 30;  // 1 GiB

// The file's bytes. Throws Error(io) naming the path: missing, unreadable, a directory, not a
// regular file or pipe, or longer than `limit`.
std::string read_input_file(const std::filesystem::path& path, uint64_t limit = kMaxInputBytes);

}  // namespace crowddb
