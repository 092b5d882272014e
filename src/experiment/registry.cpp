// The catalogue of experiments. Each issue adds its own entries (e1..e5).
#include "experiment/experiment.hpp"

namespace crowddb::experiment {

const std::vector<Experiment>& registry() {
  static const std::vector<Experiment> experiments = {};
  return experiments;
}

}  // namespace crowddb::experiment
