// Shared by the sdf tests: compact graph construction and running the sdfsched binary.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "sdf/graph.hpp"

namespace sdf::test {

struct Edge {
  const char* src;
  const char* dst;
  uint64_t prd, cns, delay;
};

// Actors named in `actors` order; channels named src->dst#k.
inline Graph make(std::vector<const char*> actors, std::vector<Edge> edges) {
  Graph g;
  for (const char* a : actors) g.add_actor(a);
  for (const Edge& e : edges)
    g.add_channel(*g.find_actor(e.src), *g.find_actor(e.dst), e.prd, e.cns, e.delay);
  return g;
}

// `g` with execution times `times`, one per actor in actor order.
inline Graph timed(Graph g, std::vector<uint64_t> times) {
  for (ActorId a = 0; a < g.actor_count(); ++a) g.set_actor_time(a, times[a]);
  return g;
}

inline std::string data(const std::string& name) {
  return std::string(SDF_DATA_DIR) + "/" + name;
}

// A file name in the test temp directory, unique to this process (ctest runs tests in parallel).
inline std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "sdf_" + std::to_string(::getpid()) + "_" + name;
}

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Cli {
  int status = -1;
  std::string out, err;
};

// Runs `sdfsched ARGS` (ARGS already shell-quoted), capturing stdout, stderr and the exit status.
inline Cli sdfsched(const std::string& args) {
  static int counter = 0;
  const std::string err_file = ::testing::TempDir() + "sdfsched_err_" + std::to_string(::getpid()) +
                               "_" + std::to_string(counter++);
  const std::string cmd = std::string(SDFSCHED) + " " + args + " 2>" + err_file;
  Cli r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int st = ::pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.err = slurp(err_file);
  std::remove(err_file.c_str());
  return r;
}

}  // namespace sdf::test
