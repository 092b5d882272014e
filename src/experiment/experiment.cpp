#include "experiment/experiment.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "crowddb/error.hpp"

namespace crowddb::experiment {

const Experiment& find(std::string_view name) {
  for (const auto& e : registry())
    if (e.name == name) return e;
  std::string names;
  for (const auto& e : registry()) names += (names.empty() ? "" : ", ") + e.name;
  throw Error(Error::Kind::usage,
              "unknown experiment '" + std::string(name) + "' (choose from " + names + ")");
}

CsvWriter::CsvWriter(const std::filesystem::path& path, std::span<const std::string> header)
    : path_(path), out_(path) {
  if (!out_) throw Error(Error::Kind::io, path.string() + ": cannot open for writing");
  row(header);
}

void CsvWriter::row(std::span<const double> values) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    char buf[32];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, values[i]);
    out_ << (i ? "," : "") << std::string_view(buf, static_cast<std::size_t>(end - buf));
  }
  out_ << '\n';
}

void CsvWriter::row(std::span<const std::string> cells) {
  for (std::size_t i = 0; i < cells.size(); ++i) out_ << (i ? "," : "") << cells[i];
  out_ << '\n';
}

void CsvWriter::close() {
  out_.close();
  if (!out_) throw Error(Error::Kind::io, path_.string() + ": write failed");
}

void plot(const std::filesystem::path& out_dir, const std::string& name,
          const std::string& script) {
  const auto gp = out_dir / (name + ".gp");
  {
    std::ofstream f(gp);
    f << script;
    if (!f) throw Error(Error::Kind::io, gp.string() + ": cannot write");
  }
  const std::string cmd =
      "cd '" + out_dir.string() + "' && gnuplot '" + gp.filename().string() + "' 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) throw Error(Error::Kind::io, "cannot run gnuplot");
  std::string output;
  char buf[256];
  while (fgets(buf, sizeof buf, p)) output += buf;
  const int status = pclose(p);
  if (status != 0)
    throw Error(Error::Kind::io,
                "gnuplot failed on " + gp.string() + ": " + output.substr(0, output.find('\n')));
}

MeanSd mean_sd(std::span<const double> v) {
  MeanSd r;
  if (v.empty()) return r;
  double s = 0;
  for (double x : v) s += x;
  r.mean = s / static_cast<double>(v.size());
  if (v.size() > 1) {
    double q = 0;
    for (double x : v) q += (x - r.mean) * (x - r.mean);
    r.sd = std::sqrt(q / static_cast<double>(v.size() - 1));
  }
  return r;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : (v[m - 1] + v[m]) / 2;
}

std::string machine_note(int threads) {
  std::string cpu = "unknown CPU";
  if (FILE* f = std::fopen("/proc/cpuinfo", "r")) {
    char line[512];
    while (std::fgets(line, sizeof line, f)) {
      std::string s(line);
      if (s.rfind("model name", 0) == 0) {
        cpu = s.substr(s.find(':') + 2);
        if (!cpu.empty() && cpu.back() == '\n') cpu.pop_back();
        break;
      }
    }
    std::fclose(f);
  }
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) < 0) load[0] = -1;
  std::ostringstream os;
  os << cpu << "; load " << load[0] << " " << load[1] << " " << load[2] << "; threads " << threads
#ifdef NDEBUG
     << "; release build"
#else
     << "; debug build (asserts on)"
#endif
#ifdef __OPTIMIZE__
     << " optimised"
#endif
      ;
  return os.str();
}

}  // namespace crowddb::experiment
