#include "util/read_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "crowddb/error.hpp"

namespace crowddb {

std::string read_input_file(const std::filesystem::path& path, uint64_t limit) {
  const std::string name = path.string();
  const int fd = ::open(name.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const int err = errno;
    throw Error(Error::Kind::io, name + ": cannot open file (" + std::strerror(err) + ")");
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    throw Error(Error::Kind::io, name + ": cannot read file (" + std::strerror(errno) + ")");
  if (S_ISDIR(st.st_mode)) throw Error(Error::Kind::io, name + ": is a directory");
  if (!S_ISREG(st.st_mode) && !S_ISFIFO(st.st_mode))
    throw Error(Error::Kind::io, name + ": not a regular file (a device or socket)");
  const auto over = [&] {
    return Error(Error::Kind::io, name + ": longer than " + std::to_string(limit >> 20) +
                                      " MiB, the limit for an input file");
  };
  if (S_ISREG(st.st_mode) && static_cast<uint64_t>(st.st_size) > limit) throw over();
  // Blocking reads from here on (O_NONBLOCK only kept a FIFO without a writer from blocking open).
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  std::string out;
  if (S_ISREG(st.st_mode)) out.reserve(static_cast<std::size_t>(st.st_size));
  char buf[1 << 16];
  while (true) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw Error(Error::Kind::io, name + ": read error (" + std::strerror(errno) + ")");
    }
    if (n == 0) break;
    if (out.size() + static_cast<std::size_t>(n) > limit) throw over();
    out.append(buf, static_cast<std::size_t>(n));
  }
  return out;
}

}  // namespace crowddb
