// The catalogue of access paths, and the planner's rule for "auto". Adding an index means adding
// one entry here; no stage of the tick changes.
#include <algorithm>

#include "plan/access_path.hpp"
#include "query/naive_paths.hpp"

namespace crowddb {
namespace {

template <class M>
std::string choices(const std::vector<M>& registry) {
  std::string s;
  for (const auto& m : registry) s += (s.empty() ? "" : ", ") + m.info.name;
  return s + (s.empty() ? "" : ", ") + "auto";
}

template <class M>
const M* by_name(const std::vector<M>& registry, std::string_view name) {
  for (const auto& m : registry)
    if (m.info.name == name) return &m;
  return nullptr;
}

// Highest auto_rank among the applicable methods; naive (rank 0, min 0) always applies.
template <class M, class Ok>
const M& pick(const std::vector<M>& registry, std::size_t rows, Ok ok) {
  const M* best = &registry.front();
  for (const auto& m : registry)
    if (m.info.in_auto && m.info.exact && rows >= m.info.auto_min_rows && ok(m) &&
        m.info.auto_rank > best->info.auto_rank)
      best = &m;
  return *best;
}

}  // namespace

const std::vector<FtcMethod>& ftc_registry() {
  static const std::vector<FtcMethod> methods = {
      {{"naive", "nested loop over all pairs, O(n^2)"},
       [] { return std::make_unique<FtcNaive>(); }},
  };
  return methods;
}

const std::vector<FieldMethod>& field_registry() {
  static const std::vector<FieldMethod> methods = {
      {{"naive", "nested loop over all pairs, O(n^2)"},
       [](const PotentialSpec&) { return true; },
       [] { return std::make_unique<FieldNaive>(); }},
  };
  return methods;
}

const std::vector<CollisionMethod>& collision_registry() {
  static const std::vector<CollisionMethod> methods = {
      {{"naive", "nested loop over all pairs, O(n^2)"},
       [](const CollisionQueryShape&) { return true; },
       [] { return std::make_unique<CollisionNaive>(); }},
  };
  return methods;
}

const FtcMethod& find_ftc_method(std::string_view name) {
  if (const auto* m = by_name(ftc_registry(), name)) return *m;
  throw Error(Error::Kind::usage, "unknown first-to-collide method '" + std::string(name) +
                                      "' (choose from " + choices(ftc_registry()) + ")");
}

const FieldMethod& find_field_method(std::string_view name, const PotentialSpec& spec) {
  const auto* m = by_name(field_registry(), name);
  if (!m)
    throw Error(Error::Kind::usage, "unknown field method '" + std::string(name) +
                                        "' (choose from " + choices(field_registry()) + ")");
  if (!m->supports(spec))
    throw Error(Error::Kind::usage,
                "field method '" + std::string(name) + "' does not support this kernel and metric");
  return *m;
}

const CollisionMethod& find_collision_method(std::string_view name,
                                             const CollisionQueryShape& shape) {
  const auto* m = by_name(collision_registry(), name);
  if (!m)
    throw Error(Error::Kind::usage, "unknown collision method '" + std::string(name) +
                                        "' (choose from " + choices(collision_registry()) + ")");
  if (!m->supports(shape))
    throw Error(Error::Kind::usage, "collision method '" + std::string(name) +
                                        "' does not apply here (" + m->info.description + ")");
  return *m;
}

const FtcMethod& choose_ftc_method(std::size_t rows) {
  return pick(ftc_registry(), rows, [](const FtcMethod&) { return true; });
}

const FieldMethod& choose_field_method(std::size_t rows, const PotentialSpec& spec) {
  return pick(field_registry(), rows, [&](const FieldMethod& m) { return m.supports(spec); });
}

const CollisionMethod& choose_collision_method(const CollisionQueryShape& shape) {
  return pick(collision_registry(), shape.rows,
              [&](const CollisionMethod& m) { return m.supports(shape); });
}

}  // namespace crowddb
