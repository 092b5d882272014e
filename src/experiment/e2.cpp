// E2 — the Big Crunch and the perturbed Big Crunch against naive (thesis §4.1, Figure 4.2;
// DESIGN.md §7).
//
// Big Crunch: positions uniform on 640 x 480, every agent heading for the centre so that all
// arrive at t = 20 (horizon 30); perturbed: ±1 (uniform) added to each velocity component.
// Uniform E1 worlds for reference. Two radius ranges: E1's [1, 3] (at n = 15,000 most agents
// already overlap a neighbour, so the answer is mostly t = 0) and [0.1, 0.3] ("sparse"), where the
// collision times crowd just before the arrival and a bound that is loose near t = 20 prunes
// nothing. Methods: "index" (ours), "thesis" (the thesis's frustum bound and best-first search
// from the root with one agent per leaf, made exact), and "naive". Every naive run is compared
// with both indexed answers, row by row ("mismatches").
//
// Output: e2.csv, e2.png (+ e2.gp), e2.txt (machine).
#include <fstream>
#include <ostream>

#include "experiment/experiment.hpp"
#include "experiment/ftc_runs.hpp"
#include "util/executor.hpp"

namespace crowddb::experiment {

void run_e2(const Options& opt) {
  using namespace ftc;
  const bool quick = opt.quick;
  const std::vector<std::size_t> sizes =
      quick ? std::vector<std::size_t>{300, 600}
            : std::vector<std::size_t>{1000, 3000, 5000, 7500, 10000, 12500, 15000};
  const int index_runs = quick ? 2 : 50, thesis_runs = quick ? 2 : 20;
  const double budget = quick ? 4e6 : 3e8;
  const int naive_least = quick ? 1 : 2;

  Executor ex(opt.threads);
  FtcIndex index(ours()), old(thesis());
  std::vector<FtcHit> got, want;
  const std::vector<std::string> head = {
      "radii",          "world",           "method",    "n",        "runs",
      "total_ms",       "total_2sd_ms",    "build_ms",  "query_ms", "nodes_per_query",
      "pops_per_query", "pairs_per_query", "mismatches"};
  CsvWriter csv(opt.out_dir / "e2.csv", head);
  for (const Radii& radii : {kE1Radii, kSparseRadii}) {
    for (World world : {World::crunch, World::perturbed, World::uniform}) {
      const build::Box box = e1_plane();
      auto seed_of = [&](std::size_t n, int r) {
        return opt.seed * 1000003 + n * 7919 + static_cast<uint64_t>(r);
      };
      for (const char* method : {"index", "thesis", "naive"}) {
        const bool is_naive = std::string(method) == "naive";
        if (is_naive && world == World::uniform) continue;  // E1 has naive on uniform worlds
        for (std::size_t n : sizes) {
          FtcIndex& idx = std::string(method) == "index" ? index : old;
          const int runs = is_naive ? naive_runs(n, budget, naive_least, index_runs)
                                    : (std::string(method) == "index" ? index_runs : thesis_runs);
          std::vector<double> tot, b, q;
          QueryStats st;
          std::size_t bad = 0;
          for (int r = 0; r < runs; ++r) {
            const DiscTable t = make_world(world, n, box, radii, seed_of(n, r));
            if (is_naive) {
              tot.push_back(run_naive(t, ex, want) * 1e3);
              run_index(index, t, ex, got);
              bad += mismatches(got, want);
              run_index(old, t, ex, got);
              bad += mismatches(got, want);
              continue;
            }
            const Run x = run_index(idx, t, ex, got);
            tot.push_back((x.build_s + x.query_s) * 1e3);
            b.push_back(x.build_s * 1e3);
            q.push_back(x.query_s * 1e3);
            st += x.stats;
          }
          const MeanSd mt = mean_sd(tot), mb = mean_sd(b), mq = mean_sd(q);
          const double queries = std::max<double>(1, static_cast<double>(st.rows));
          const bool has_stats = !is_naive;
          csv.row(std::vector<std::string>{
              radii.name, name(world), method, std::to_string(n), std::to_string(runs),
              fmt(mt.mean), fmt(2 * mt.sd), has_stats ? fmt(mb.mean) : "",
              has_stats ? fmt(mq.mean) : "",
              has_stats ? fmt(static_cast<double>(st.nodes_visited) / queries) : "",
              has_stats ? fmt(static_cast<double>(st.queue_pops) / queries) : "",
              has_stats ? fmt(static_cast<double>(st.pair_tests) / queries) : "",
              is_naive ? std::to_string(bad) : ""});
          if (opt.log)
            *opt.log << "e2: " << radii.name << " " << name(world) << " " << method << " n=" << n
                     << ": " << fmt(mt.mean) << " ms over " << runs << " runs"
                     << (is_naive ? ", mismatches " : "") << (is_naive ? std::to_string(bad) : "")
                     << "\n";
        }
      }
    }
  }
  csv.close();

  const std::string note = ftc::write_run_note(opt, "e2");
  auto series = [](const std::string& radii, const std::string& world, const std::string& method,
                   const std::string& style, const std::string& title) {
    return ftc::series("e2.csv", radii, world, method, style, title);
  };
  auto panel = [&](const std::string& radii, const std::string& title) {
    return "set title '" + title + "'\nplot " +
           series(radii, "crunch", "index", "lw 2 lc 1 pt 7", "index, Big Crunch") + ", \\\n  " +
           series(radii, "perturbed", "index", "lw 2 lc 2 pt 7", "index, perturbed") + ", \\\n  " +
           series(radii, "uniform", "index", "lw 2 lc 3 pt 7", "index, uniform") + ", \\\n  " +
           series(radii, "crunch", "thesis", "lw 2 lc 1 dt 2 pt 6", "thesis's search, Big Crunch") +
           ", \\\n  " +
           series(radii, "perturbed", "thesis", "lw 2 lc 2 dt 2 pt 6",
                  "thesis's search, perturbed") +
           ", \\\n  " +
           series(radii, "uniform", "thesis", "lw 2 lc 3 dt 2 pt 6", "thesis's search, uniform") +
           ", \\\n  " + series(radii, "crunch", "naive", "lw 2 lc 8 pt 5", "naive, Big Crunch") +
           ", \\\n  " +
           series(radii, "perturbed", "naive", "lw 2 lc 7 dt 3 pt 4", "naive, perturbed") + "\n";
  };
  plot(opt.out_dir, "e2",
       "set terminal pngcairo size 1600,760 font ',11'\n"
       "set output 'e2.png'\n"
       "set datafile separator ','\n"
       "set datafile columnheaders\n"
       "set multiplot layout 1,2 title \"E2 Big Crunch (all arrive at t = 20) and perturbed (±1 "
       "per velocity "
       "component) on 640 x 480, horizon 30: build + query time per tick, mean ± 2σ\\n" +
           note +
           "\"\n"
           "set grid\n"
           "set key below maxrows 3 font ',10'\n"
           "set logscale y\n"
           "set xlabel 'agents n'\n"
           "set ylabel 'time per tick [ms] (log; low bars clipped at mean/10)'\n"
           "lowbar(m, x) = x > m / 10 ? x : m / 10\n" +
           panel("e1", "radius in [1, 3] (the E1 setup)") +
           panel("sparse", "radius in [0.1, 0.3]") + "unset multiplot\n");
}

}  // namespace crowddb::experiment
