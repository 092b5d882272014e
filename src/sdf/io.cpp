#include "sdf/io.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <functional>

#include "json_detail.hpp"

namespace sdf {

namespace {

constexpr uint64_t kMaxGraphBytes = uint64_t{1} << 30;  // 1 GiB

bool ends_with(const std::string& s, const char* suffix) {
  const size_t n = std::strlen(suffix);
  return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

// release: for a mapped file, drops the pages before an offset (see read_sdf3_released).
Graph parse_graph_text(std::string_view text, const std::string& path,
                       const std::function<void(size_t)>* release = nullptr) {
  if (ends_with(path, ".xml"))
    return release ? detail::read_sdf3_released(text, path, *release) : read_sdf3(text, path);
  auto json = [&] {
    return release ? detail::read_json_released(text, path, *release) : read_json(text, path);
  };
  if (ends_with(path, ".json")) return json();
  for (char c : text) {
    if (c == '<')
      return release ? detail::read_sdf3_released(text, path, *release) : read_sdf3(text, path);
    if (c == '{') return json();
    if (c != ' ' && c != '\t' && c != '\r' && c != '\n') break;
  }
  throw Error(Error::Kind::input,
              path + ":1: not a graph file (expected SDF3 XML or the JSON form, .xml or .json)");
}

}  // namespace

Graph read_graph_file(const std::string& path) {
  // A regular file is mapped rather than copied into a string (a 100 MB file costs a copy and
  // the page faults of a fresh buffer otherwise); a pipe is read. Devices (/dev/zero), sockets
  // and directories are refused, and nothing longer than kMaxGraphBytes is read.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw Error(Error::Kind::io, path + ": cannot open (" + std::strerror(errno) + ")");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    throw Error(Error::Kind::io, path + ": cannot read (" + std::strerror(errno) + ")");
  if (S_ISDIR(st.st_mode)) throw Error(Error::Kind::io, path + ": is a directory");
  if (!S_ISREG(st.st_mode) && !S_ISFIFO(st.st_mode))
    throw Error(Error::Kind::io, path + ": not a regular file (a device or socket)");
  const auto too_long = [&] {
    return Error(Error::Kind::io, path + ": longer than " + std::to_string(kMaxGraphBytes >> 20) +
                                      " MiB, the limit for a graph file");
  };
  if (S_ISREG(st.st_mode) && static_cast<uint64_t>(st.st_size) > kMaxGraphBytes) throw too_long();
  if (S_ISREG(st.st_mode) && st.st_size > 0) {
    const auto size = static_cast<size_t>(st.st_size);
    // Faulted in as the streaming readers go; they drop what they have passed.
    void* p = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p == MAP_FAILED)
      throw Error(Error::Kind::io, path + ": cannot map (" + std::strerror(errno) + ")");
    struct Unmap {
      void* p;
      size_t size;
      ~Unmap() { ::munmap(p, size); }
    } unmap{p, size};
    // The readers stream: the pages they have passed are dropped (they are read back from the
    // page cache if one looks again), so RSS holds the graph, not the file beside it.
    ::madvise(p, size, MADV_SEQUENTIAL);
    const std::function<void(size_t)> release = [&](size_t offset) {
      const auto page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
      const size_t end = offset / page * page;
      if (end > 0) ::madvise(p, end, MADV_DONTNEED);
    };
    return parse_graph_text(std::string_view(static_cast<const char*>(p), size), path, &release);
  }
  std::string text;
  char buf[1 << 16];
  while (true) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(Error::Kind::io, path + ": read error (" + std::strerror(errno) + ")");
    if (n == 0) break;
    if (text.size() + static_cast<size_t>(n) > kMaxGraphBytes) throw too_long();
    text.append(buf, static_cast<size_t>(n));
  }
  return parse_graph_text(std::move(text), path);
}

std::string write_dot(const Graph& g) {
  std::string out = "digraph " + quoted(g.name.empty() ? "sdf" : g.name) + " {\n";
  for (ActorId a = 0; a < g.actor_count(); ++a) out += "  " + quoted(g.actor_name(a)) + ";\n";
  for (ChannelId id = 0; id < g.channel_count(); ++id) {
    const Channel& c = g.channel(id);
    std::string label = std::to_string(c.prd) + ":" + std::to_string(c.cns);
    if (c.delay != 0) label += " (" + std::to_string(c.delay) + ")";
    out += "  " + quoted(g.actor_name(c.src)) + " -> " + quoted(g.actor_name(c.dst)) +
           " [label=" + quoted(label) + ", tooltip=" + quoted(std::string(g.channel_name(id))) +
           "];\n";
  }
  return out + "}\n";
}

}  // namespace sdf
