// The potential-field aggregate index (DESIGN.md §4, thesis §2.2): exact sums of separable
// exponential kernels — exp-l1, and exp-radial with 1 or 2 frames — for every probe at once in
// O(n log n). The numerical scheme, its error bound and its complexity are explained at the top
// of field_index.cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "plan/access_path.hpp"

namespace crowddb {

// True when the kernel separates into exponential wedge sums: kernel exp with metric l1, or
// radial with 1 or 2 frames; A finite, k finite and >= 0, and a finite positive fd_step when
// finite differences are asked for.
bool field_index_supports(const PotentialSpec& spec);

// One point of a separable field sum: a source (weight w != 0), a probe (slot != kNoSlot), or
// both (an agent probing the field of the others: it never sees itself, whatever its position;
// a coincident distinct entry does contribute its e^0 term).
struct FieldEntry {
  static constexpr uint32_t kNoSlot = UINT32_MAX;
  double x = 0, y = 0;
  double w = 0;             // source weight (charge / the largest |charge|, so |w| <= 1)
  uint32_t slot = kNoSlot;  // output row of a probe
  uint32_t id = 0;          // unique: tie-break, so the result never depends on sort order
};

// Working storage of the sums (sorted entries, tiles' sweeps), for a caller that sums again and
// again (FieldIndex, tick after tick): allocated per call, its megabytes went through malloc
// every tick, and freed on another thread than the last (the thesis model runs the field beside
// first-to-collide) glibc gave them back to the system and faulted them in anew (2026-12-04).
struct FieldSumScratch;
struct FieldSumScratchDeleter {
  void operator()(FieldSumScratch* s) const;
};
using FieldSumScratchPtr = std::unique_ptr<FieldSumScratch, FieldSumScratchDeleter>;
FieldSumScratchPtr make_field_sum_scratch();

// Exact separable sums: out_*[slot] = sum over source entries q other than the probe entry itself
// of w_q K(d(p, q)), and its analytic gradient with respect to p, for K = e^{-k d} with d the
// spec's l1 or radial (1-2 frames) metric; sign(0) = 0 conventions as PairKernel. The sums are
// unscaled (no A, no probe charge). `entries` may be reordered. out_* must have room for every
// slot; slots not present are left untouched. Thread count does not change the output; nor does
// `scratch` (none: the call's own).
void separable_field_sums(std::vector<FieldEntry>& entries, const PotentialSpec& spec,
                          std::span<double> out_pot, std::span<double> out_gx,
                          std::span<double> out_gy, Executor& ex, QueryStats& stats,
                          FieldSumScratch* scratch = nullptr);

// True for every exp kernel (any metric) with A finite, k finite and >= 0.
bool field_cutoff_supports(const PotentialSpec& spec);

// The same sums for any exp kernel by direct pair evaluation inside the tiles of the same
// halo-cut tiling (terms farther than the halo are dropped: <= 2.4e-16 A c_max^2 per probe), so
// exact within DESIGN.md's tolerance; O(n * sources within the halo), not O(n log n).
void cutoff_field_sums(std::vector<FieldEntry>& entries, const PotentialSpec& spec,
                       std::span<double> out_pot, std::span<double> out_gx,
                       std::span<double> out_gy, Executor& ex, QueryStats& stats,
                       FieldSumScratch* scratch = nullptr);

// FieldPath "index" (separable sweeps) or "cutoff" (direct pairs within the halo):
// set-at-a-time potential and gradient at every disc, and the field at arbitrary points.
class FieldIndex final : public FieldPath {
 public:
  enum class Mode { separable, cutoff };
  explicit FieldIndex(Mode mode = Mode::separable) : mode_(mode) {}
  void run(const DiscView& discs, const StaticScene& scene, const PotentialSpec& spec,
           FieldColumns& out, Executor& ex, QueryStats& stats) override;
  void probe(std::span<const Vec2> points, const DiscView& sources, const StaticScene& scene,
             const PotentialSpec& spec, FieldColumns& out, Executor& ex,
             QueryStats& stats) override;

 private:
  void sums(std::vector<FieldEntry>& e, const PotentialSpec& spec, std::span<double> pot,
            std::span<double> gx, std::span<double> gy, Executor& ex, QueryStats& stats) {
    (mode_ == Mode::cutoff ? cutoff_field_sums : separable_field_sums)(e, spec, pot, gx, gy, ex,
                                                                       stats, scratch_.get());
  }
  Mode mode_;
  // Reused from tick to tick: the entries, the unscaled sums, the sums' working storage.
  std::vector<FieldEntry> entries_;
  std::vector<double> pot_, gx_, gy_;
  FieldSumScratchPtr scratch_ = make_field_sum_scratch();
};

}  // namespace crowddb
