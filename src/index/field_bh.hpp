// Approximate potential field for the inv kernels (DESIGN.md §4: no exact separable index):
// a Barnes-Hut k-d tree with monopoles. Registered as "bh", exact = false: the planner never
// picks it for "auto"; only by name. The error bound is stated in field_bh.cpp.
#pragma once

#include <vector>

#include "plan/access_path.hpp"

namespace crowddb {

// Opening parameter: a node is replaced by its monopoles only when its radius is at most
// kBhTheta times the distance from the probe to the monopole (in the spec's metric).
inline constexpr double kBhTheta = 0.1;

// Worst-case relative errors (field_bh.cpp): potential <= 2θ/(1-θ) of S_abs, the sum of
// |contributions|; gradient (Euclidean norm of the error vector) <= bh_gradient_bound(metric)
// of G_abs, the sum of the norms of the contributions' gradients.
inline constexpr double kBhPotentialBound = 2 * kBhTheta / (1 - kBhTheta);
double bh_gradient_bound(Metric metric);

// inv kernel, any metric (radial up to 16 frames), A finite, inv_floor > 0.
bool field_bh_supports(const PotentialSpec& spec);

class FieldBarnesHut final : public FieldPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, const PotentialSpec& spec,
           FieldColumns& out, Executor& ex, QueryStats& stats) override;
  void probe(std::span<const Vec2> points, const DiscView& sources, const StaticScene& scene,
             const PotentialSpec& spec, FieldColumns& out, Executor& ex,
             QueryStats& stats) override;
};

}  // namespace crowddb
