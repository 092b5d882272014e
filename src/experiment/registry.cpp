// The catalogue of experiments. Each issue adds its own entries (e1..e5).
#include "experiment/experiment.hpp"

namespace crowddb::experiment {

void run_e4(const Options& opt);  // e4.cpp
void run_e5(const Options& opt);  // e5.cpp

const std::vector<Experiment>& registry() {
  static const std::vector<Experiment> experiments = {
      {"e4",
       "collision quality of the six potential functions (airport, no backoff) vs density x n",
       run_e4},
      {"e5", "potential-field speed: aggregate index vs naive, density x n = 1, n up to 10^6",
       run_e5},
  };
  return experiments;
}

}  // namespace crowddb::experiment
