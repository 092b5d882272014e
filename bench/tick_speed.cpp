// The whole tick's speed on named scenarios, per steering model and thread count: median and
// minimum ms per tick, agent-ticks per second, the tick's drift over the run (median of the first
// and of the last tenth of the ticks), peak resident memory, the machine's load, and the final
// state hash (which must not depend on the thread count; a difference fails the run). Before
// each run, column "2cpu": what two CPUs at once get done against one on a kernel in the level-1
// cache (two_cpu_throughput): near 2 on cores of their own, near 1 where the VM's two CPUs are
// one core's two hardware threads, which the host may switch between from one minute to the
// next (seen here on 2026-12-04: two processes copying 16 KB took 0.055 s each at once against
// 0.026 alone at 00:58, 0.026 each at 01:10), and a tick cannot then gain near 2 from a second
// thread. Column "cpus": each CPU's speed at the tick itself, against the fastest (cpu_speeds:
// one CPU can run the tick a quarter slower than the other for minutes while "2cpu" reads 2).
// One-thread runs are pinned to the fastest CPU (column "pin"; `--pin no` leaves them to the
// scheduler, which put them on either and so made the one-thread figure, and every speed-up,
// swing by that quarter), and `--rounds` also gives each speed-up against what the CPUs could
// do: the sum of the speeds of as many CPUs as threads.
//
// Each case runs in a child process of its own, so that its peak memory is its own
// (getrusage of the child) and one case's allocations do not slow the next. `--fork no` runs
// them in this process instead, for profilers that do not follow a fork (heaptrack, perf); the
// peak memory printed is then the process's so far.
//
//   build/bench/tick_speed                          # every case but airport-1m and -10m
//   build/bench/tick_speed --cases airport-20k --models orca --threads 1,2 --ticks 100
//   build/bench/tick_speed --cases all --csv docs/bench/tick_speed.csv   # all but airport-10m
//   build/bench/tick_speed --cases airport-10m --models orca --threads 2   # ~9 GB, minutes
//   build/bench/tick_speed --cases airport-20k --models orca --threads 1,2 --rounds 6
//   build/bench/tick_speed --print airport-20k --threads 1 > a20k.json  # the case, for crowddb run
//   build/bench/tick_speed --cases airport-20k --models orca --rounds 3 --busy-cpu 0
//
// `--busy-cpu K` keeps CPU K busy for the whole run with a loop of another process pinned there
// (CSV column busy_cpu), the way other work on the machine would: is two threads' tick still no
// slower than one thread's (issue "Five times RVO2")? The CPU probe then reads K slow, so with
// `--pin yes` the one-thread runs go to another CPU; "2cpu" reads about 1 throughout (one of
// the two CPUs is taken), which then says nothing about whether they share a core.
//
// `--rounds N` runs every case N times, the thread counts in turn forwards and backwards (1 2,
// 2 1, 1 2, ...), and ends with a summary per case, model and thread count: the median, least
// and greatest of the rounds' medians, and the speed-up over the first thread count taken
// within each round (pairs run minutes apart compare the host's states, not the code). On a
// shared machine whose speed swings from run to run, one pair of runs can put the speed-up
// anywhere between 1.6 and 2.0 (docs/benchmarks.md).
//
// Cases (docs/benchmarks.md): airport-1k/20k/100k/1m are the agents of bench/rvo2_side_by_side
// (uniform at 0.5 people/m^2 in a walled square, radius 0.25 m, 1.3 m/s, four goals on the
// walls, round robin, dt 0.1 s), so their figures compare with RVO2's; ring-1k is 1,000 people
// on a circle of radius 100 m swapping with the point opposite (RVO2's Circle in metres);
// bottleneck-2k empties a 40 x 40 m room of 2,000 people through a 2.4 m door (navigation on);
// hall-100k walks 10^5 people to the middle of a round hall of radius 480 m drawn as a walkable
// area of 20,000 vertices (its blocked pieces are polygons of that many edges: the polygon tests
// through edge grids).
//
// Models: any registered steering model, or a benchmark variant (bench/model_variant.hpp):
// `--models orca,orca-core` puts the default orca beside itself without keeping to a side, the
// stream gap and the perturbation, which is what those three cost.
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "airport_scenario.hpp"
#include "bench_args.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "model_variant.hpp"
#include "util/rng.hpp"

using namespace crowddb;
using Clock = std::chrono::steady_clock;

namespace {

struct Case {
  const char* name;
  uint64_t ticks;  // default ticks per run
  std::string (*doc)(const std::string& model, int threads);
  // > 0: the document's agents are replaced by this many inserted through World::insert (the
  // airport at 10^7, past the scenario files' cap of 2 * 10^6 agents).
  std::size_t inserted = 0;
};

// The airport's people at 0.5 /m^2 on a jittered square lattice over the whole square: cells
// side/ceil(sqrt(n)) ~ 1.41 m wide, each person moved uniformly up to 0.44 m in x and y from
// its cell's centre (so never closer than 0.02 m to another, nor than 0.01 m to a wall), goals
// round robin and every other field as the document's one agent has them. The document's
// uniform placement draws each position against the ones placed so far; at 10^7 agents this
// lattice is the quick way to the same density.
void insert_lattice(World& w, std::size_t n) {
  const AgentTable& t = w.agents();
  AgentSpec spec;
  spec.radius = t.radius[0];
  spec.pref_speed = t.pref_speed[0];
  spec.max_speed = t.max_speed[0];
  spec.max_accel = t.max_accel[0];
  spec.charge = t.charge[0];
  w.erase(AgentId::from_value(t.id[0]));
  const double side = w.bounds().width();
  const auto per_row = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  const double cell = side / static_cast<double>(per_row);
  const double jitter = cell / 2 - spec.radius - 0.01;
  uint64_t state = 3;
  auto uniform = [&] {  // in [-1, 1)
    return static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-52 - 1;
  };
  const auto goals = static_cast<uint32_t>(w.goals().size());
  for (std::size_t k = 0; k < n; ++k) {
    spec.x = (static_cast<double>(k % per_row) + 0.5) * cell + jitter * uniform();
    spec.y = (static_cast<double>(k / per_row) + 0.5) * cell + jitter * uniform();
    spec.goal = static_cast<uint32_t>(k % goals);
    w.insert(spec);
  }
  w.apply_pending();
}

std::string airport(std::size_t agents, const std::string& model, int threads) {
  return bench::airport_scenario(agents, model, threads);
}

std::string ring(const std::string& model, int threads) {
  char doc[1024];
  std::snprintf(doc, sizeof doc, R"({"bounds": [-110, -110, 110, 110], "dt": 0.1, "seed": 7,
    "threads": %d, "steering": {"model": "%s"}, "arrival": "idle",
    "groups": [{"count": 1000, "placement": {"type": "circle", "center": [0, 0], "radius": 100},
                "radius": 0.25, "pref_speed": 1.34,
                "goals": {"assign": "antipodal", "arrival_radius": 0.3}}]})",
                threads, model.c_str());
  return doc;
}

std::string bottleneck(const std::string& model, int threads) {
  char doc[1536];
  std::snprintf(doc, sizeof doc, R"({"bounds": [0, 0, 50, 40], "dt": 0.1, "seed": 11,
    "threads": %d, "steering": {"model": "%s"}, "arrival": "remove", "navigation": {},
    "obstacles": [{"type": "polygon", "vertices": [[40, 0], [40.3, 0], [40.3, 18.8], [40, 18.8]]},
                  {"type": "polygon", "vertices": [[40, 21.2], [40.3, 21.2], [40.3, 40], [40, 40]]}],
    "goals": [{"name": "out", "area": [[48, 0], [50, 0], [50, 40], [48, 40]]}],
    "groups": [{"count": 2000, "placement": {"type": "uniform", "region": [0.3, 0.3, 39.7, 39.7],
                "gap": 0.05}, "radius": [0.2, 0.25], "pref_speed": [1.1, 1.5], "goal": "out"}]})",
                threads, model.c_str());
  return doc;
}

std::string hall(const std::string& model, int threads) {
  constexpr int kVertices = 20000;
  std::string ring;
  for (int k = 0; k <= kVertices; ++k) {  // closed: the last vertex is the first
    const double a = 2 * 3.14159265358979323846 * (k % kVertices) / kVertices;
    char v[64];
    std::snprintf(v, sizeof v, "%s%.6f %.6f", k ? "," : "", 500 + 480 * std::cos(a),
                  500 + 480 * std::sin(a));
    ring += v;
  }
  char doc[1024];
  std::snprintf(doc, sizeof doc, R"json({"bounds": [0, 0, 1000, 1000], "dt": 0.1, "seed": 5,
    "threads": %d, "steering": {"model": "%s"}, "goals": [{"name": "g", "x": 500, "y": 500}],
    "groups": [{"count": 100000, "placement": {"type": "uniform", "region": [200, 200, 800, 800]},
                "radius": 0.25, "goals": {"assign": "round_robin"}}],
    "walkable": "POLYGON((RING))"})json",
                threads, model.c_str());
  std::string out = doc;
  out.replace(out.find("RING"), 4, ring);
  return out;
}

const Case kCases[] = {
    {"airport-1k", 200, [](const std::string& m, int t) { return airport(1000, m, t); }},
    {"airport-20k", 100, [](const std::string& m, int t) { return airport(20000, m, t); }},
    {"airport-100k", 30, [](const std::string& m, int t) { return airport(100000, m, t); }},
    {"airport-1m", 8, [](const std::string& m, int t) { return airport(1000000, m, t); }},
    {"airport-10m", 3,
     [](const std::string& m, int t) { return bench::airport_scenario(10000000, m, t, 0.5, 1); },
     10000000},
    {"ring-1k", 1200, ring},
    {"bottleneck-2k", 600, bottleneck},
    {"hall-100k", 10, hall},
};

// The case of that name, or nullptr.
const Case* find_case(const std::string& name) {
  for (const Case& c : kCases)
    if (name == c.name) return &c;
  return nullptr;
}

// What a child sends back through its pipe.
struct Result {
  uint64_t ticks = 0;
  double agents = 0;  // mean rows per tick
  double median_ms = 0, min_ms = 0, first_ms = 0, last_ms = 0, seconds = 0;
  uint64_t hash = 0;
  int cpu = -1;  // the CPU the run was pinned to, -1: none (not asked, or refused)
  char error[256] = {};
};

double load_average() {
  std::ifstream f("/proc/loadavg");
  double l = -1;
  f >> l;
  return l;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Two copies of a kernel that lives in the level-1 cache (16 KB copied back and forth), run at
// once, against one alone: how many times one copy's work the pair gets done in the same time.
// About 2 when the two CPUs are cores of their own; about 1 when they are the two hardware
// threads of one core, which a VM need not show (its lscpu may say one thread per core). A
// two-thread speed-up of the tick can then not pass this figure by much. Each run lasts ~30 ms
// and the pair starts together once both threads spin: an idle virtual CPU can take
// milliseconds to wake, and a 2.5 ms kernel measured 1.0 on two free cores. The median of 3.
double two_cpu_throughput() {
  constexpr std::size_t kBytes = 16 * 1024;
  const auto kernel = [](long reps) {
    std::vector<char> a(kBytes, 1), b(kBytes, 2);
    for (long r = 0; r < reps; ++r) {
      std::memcpy(r % 2 ? a.data() : b.data(), r % 2 ? b.data() : a.data(), kBytes);
      a[static_cast<std::size_t>(r) % kBytes] ^= static_cast<char>(r);
    }
    volatile char sink = a[7] ^ b[11];  // the copies are used
    (void)sink;
  };
  const auto seconds = [](auto&& f) {
    const auto t0 = Clock::now();
    f();
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  // Repetitions for ~30 ms alone.
  long reps = 1000;
  for (double t = seconds([&] { kernel(reps); }); t < 0.03; t = seconds([&] { kernel(reps); }))
    reps = static_cast<long>(static_cast<double>(reps) * std::min(10.0, 0.032 / std::max(t, 1e-6)));
  std::vector<double> ratios;
  for (int k = 0; k < 3; ++k) {
    const double alone = seconds([&] { kernel(reps); });
    std::atomic<int> ready{0};
    std::atomic<bool> go{false};
    std::thread other([&] {
      ready.fetch_add(1);
      while (!go.load()) {
      }
      kernel(reps);
    });
    while (ready.load() < 1) {
    }
    // (The other thread spins by now: its CPU is awake.)
    const double pair = seconds([&] {
      go.store(true);
      kernel(reps);
      other.join();
    });
    ratios.push_back(2 * alone / pair);
  }
  return median(ratios);
}

// Each CPU this process may run on, and how fast it runs the tick now against the fastest: the
// host can give one of a VM's CPUs less than the other for minutes at a time. Seen here on
// 2026-12-06: `crowddb run` of airport-20k, one thread, pinned by taskset, took 1,597-1,647 ms on
// CPU 0 and 1,261-1,272 ms on CPU 1 for 100 ticks (four runs each), and two such runs at once, one
// on each, 1,751 and 1,266; ten minutes later 1,255 and 1,303. A 16 KB copy in the level-1 cache
// and a random walk over 1-64 MB ran alike on both meanwhile, so "2cpu" above does not see it: this
// probe runs the tick itself. A two-thread tick then gets at most the sum of its CPUs' speeds over
// one thread on the fastest (1.79 with 0.79), however well its work is shared; the summary gives
// the speed-ups against that sum as well. The probe: airport-20k under orca on one thread, two
// ticks to warm up, then eight turns of two ticks pinned to each CPU in turn (the same crowd for
// all), each CPU's median; about 0.6 s (with four turns equal CPUs read 0.91-1.00). It runs in a
// child process of its own: the crowd's memory, kept by the heap after it is freed, would
// otherwise be counted in the peak of every case forked after it.
struct CpuSpeeds {
  std::vector<int> cpu;       // the CPUs this process may run on
  std::vector<double> speed;  // of each: the fastest's median ms over its own, so 1 for the fastest
  int fastest = -1;           // -1: the affinity could not be read or set (nothing pinned)
  // "1.00/0.79": the speeds in CPU order.
  std::string text() const {
    std::string t;
    for (double v : speed) {
      char b[16];
      std::snprintf(b, sizeof b, "%s%.2f", t.empty() ? "" : "/", v);
      t += b;
    }
    return t.empty() ? "-" : t;
  }
  // The sum of the `threads` largest speeds: what `threads` threads can get done against one on
  // the fastest CPU.
  double capacity(int threads) const {
    std::vector<double> v = speed;
    std::sort(v.rbegin(), v.rend());
    double c = 0;
    for (std::size_t k = 0; k < v.size() && k < static_cast<std::size_t>(threads); ++k) c += v[k];
    return c;
  }
};

bool pin_to(const cpu_set_t& set) {
  return sched_setaffinity(0, sizeof set, &set) == 0;
}

bool pin_to(int cpu) {
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(cpu, &one);
  return pin_to(one);
}

// A process spinning on one CPU while it lives (--busy-cpu); it dies with this one. started():
// it has pinned itself to that CPU (it says so through a pipe; end of file: it could not).
class BusyLoop {
 public:
  explicit BusyLoop(int cpu) {
    int ready[2];
    if (pipe(ready) != 0) return;
    std::fflush(nullptr);  // (nothing buffered can be written twice)
    owner_ = getpid();
    pid_ = fork();
    if (pid_ == 0) {
      close(ready[0]);
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (getppid() != owner_ || !pin_to(cpu)) _exit(1);  // (the parent gone already, or no pin)
      const char yes = 1;
      if (write(ready[1], &yes, 1) != 1) _exit(1);
      close(ready[1]);
      volatile uint64_t spins = 0;
      for (;;) spins = spins + 1;
    }
    close(ready[1]);
    char got = 0;
    ssize_t r;
    while ((r = read(ready[0], &got, 1)) < 0 && errno == EINTR) {
    }
    close(ready[0]);
    started_ = pid_ > 0 && r == 1;
    if (pid_ > 0 && !started_) {  // it has exited, or is about to: reap it, never kill a reused pid
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }
  ~BusyLoop() {
    // (Only its owner ends it: not a case's child process that leaves main by an exception.)
    if (pid_ <= 0 || getpid() != owner_) return;
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  BusyLoop(const BusyLoop&) = delete;
  BusyLoop& operator=(const BusyLoop&) = delete;
  bool started() const { return started_; }

 private:
  pid_t pid_ = -1, owner_ = -1;
  bool started_ = false;
};

// The probe itself, in the calling process (it pins the calling thread and leaves it pinned).
CpuSpeeds cpu_speeds_here() {
  CpuSpeeds s;
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return s;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &allowed)) s.cpu.push_back(c);
  if (s.cpu.size() < 2) {
    s.speed.assign(s.cpu.size(), 1.0);
    s.fastest = s.cpu.empty() ? -1 : s.cpu.front();
    return s;
  }
  std::vector<std::vector<double>> ms(s.cpu.size());
  bool pinned = true;
  try {
    Scenario sc = parse_scenario(airport(20000, "orca", 1), "cpu probe");
    Simulation sim(std::move(sc.world), sc.config);
    sim.step();
    sim.step();
    for (int turn = 0; turn < 8 && pinned; ++turn)
      for (std::size_t k = 0; k < s.cpu.size() && pinned; ++k) {
        pinned = pin_to(s.cpu[k]);
        for (int t = 0; t < 2 && pinned; ++t) {
          const auto a = Clock::now();
          sim.step();
          ms[k].push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
        }
      }
  } catch (const std::exception&) {
    pinned = false;
  }
  if (!pinned) return CpuSpeeds{s.cpu, {}, -1};
  std::vector<double> med;
  for (const auto& m : ms) med.push_back(median(m));
  const auto best = std::min_element(med.begin(), med.end());
  s.fastest = s.cpu[static_cast<std::size_t>(best - med.begin())];
  for (double m : med) s.speed.push_back(*best / m);
  return s;
}

// Runs f() in a child process of its own and puts its answer (trivially copyable) in `out`,
// through a pipe; `ru` gets the child's resource use. False when the pipe or the fork failed or
// the child died before answering.
template <class T, class F>
bool in_child(F&& f, T& out, rusage* ru = nullptr) {
  static_assert(std::is_trivially_copyable_v<T>);
  int fd[2];
  if (pipe(fd) != 0) return false;
  const pid_t pid = fork();
  if (pid < 0) {
    close(fd[0]);
    close(fd[1]);
    return false;
  }
  if (pid == 0) {
    close(fd[0]);
    const T answer = f();
    const ssize_t w = write(fd[1], &answer, sizeof answer);
    _exit(w == static_cast<ssize_t>(sizeof answer) ? 0 : 1);
  }
  close(fd[1]);
  const bool got = read(fd[0], &out, sizeof out) == static_cast<ssize_t>(sizeof out);
  close(fd[0]);
  int wstatus = 0;
  rusage ignored{};
  wait4(pid, &wstatus, 0, ru ? ru : &ignored);
  return got;
}

// cpu_speeds_here in a child process (empty speeds: none).
CpuSpeeds cpu_speeds() {
  struct Sent {
    int n = 0, fastest = -1;
    int cpu[64] = {};
    double speed[64] = {};
  };
  Sent in;
  const bool got = in_child(
      [] {
        const CpuSpeeds here = cpu_speeds_here();
        Sent out;
        out.fastest = here.fastest;
        for (std::size_t k = 0; k < here.speed.size() && k < 64; ++k) {
          out.cpu[k] = here.cpu[k];
          out.speed[k] = here.speed[k];
          out.n = static_cast<int>(k + 1);
        }
        return out;
      },
      in);
  CpuSpeeds s;
  if (!got) return s;
  for (int k = 0; k < in.n; ++k) {
    s.cpu.push_back(in.cpu[k]);
    s.speed.push_back(in.speed[k]);
  }
  s.fastest = in.n > 0 ? in.fastest : -1;
  return s;
}

Result run_case(const Case& c, const std::string& model, int threads, uint64_t ticks) {
  Result r;
  try {
    Scenario sc = parse_scenario(c.doc(bench::engine_model(model), threads), c.name);
    bench::apply_variant(model, sc.config);
    if (c.inserted > 0) insert_lattice(sc.world, c.inserted);
    Simulation sim(std::move(sc.world), sc.config);
    std::vector<double> ms;
    double rows = 0;
    for (uint64_t k = 0; k < ticks; ++k) {
      rows += static_cast<double>(sim.world().agents().size());
      const auto a = Clock::now();
      r.hash = sim.step().state_hash;
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
    }
    const std::size_t tenth = std::max<std::size_t>(1, ms.size() / 10);
    r.ticks = ms.size();
    r.agents = rows / static_cast<double>(ms.size());
    r.median_ms = median(ms);
    r.min_ms = *std::min_element(ms.begin(), ms.end());
    r.first_ms = median({ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(tenth)});
    r.last_ms = median({ms.end() - static_cast<std::ptrdiff_t>(tenth), ms.end()});
    for (double v : ms) r.seconds += v / 1e3;
  } catch (const std::exception& e) {
    std::snprintf(r.error, sizeof r.error, "%s", e.what());
  }
  return r;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::size_t a = 0;
  while (a <= s.size()) {
    const std::size_t b = std::min(s.find(',', a), s.size());
    if (b > a) out.push_back(s.substr(a, b - a));
    a = b + 1;
  }
  return out;
}

// The median, least and greatest of v (not empty).
struct Spread {
  double median, least, greatest;
};
Spread spread(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size();
  return {m % 2 ? v[m / 2] : (v[m / 2 - 1] + v[m / 2]) / 2, v.front(), v.back()};
}

// After several rounds: per case/model and thread count the spread of the rounds' medians, and
// the speed-up over the first thread count within each round that ran both.
void print_summary(const std::map<std::string, std::vector<std::map<int, double>>>& medians,
                   const std::map<std::string, std::vector<std::map<int, double>>>& capacities,
                   const std::vector<int>& thread_counts, int rounds) {
  std::printf(
      "\nover %d rounds (ms per tick: median of the rounds' medians, least - greatest; "
      "speed-up over %d thread%s within each round)\n",
      rounds, thread_counts.front(), thread_counts.front() == 1 ? "" : "s");
  for (const auto& [key, per_round] : medians) {
    for (int threads : thread_counts) {
      std::vector<double> ms, ratio, of_capacity;
      const auto caps = capacities.find(key);
      for (std::size_t r = 0; r < per_round.size(); ++r) {
        const auto& round = per_round[r];
        const auto it = round.find(threads);
        if (it == round.end()) continue;
        ms.push_back(it->second);
        const auto base = round.find(thread_counts.front());
        if (base == round.end() || !(it->second > 0)) continue;
        ratio.push_back(base->second / it->second);
        // Against what the CPUs could do in that round: the speed-up over the first thread
        // count divided by the capacities' ratio (1 thread: pinned to the fastest, capacity 1).
        if (caps == capacities.end() || r >= caps->second.size()) continue;
        const auto cap = caps->second[r].find(threads), cap0 = caps->second[r].find(base->first);
        if (cap != caps->second[r].end() && cap0 != caps->second[r].end() && cap->second > 0)
          of_capacity.push_back(ratio.back() / (cap->second / cap0->second));
      }
      if (ms.empty()) continue;
      const Spread t = spread(ms);
      std::printf("%-22s %3d  %10.2f  %8.2f - %8.2f", key.c_str(), threads, t.median, t.least,
                  t.greatest);
      if (threads != thread_counts.front() && !ratio.empty()) {
        const Spread r = spread(ratio);
        std::printf("  speed-up %.2f (%.2f - %.2f)", r.median, r.least, r.greatest);
        if (!of_capacity.empty()) {
          const Spread e = spread(of_capacity);
          std::printf(", of the CPUs' capacity %.2f (%.2f - %.2f)", e.median, e.least, e.greatest);
        }
      }
      std::printf("\n");
    }
  }
}

// The usage, after `why` (nullptr: asked for with --help, on standard output, exit 0).
int usage(const char* why) {
  static const std::string text = [] {
    std::string s =
        "usage: tick_speed [--cases all|NAME,...] [--models orca,cfsm,thesis,orca-core] "
        "[--threads 1,2] [--ticks N] [--rounds N] [--csv FILE] [--fork yes|no] [--pin yes|no] "
        "[--busy-cpu K]\n"
        "       tick_speed --print CASE [--models M] [--threads T]   (its scenario, for crowddb "
        "run)\ncases:";
    for (const Case& c : kCases) s += std::string(" ") + c.name;
    return s + "\n";
  }();
  const bench::Usage u{"tick_speed", text.c_str()};
  return why ? u.refuse(why) : u.print();
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> cases, models = {"orca", "cfsm", "thesis"};
  std::vector<int> thread_counts = {1, 2};
  uint64_t ticks = 0;
  int rounds = 1;
  std::string csv, print;
  bool fork_cases = true, pin = true;
  int busy_cpu = -1;
  for (int a = 1; a < argc; a += 2) {
    const std::string k = argv[a];
    if (bench::Usage::asked(k)) return usage(nullptr);
    if (a + 1 >= argc) return usage(("missing value after " + k).c_str());
    const std::string v = argv[a + 1];
    if (k == "--cases") {
      cases = split(v);
    } else if (k == "--models") {
      models = split(v);
    } else if (k == "--threads") {
      thread_counts.clear();
      for (const std::string& t : split(v)) {
        const auto n = bench::whole_number(t, 1, 1024);
        if (!n) return usage(("--threads takes counts from 1 to 1024, not '" + v + "'").c_str());
        thread_counts.push_back(static_cast<int>(*n));
      }
    } else if (k == "--ticks") {
      const auto n = bench::whole_number(v, 1, 1'000'000'000);
      if (!n) return usage(("--ticks takes a count from 1 to 10^9, not '" + v + "'").c_str());
      ticks = static_cast<uint64_t>(*n);
    } else if (k == "--rounds") {
      const auto n = bench::whole_number(v, 1, 1000);
      if (!n) return usage(("--rounds takes a count from 1 to 1000, not '" + v + "'").c_str());
      rounds = static_cast<int>(*n);
    } else if (k == "--fork") {
      if (v != "yes" && v != "no") return usage("--fork takes yes or no");
      fork_cases = v == "yes";
    } else if (k == "--pin") {
      if (v != "yes" && v != "no") return usage("--pin takes yes or no");
      pin = v == "yes";
    } else if (k == "--busy-cpu") {
      cpu_set_t allowed;
      const auto n = bench::whole_number(v, 0, CPU_SETSIZE - 1);
      if (!n || sched_getaffinity(0, sizeof allowed, &allowed) != 0 ||
          !CPU_ISSET(static_cast<int>(*n), &allowed) || CPU_COUNT(&allowed) < 2)
        return usage(
            ("--busy-cpu takes one of this process's CPUs (and it needs two), not '" + v + "'")
                .c_str());
      busy_cpu = static_cast<int>(*n);
    } else if (k == "--csv") {
      csv = v;
    } else if (k == "--print") {
      print = v;
    } else {
      return usage(("unknown option " + k).c_str());
    }
  }
  std::vector<const Case*> chosen;
  for (const Case& c : kCases) {
    const bool named = std::find(cases.begin(), cases.end(), c.name) != cases.end();
    const bool all = std::find(cases.begin(), cases.end(), "all") != cases.end();
    const bool huge = std::strcmp(c.name, "airport-1m") == 0 || c.inserted > 0;
    if (named || (all && c.inserted == 0) || (cases.empty() && !huge)) chosen.push_back(&c);
  }
  for (const std::string& n : cases)
    if (n != "all" && !find_case(n)) return usage(("no case named " + n).c_str());
  if (thread_counts.empty()) return usage("--threads takes counts from 1 to 1024");
  if (models.empty()) return usage("--models takes one model at least");
  if (!print.empty()) {
    // The case's document for the first model and thread count, so that the journal's
    // `crowddb run` commands on a case (EXPLAIN ANALYZE, profiles) can be repeated.
    const Case* c = find_case(print);
    if (!c) return usage(("no case named " + print).c_str());
    if (c->inserted > 0)
      return usage(
          (print + ": its agents are inserted by the benchmark, not in a document").c_str());
    if (bench::engine_model(models.front()) != models.front())
      return usage(
          (models.front() + " is a benchmark variant, not a model a document names").c_str());
    std::printf("%s\n", c->doc(models.front(), thread_counts.front()).c_str());
    return 0;
  }

  std::FILE* out = csv.empty() ? nullptr : std::fopen(csv.c_str(), "w");
  if (!csv.empty() && !out) return usage(("cannot write " + csv).c_str());
  if (out)
    std::fprintf(
        out,
        "case,model,threads,agents,ticks,median_ms,min_ms,first_tenth_ms,last_tenth_ms,"
        "agent_ticks_per_s,peak_mb,load_before,load_after,two_cpu,state_hash,round,cpu_speeds,"
        "pinned_cpu,busy_cpu\n");
  std::unique_ptr<BusyLoop> busy;
  char busy_text[16] = "-";
  if (busy_cpu >= 0) {
    busy = std::make_unique<BusyLoop>(busy_cpu);
    if (!busy->started()) {
      std::fprintf(stderr, "tick_speed: could not keep CPU %d busy\n", busy_cpu);
      if (out) std::fclose(out);
      return 1;
    }
    std::snprintf(busy_text, sizeof busy_text, "%d", busy_cpu);
    std::printf("a loop of another process keeps CPU %d busy throughout\n", busy_cpu);
  }
  std::printf("%-14s %-9s %3s %9s %6s %10s %10s %10s %10s %12s %8s %11s %5s %-9s %3s  %s\n", "case",
              "model", "thr", "agents", "ticks", "median ms", "min ms", "first 1/10", "last 1/10",
              "agent-t/s", "peak MB", "load", "2cpu", "cpus", "pin", "state hash");
  int status = 0;
  std::map<std::string, uint64_t> hash_of;  // case/model -> hash of the first thread count
  // Per case/model, per round: the median ms of each thread count (for the summary).
  std::map<std::string, std::vector<std::map<int, double>>> medians;
  // Per case/model, per round: what each thread count's CPUs could do (CpuSpeeds::capacity).
  std::map<std::string, std::vector<std::map<int, double>>> capacities;
  for (int round = 0; round < rounds; ++round) {
    for (const Case* c : chosen) {
      for (const std::string& model : models) {
        std::vector<int> order = thread_counts;
        if (round % 2 == 1) std::reverse(order.begin(), order.end());
        for (int threads : order) {
          const uint64_t n = ticks ? ticks : c->ticks;
          const double load_before = load_average();
          const double two_cpu = two_cpu_throughput();
          const CpuSpeeds speeds = cpu_speeds();
          // One thread on the fastest CPU: its figure does not depend on where the scheduler put
          // it, and the speed-ups are over the best one CPU does.
          const int pinned = pin && threads == 1 ? speeds.fastest : -1;
          Result r;
          bool got = true;
          rusage ru{};
          if (fork_cases) {
            got = in_child(
                [&] {
                  const bool on = pinned >= 0 && pin_to(pinned);
                  Result child = run_case(*c, model, threads, n);
                  child.cpu = on ? pinned : -1;
                  return child;
                },
                r, &ru);
          } else {
            cpu_set_t allowed;
            const bool on = pinned >= 0 && sched_getaffinity(0, sizeof allowed, &allowed) == 0 &&
                            pin_to(pinned);
            r = run_case(*c, model, threads, n);
            r.cpu = on ? pinned : -1;
            if (on && !pin_to(allowed)) {
              // Every later run would inherit the one CPU: stop rather than print their figures.
              std::fprintf(stderr, "tick_speed: could not give the process its CPUs back\n");
              return 1;
            }
            getrusage(RUSAGE_SELF, &ru);  // the process's peak so far, every earlier case included
          }
          const double load_after = load_average();
          if (!got || r.error[0]) {
            std::printf(
                "%-14s %-9s %3d  failed: %s\n", c->name, model.c_str(), threads,
                got ? r.error : "no answer from its child process (pipe, fork, or it died)");
            status = 1;
            continue;
          }
          const double peak_mb = static_cast<double>(ru.ru_maxrss) / 1024.0;
          const double rate = r.agents * static_cast<double>(r.ticks) / r.seconds;
          char hash[17];
          std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(r.hash));
          const std::string key = std::string(c->name) + "/" + model;
          const auto [it, first] = hash_of.emplace(key, r.hash);
          const bool same = first || it->second == r.hash;
          const std::string cpus = speeds.text();
          char pin_text[16] = "-";
          if (r.cpu >= 0) std::snprintf(pin_text, sizeof pin_text, "%d", r.cpu);
          std::printf(
              "%-14s %-9s %3d %9.0f %6llu %10.2f %10.2f %10.2f %10.2f %12.3g %8.0f %5.2f-%5.2f "
              "%5.2f %-9s %3s  "
              "%s%s\n",
              c->name, model.c_str(), threads, r.agents, static_cast<unsigned long long>(r.ticks),
              r.median_ms, r.min_ms, r.first_ms, r.last_ms, rate, peak_mb, load_before, load_after,
              two_cpu, cpus.c_str(), pin_text, hash,
              same ? "" : "  DIFFERS FROM THE FIRST THREAD COUNT");
          std::fflush(stdout);
          if (!same) status = 1;
          auto& per_round = medians[key];
          per_round.resize(static_cast<std::size_t>(rounds));
          per_round[static_cast<std::size_t>(round)][threads] = r.median_ms;
          auto& cap_round = capacities[key];
          cap_round.resize(static_cast<std::size_t>(rounds));
          // (A one-thread run not pinned to the fastest CPU has no capacity of 1: none booked.)
          if (!speeds.speed.empty() && (threads > 1 || r.cpu >= 0))
            cap_round[static_cast<std::size_t>(round)][threads] = speeds.capacity(threads);
          if (out)
            std::fprintf(
                out,
                "%s,%s,%d,%.0f,%llu,%.3f,%.3f,%.3f,%.3f,%.4g,%.0f,%.2f,%.2f,%.2f,%s,%d,%s,%s,%s\n",
                c->name, model.c_str(), threads, r.agents, static_cast<unsigned long long>(r.ticks),
                r.median_ms, r.min_ms, r.first_ms, r.last_ms, rate, peak_mb, load_before,
                load_after, two_cpu, hash, round + 1, cpus.c_str(), pin_text, busy_text);
        }
      }
    }
  }
  if (out) std::fclose(out);
  if (rounds > 1) print_summary(medians, capacities, thread_counts, rounds);
  return status;
}
