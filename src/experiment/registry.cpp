// The catalogue of experiments. Each issue adds its own entries (e1..e5), in name order.
#include "experiment/experiment.hpp"

namespace crowddb::experiment {

void run_e1(const Options& opt);          // e1.cpp
void run_e2(const Options& opt);          // e2.cpp
void run_e3(const Options& opt);          // e3.cpp
void run_e4(const Options& opt);          // e4.cpp
void run_e5(const Options& opt);          // e5.cpp
void run_fd(const Options& opt);          // flows.cpp
void run_bottleneck(const Options& opt);  // flows.cpp

const std::vector<Experiment>& registry() {
  static const std::vector<Experiment> experiments = {
      {"bottleneck",
       "flow through a bottleneck of 0.8-2.5 m per steering model, beside the Juelich specific "
       "flow",
       run_bottleneck, true, true},
      {"e1",
       "first-to-collide scaling: index build/query vs naive, n = 1,000..15,000 (and 10^6 at E1 "
       "density)",
       run_e1},
      {"e2", "first-to-collide on the Big Crunch and the perturbed Big Crunch vs naive", run_e2},
      {"e3",
       "first-to-collide priority-queue deletions per query: uniform vs (perturbed) Big Crunch",
       run_e3},
      {"e4",
       "collision quality of the six potential functions (airport, no backoff) vs density x n",
       run_e4},
      {"e5", "potential-field speed: aggregate index vs naive, density x n = 1, n up to 10^6",
       run_e5},
      {"fd",
       "speed against density in a 4 m wide ring corridor (RiMEA 4 with periodic ends) per "
       "steering model, beside Weidmann",
       run_fd, true},
  };
  return experiments;
}

}  // namespace crowddb::experiment
