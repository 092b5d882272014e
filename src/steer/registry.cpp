// The catalogue of steering models. Adding a model means adding one entry here; no stage of the
// tick changes.
#include <sstream>

#include "crowddb/error.hpp"
#include "steer/model.hpp"

namespace crowddb::steer {

std::string explain_number(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

std::unique_ptr<Model> make_thesis_model();
std::unique_ptr<Model> make_orca_model();
std::unique_ptr<Model> make_cfsm_model();

const std::vector<ModelInfo>& model_registry() {
  static const std::vector<ModelInfo> models = {
      {"orca", "optimal reciprocal collision avoidance (van den Berg et al. 2011): half-planes, LP",
       make_orca_model},
      {"cfsm",
       "collision-free speed model (Tordeux, Chraibi, Seyfried 2016): headway speed, repulsion",
       make_cfsm_model},
      {"thesis",
       "the thesis's rule: attraction, potential field, first-to-collide (DESIGN.md §3.1)",
       make_thesis_model},
  };
  return models;
}

const ModelInfo& find_model(std::string_view name) {
  std::string names;
  for (const ModelInfo& m : model_registry()) {
    if (m.name == name) return m;
    names += (names.empty() ? "" : ", ") + m.name;
  }
  throw Error(Error::Kind::usage,
              "unknown steering model '" + std::string(name) + "' (choose from " + names + ")");
}

}  // namespace crowddb::steer
