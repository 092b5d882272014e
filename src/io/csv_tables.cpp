// CSV structure (header mapping, column counts, line numbers) comes from fast-cpp-csv-parser
// (Debian libfccp-dev); numbers are parsed with std::from_chars, which rounds correctly (the
// library's own float parser does not) and lets us reject NaN and infinities by name.
#define CSV_IO_NO_THREAD
// The library's bounded file-name copy trips -Wstringop-truncation where it is inlined.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wstringop-truncation"
#endif
#include "io/csv_tables.hpp"

#include <libfccp/csv.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>
#include <unordered_set>

#include "crowddb/error.hpp"
#include "util/plain_number.hpp"
#include "util/read_file.hpp"

namespace crowddb::io {
namespace {

std::string where(const std::string& path, unsigned line, const char* field) {
  return path + ":" + std::to_string(line) + ": field " + field;
}

std::string read_file(const std::filesystem::path& path) {
  return read_input_file(path);
}

// One-line message of a library error, without its trailing period.
[[noreturn]] void rethrow_csv(const std::string& path, const std::exception& e) {
  std::string msg = e.what();
  while (!msg.empty() && (msg.back() == '.' || msg.back() == '\n')) msg.pop_back();
  for (char& c : msg)
    if (c == '\n' || c == '\r') c = ' ';
  throw Error(Error::Kind::input, path + ": " + msg);
}

template <class Reader>
void require_columns(Reader& in, const std::string& path,
                     std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (!in.has_column(n))
      throw Error(Error::Kind::input, path + ": missing column '" + n + "' in the header");
}

// The CSV library reads fields as C strings, so a NUL byte would silently cut a field short
// ("1\0junk" reads as 1): refuse the file, naming the line.
void reject_nul(std::string_view text, const std::string& path) {
  const std::size_t at = text.find('\0');
  if (at == std::string_view::npos) return;
  const auto line =
      1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  throw Error(Error::Kind::input,
              path + ":" + std::to_string(line) + ": contains a NUL byte (not a text file?)");
}

// A number within [-limit, limit]: the ranges of crowddb/query.hpp, said with file and line.
double parse_bounded(const char* text, const std::string& at, double limit) {
  const double v = parse_number(text, at);
  if (std::abs(v) > limit)
    throw Error(Error::Kind::input,
                at + ": must lie within +-" + plain_number(limit) + " (got " + text + ")");
  return v;
}

}  // namespace

double parse_number(const char* text, const std::string& at) {
  if (!text) throw Error(Error::Kind::input, at + ": missing value");
  const char* end = text + std::strlen(text);
  const char* begin = text;
  if (begin != end && *begin == '+') ++begin;  // from_chars rejects a leading '+'
  double v = 0;
  auto [ptr, ec] = std::from_chars(begin, end, v);
  if (begin == end || ec != std::errc() || ptr != end)
    throw Error(Error::Kind::input, at + ": '" + std::string(text) + "' is not a number");
  if (!std::isfinite(v))
    throw Error(Error::Kind::input, at + ": must be finite (got " + std::string(text) + ")");
  return v;
}

DiscTable read_agents_csv(const std::filesystem::path& path) {
  return parse_agents_csv(read_file(path), path.string());
}

std::vector<CircleObstacle> read_obstacles_csv(const std::filesystem::path& path) {
  return parse_obstacles_csv(read_file(path), path.string());
}

DiscTable parse_agents_csv(std::string_view text, const std::string& path) {
  reject_nul(text, path);
  DiscTable t;
  try {
    ::io::CSVReader<7, ::io::trim_chars<' ', '\t'>, ::io::no_quote_escape<','>> in(
        path, text.data(), text.data() + text.size());
    in.read_header(::io::ignore_missing_column, "id", "x", "y", "vx", "vy", "radius", "charge");
    require_columns(in, path, {"id", "x", "y", "vx", "vy", "radius"});
    const bool has_charge = in.has_column("charge");
    std::unordered_set<uint64_t> seen;
    char *id = nullptr, *x = nullptr, *y = nullptr, *vx = nullptr, *vy = nullptr, *r = nullptr,
         *c = nullptr;
    while (in.read_row(id, x, y, vx, vy, r, c)) {
      const unsigned line = in.get_file_line();
      uint64_t idv = 0;
      const char* idend = id + std::strlen(id);
      auto [p, ec] = std::from_chars(id, idend, idv);
      if (id == idend || ec != std::errc() || p != idend)
        throw Error(Error::Kind::input,
                    where(path, line, "id") + ": '" + id + "' is not a non-negative integer");
      if (!seen.insert(idv).second)
        throw Error(Error::Kind::input,
                    where(path, line, "id") + ": duplicate id " + std::to_string(idv));
      const double px = parse_bounded(x, where(path, line, "x"), kMaxCoordinate);
      const double py = parse_bounded(y, where(path, line, "y"), kMaxCoordinate);
      const double pvx = parse_bounded(vx, where(path, line, "vx"), kMaxQuerySpeed);
      const double pvy = parse_bounded(vy, where(path, line, "vy"), kMaxQuerySpeed);
      const double pr = parse_bounded(r, where(path, line, "radius"), kMaxCoordinate);
      if (!(pr > 0))
        throw Error(Error::Kind::input,
                    where(path, line, "radius") + ": must be > 0 (got " + r + ")");
      const double pc =
          has_charge ? parse_bounded(c, where(path, line, "charge"), kMaxCoordinate) : 1.0;
      t.push_back(idv, px, py, pvx, pvy, pr, pc);
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    rethrow_csv(path, e);
  }
  return t;
}

std::vector<CircleObstacle> parse_obstacles_csv(std::string_view text, const std::string& path) {
  reject_nul(text, path);
  std::vector<CircleObstacle> out;
  try {
    ::io::CSVReader<4, ::io::trim_chars<' ', '\t'>, ::io::no_quote_escape<','>> in(
        path, text.data(), text.data() + text.size());
    in.read_header(::io::ignore_missing_column, "x", "y", "radius", "charge");
    require_columns(in, path, {"x", "y", "radius"});
    const bool has_charge = in.has_column("charge");
    char *x = nullptr, *y = nullptr, *r = nullptr, *c = nullptr;
    while (in.read_row(x, y, r, c)) {
      const unsigned line = in.get_file_line();
      CircleObstacle o;
      o.x = parse_bounded(x, where(path, line, "x"), kMaxCoordinate);
      o.y = parse_bounded(y, where(path, line, "y"), kMaxCoordinate);
      o.radius = parse_bounded(r, where(path, line, "radius"), kMaxCoordinate);
      if (!(o.radius > 0))
        throw Error(Error::Kind::input,
                    where(path, line, "radius") + ": must be > 0 (got " + r + ")");
      o.charge = has_charge ? parse_bounded(c, where(path, line, "charge"), kMaxCoordinate) : 1.0;
      out.push_back(o);
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    rethrow_csv(path, e);
  }
  return out;
}

}  // namespace crowddb::io
