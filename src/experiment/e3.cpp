// E3 — priority-queue deletions per query (thesis §4.1, Figure 4.3; DESIGN.md §7): uniform
// worlds against the perturbed Big Crunch (and the exact one), for our index and for the
// thesis's search (frustum bound, best-first from the root, one agent per leaf, made exact).
// Worlds and radii as in E2. Per run: queue pops (deletions), pushes and nodes visited per query
// over all agents; mean ± 2σ over runs; and the largest per-query pop count of the first run.
//
// Output: e3.csv, e3.png (+ e3.gp), e3.txt (machine).
#include <algorithm>
#include <fstream>
#include <ostream>

#include "experiment/experiment.hpp"
#include "experiment/ftc_runs.hpp"
#include "util/executor.hpp"

namespace crowddb::experiment {

void run_e3(const Options& opt) {
  using namespace ftc;
  const bool quick = opt.quick;
  const std::vector<std::size_t> sizes =
      quick ? std::vector<std::size_t>{300, 600}
            : std::vector<std::size_t>{1000, 3000, 5000, 7500, 10000, 12500, 15000};
  const int runs = quick ? 2 : 20;

  Executor ex(opt.threads);
  std::vector<FtcHit> got;
  const std::vector<std::string> head = {"radii",
                                         "world",
                                         "method",
                                         "n",
                                         "runs",
                                         "pops_per_query",
                                         "pops_2sd",
                                         "pushes_per_query",
                                         "nodes_per_query",
                                         "pairs_per_query",
                                         "max_pops_query"};
  CsvWriter csv(opt.out_dir / "e3.csv", head);
  for (const Radii& radii : {kE1Radii, kSparseRadii}) {
    for (World world : {World::uniform, World::perturbed, World::crunch}) {
      for (const char* method : {"index", "thesis"}) {
        FtcIndex idx(std::string(method) == "index" ? ours() : thesis());
        for (std::size_t n : sizes) {
          std::vector<double> pops;
          QueryStats st;
          uint64_t max_pops = 0;
          for (int r = 0; r < runs; ++r) {
            const DiscTable t =
                make_world(world, n, e1_plane(), radii,
                           opt.seed * 1000003 + n * 7919 + static_cast<uint64_t>(r));
            const Run x = run_index(idx, t, ex, got);
            pops.push_back(static_cast<double>(x.stats.queue_pops) / static_cast<double>(n));
            st += x.stats;
            if (r == 0)
              for (std::size_t i = 0; i < n; ++i) {
                QueryStats one;
                idx.query(i, &one);
                max_pops = std::max(max_pops, one.queue_pops);
              }
          }
          const MeanSd mp = mean_sd(pops);
          const double queries = static_cast<double>(st.rows);
          csv.row(std::vector<std::string>{
              radii.name, name(world), method, std::to_string(n), std::to_string(runs),
              fmt(mp.mean), fmt(2 * mp.sd), fmt(static_cast<double>(st.queue_pushes) / queries),
              fmt(static_cast<double>(st.nodes_visited) / queries),
              fmt(static_cast<double>(st.pair_tests) / queries), std::to_string(max_pops)});
          if (opt.log)
            *opt.log << "e3: " << radii.name << " " << name(world) << " " << method << " n=" << n
                     << ": " << fmt(mp.mean) << " pops/query (max " << max_pops << ")\n";
        }
      }
    }
  }
  csv.close();

  const std::string note = ftc::write_run_note(opt, "e3");
  auto series = [](const std::string& radii, const std::string& world, const std::string& method,
                   const std::string& style, const std::string& title) {
    return ftc::series("e3.csv", radii, world, method, style, title);
  };
  auto panel = [&](const std::string& radii, const std::string& title) {
    return "set title '" + title + "'\nplot " +
           series(radii, "uniform", "index", "lw 2 lc 3 pt 7", "index, uniform") + ", \\\n  " +
           series(radii, "perturbed", "index", "lw 2 lc 2 pt 7", "index, perturbed Big Crunch") +
           ", \\\n  " + series(radii, "crunch", "index", "lw 2 lc 1 pt 7", "index, Big Crunch") +
           ", \\\n  " +
           series(radii, "uniform", "thesis", "lw 2 lc 3 dt 2 pt 6", "thesis's search, uniform") +
           ", \\\n  " +
           series(radii, "perturbed", "thesis", "lw 2 lc 2 dt 2 pt 6",
                  "thesis's search, perturbed Big Crunch") +
           ", \\\n  " +
           series(radii, "crunch", "thesis", "lw 2 lc 1 dt 2 pt 6", "thesis's search, Big Crunch") +
           "\n";
  };
  plot(opt.out_dir, "e3",
       "set terminal pngcairo size 1600,760 font ',11'\n"
       "set output 'e3.png'\n"
       "set datafile separator ','\n"
       "set datafile columnheaders\n"
       "set multiplot layout 1,2 title \"E3 priority-queue deletions per query (640 x 480, horizon "
       "30), mean ± 2σ "
       "over runs\\n" +
           note +
           "\"\n"
           "set grid\n"
           "set key below maxrows 3 font ',10'\n"
           "set logscale y\n"
           "set xlabel 'agents n'\n"
           "set ylabel 'queue deletions (pops) per query (log; low bars clipped at mean/10)'\n"
           "lowbar(m, x) = x > m / 10 ? x : m / 10\n" +
           panel("e1", "radius in [1, 3] (the E1 setup)") +
           panel("sparse", "radius in [0.1, 0.3]") + "unset multiplot\n");
}

}  // namespace crowddb::experiment
