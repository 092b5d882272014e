// Barnes-Hut approximation of the inv-kernel fields (1/d with d = l1, l2 or radial).
//
// TREE. A k-d tree over the sources (discs with a non-zero charge and the scene's charged points),
// split at the median of the longer side of each node's bounding box, leaves of <= 8 sources.
// Each node keeps two monopoles, one for its positive and one for its negative weights: total
// weight Q and weighted centroid c, and the radius r = max over the box corners of d(corner, c)
// (d is a norm, so this bounds d(q, c) for every q in the box).
//
// OPENING RULE. For a probe p a node is replaced by its monopoles — Q K(d(p, c)) and the
// gradient Q K'(D) ∇d(p - c), through the naive path's PairKernel — only if, for each monopole,
//   r <= θ D  with D = d(p, c)   and   D - r > inv_floor (no term of the node is floored),
// the node does not hold the probe's own disc, and for l1 / radial every line of the metric
// (x = 0, y = 0, and both axes of each rotated frame) leaves the whole box strictly on one side
// of p, so that ∇d is the same constant for every source of the node. Otherwise it is opened;
// leaves are summed exactly.
//
// ERROR BOUND, per probe, θ = kBhTheta = 0.1. Each source of an approximated node has
// d_i in [D - r, D + r] (triangle inequality), so
//  - potential: |Q K(D) - sum w_i K(d_i)| <= sum |w_i| (K(D - r) - K(D + r)) and
//    K(D - r) / K(D + r) - 1 = 2r / (D - r) <= 2θ / (1 - θ):  |S_bh - S| <= 0.222 S_abs;
//  - gradient, l1 / radial (∇d constant g in the node): |K'(d_i) - K'(D)| |g| with
//    |1/d_i^2 - 1/D^2| <= ((1+θ)/(1-θ))^2 - 1 relative to 1/d_i^2: 0.494 G_abs;
//  - gradient, l2: that, plus |K'(D)| |u_i - u_c| <= (1/D^2) 2θ for the unit vectors, relative to
//    1/d_i^2 >= 1/(D+r)^2: 2θ(1+θ)^2 more, 0.736 G_abs in all;
// with S_abs = sum |A c_p c_q K(d)| and G_abs = sum |A c_p c_q K'(d)| |∇d| over the probe's terms.
// These are worst cases (a monopole at the centroid is exact to first order; the tests also
// measure the typical error, far smaller). Exact methods remain "naive" for inv kernels.
//
// COMPLEXITY. Build O(n log n). A query visits O(θ^-2 log n) nodes for l2; for l1 / radial the
// nodes cut by the probe's own lines are opened down to leaves, O(sqrt n) more per line.
// Deterministic: fixed tree, fixed traversal order, each probe summed by one thread.
#include "index/field_bh.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "crowddb/error.hpp"
#include "query/field_kernels.hpp"

namespace crowddb {
namespace {

constexpr std::size_t kLeafSize = 8;
constexpr uint32_t kNoDisc = UINT32_MAX;

struct Source {
  double x, y, w;
  uint32_t row;  // disc row, or kNoDisc for a scene point
};

struct Monopole {
  double q = 0, cx = 0, cy = 0, r = 0;
};

struct Node {
  double xmin, ymin, xmax, ymax;
  uint32_t begin, end;           // sources [begin, end)
  uint32_t left = 0, right = 0;  // children; 0: leaf (the root is never a child)
  Monopole pos, neg;
};

double metric_distance(const PairKernel& k, double dx, double dy) {
  switch (k.spec.metric) {
    case Metric::l1:
      return std::abs(dx) + std::abs(dy);
    case Metric::l2:
      return std::sqrt(dx * dx + dy * dy);
    case Metric::radial:
    default: {
      double s = 0;
      for (int j = 0; j < k.spec.radial_frames; ++j)
        s += std::abs(dx * k.cos_[j] + dy * k.sin_[j]) + std::abs(-dx * k.sin_[j] + dy * k.cos_[j]);
      return k.radial_scale * s;
    }
  }
}

class Tree {
 public:
  Tree(std::vector<Source> sources, std::size_t rows, const PairKernel& kernel)
      : src_(std::move(sources)), kernel_(kernel), where_(rows, kNoDisc) {
    nodes_.reserve(2 * src_.size() / kLeafSize + 2);
    if (!src_.empty()) build(0, static_cast<uint32_t>(src_.size()));
    for (uint32_t i = 0; i < src_.size(); ++i)
      if (src_[i].row != kNoDisc) where_[src_[i].row] = i;
  }

  // Potential and gradient at (px, py) of every source but the disc `self` (kNoDisc: none).
  void sum(double px, double py, uint32_t self, double& pot, double& gx, double& gy,
           uint64_t& pairs, uint64_t& visited, std::vector<uint32_t>& stack) const {
    pot = gx = gy = 0;
    if (nodes_.empty()) return;
    const uint32_t self_pos = self == kNoDisc ? kNoDisc : where_[self];
    stack.assign(1, 0);
    while (!stack.empty()) {
      const Node& n = nodes_[stack.back()];
      stack.pop_back();
      ++visited;
      const bool holds_self = self_pos != kNoDisc && self_pos >= n.begin && self_pos < n.end;
      if (n.left == 0) {
        for (uint32_t i = n.begin; i < n.end; ++i) {
          if (i == self_pos) continue;
          kernel_.add(px - src_[i].x, py - src_[i].y, src_[i].w, pot, gx, gy);
          ++pairs;
        }
        continue;
      }
      if (!holds_self && far_enough(n, px, py)) {
        for (const Monopole* m : {&n.pos, &n.neg})
          if (m->q != 0) kernel_.add(px - m->cx, py - m->cy, m->q, pot, gx, gy);
        continue;
      }
      stack.push_back(n.right);
      stack.push_back(n.left);
    }
  }

 private:
  uint32_t build(uint32_t begin, uint32_t end) {
    const auto id = static_cast<uint32_t>(nodes_.size());
    nodes_.push_back({});
    Node n{INFINITY, INFINITY, -INFINITY, -INFINITY, begin, end, 0, 0, {}, {}};
    for (uint32_t i = begin; i < end; ++i) {
      const Source& s = src_[i];
      n.xmin = std::min(n.xmin, s.x);
      n.ymin = std::min(n.ymin, s.y);
      n.xmax = std::max(n.xmax, s.x);
      n.ymax = std::max(n.ymax, s.y);
      Monopole& m = s.w > 0 ? n.pos : n.neg;
      m.q += s.w;
      m.cx += s.w * s.x;
      m.cy += s.w * s.y;
    }
    for (Monopole* m : {&n.pos, &n.neg}) {
      if (m->q == 0) continue;
      // The centroid, clamped into the box against rounding.
      m->cx = std::clamp(m->cx / m->q, n.xmin, n.xmax);
      m->cy = std::clamp(m->cy / m->q, n.ymin, n.ymax);
      for (double x : {n.xmin, n.xmax})
        for (double y : {n.ymin, n.ymax})
          m->r = std::max(m->r, metric_distance(kernel_, x - m->cx, y - m->cy));
    }
    if (end - begin > kLeafSize && (n.xmax > n.xmin || n.ymax > n.ymin)) {
      const bool by_x = n.xmax - n.xmin >= n.ymax - n.ymin;
      const uint32_t mid = begin + (end - begin) / 2;
      std::nth_element(src_.begin() + begin, src_.begin() + mid, src_.begin() + end,
                       [by_x](const Source& a, const Source& b) {
                         const double ka = by_x ? a.x : a.y, kb = by_x ? b.x : b.y;
                         return ka < kb || (ka == kb && (by_x ? a.y : a.x) < (by_x ? b.y : b.x));
                       });
      n.left = build(begin, mid);
      n.right = build(mid, end);
    }
    nodes_[id] = n;
    return id;
  }

  // The opening rule (see the top of the file).
  bool far_enough(const Node& n, double px, double py) const {
    const PotentialSpec& s = kernel_.spec;
    for (const Monopole* m : {&n.pos, &n.neg}) {
      if (m->q == 0) continue;
      const double D = metric_distance(kernel_, px - m->cx, py - m->cy);
      if (!(m->r <= kBhTheta * D) || !(D - m->r > s.inv_floor)) return false;
    }
    if (s.metric == Metric::l2) return true;
    // Every line of the metric must leave the box strictly on one side of p.
    const double dx[2] = {px - n.xmax, px - n.xmin}, dy[2] = {py - n.ymax, py - n.ymin};
    const auto one_side = [&](double a, double b) {
      int pos = 0, neg = 0;
      for (double x : dx)
        for (double y : dy) {
          const double f = a * x + b * y;
          pos += f > 0;
          neg += f < 0;
        }
      return pos == 4 || neg == 4;
    };
    if (s.metric == Metric::l1) return one_side(1, 0) && one_side(0, 1);
    for (int j = 0; j < s.radial_frames; ++j)
      if (!one_side(kernel_.cos_[j], kernel_.sin_[j]) ||
          !one_side(-kernel_.sin_[j], kernel_.cos_[j]))
        return false;
    return true;
  }

  std::vector<Source> src_;
  const PairKernel& kernel_;
  std::vector<uint32_t> where_;  // disc row -> position in src_
  std::vector<Node> nodes_;
};

std::vector<Source> gather(const DiscView& d, const StaticScene& scene) {
  std::vector<Source> s;
  for (std::size_t i = 0; i < d.n; ++i)
    if (d.charge[i] != 0) s.push_back({d.x[i], d.y[i], d.charge[i], static_cast<uint32_t>(i)});
  const auto px = scene.point_x(), py = scene.point_y(), pc = scene.point_charge();
  for (std::size_t j = 0; j < px.size(); ++j)
    if (pc[j] != 0) s.push_back({px[j], py[j], pc[j], kNoDisc});
  for (const Source& q : s)
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.w))
      throw Error(Error::Kind::input, "field bh: a point or charge is not finite");
  return s;
}

// Evaluates n probes: position (x(i), y(i)), own disc self(i), scale A c_p (or A).
template <class At>
void evaluate(std::size_t n, At at, const Tree& tree, const PotentialSpec& spec, FieldColumns& out,
              Executor& ex, QueryStats& stats) {
  std::vector<uint64_t> pairs(n, 0), visited(n, 0);
  ex.for_each_chunk(n, 64, [&](std::size_t b, std::size_t e) {
    std::vector<uint32_t> stack;
    for (std::size_t i = b; i < e; ++i) {
      double x, y, scale;
      uint32_t self;
      at(i, x, y, self, scale);
      double pot, gx, gy;
      tree.sum(x, y, self, pot, gx, gy, pairs[i], visited[i], stack);
      out.potential[i] = scale * pot;
      if (!spec.finite_difference) {
        out.grad_x[i] = scale * gx;
        out.grad_y[i] = scale * gy;
        continue;
      }
      const double h = spec.fd_step;
      double p1, unused1, unused2;
      tree.sum(x + h, y, self, p1, unused1, unused2, pairs[i], visited[i], stack);
      out.grad_x[i] = (scale * p1 - out.potential[i]) / h;
      tree.sum(x, y + h, self, p1, unused1, unused2, pairs[i], visited[i], stack);
      out.grad_y[i] = (scale * p1 - out.potential[i]) / h;
    }
  });
  stats.rows += n;
  for (std::size_t i = 0; i < n; ++i) {
    stats.pair_tests += pairs[i];
    stats.nodes_visited += visited[i];
  }
}

}  // namespace

double bh_gradient_bound(Metric metric) {
  const double t = kBhTheta, rel = std::pow((1 + t) / (1 - t), 2) - 1;
  return metric == Metric::l2 ? rel + 2 * t * (1 + t) * (1 + t) : rel;
}

bool field_bh_supports(const PotentialSpec& spec) {
  return spec.kernel == Kernel::inv && std::isfinite(spec.A) && spec.inv_floor > 0 &&
         std::isfinite(spec.inv_floor) && spec.radial_frames >= 1 &&
         spec.radial_frames <= PairKernel::kMaxFrames &&
         (!spec.finite_difference || (spec.fd_step > 0 && std::isfinite(spec.fd_step)));
}

void FieldBarnesHut::run(const DiscView& d, const StaticScene& scene, const PotentialSpec& spec,
                         FieldColumns& out, Executor& ex, QueryStats& stats) {
  if (!field_bh_supports(spec)) throw Error(Error::Kind::usage, "field bh: unsupported kernel");
  out.resize(d.n);
  const PairKernel kernel(spec);
  const Tree tree(gather(d, scene), d.n, kernel);
  evaluate(
      d.n,
      [&](std::size_t i, double& x, double& y, uint32_t& self, double& scale) {
        x = d.x[i];
        y = d.y[i];
        self = static_cast<uint32_t>(i);
        scale = spec.A * d.charge[i];
      },
      tree, spec, out, ex, stats);
}

void FieldBarnesHut::probe(std::span<const Vec2> points, const DiscView& sources,
                           const StaticScene& scene, const PotentialSpec& spec, FieldColumns& out,
                           Executor& ex, QueryStats& stats) {
  if (!field_bh_supports(spec)) throw Error(Error::Kind::usage, "field bh: unsupported kernel");
  out.resize(points.size());
  const PairKernel kernel(spec);
  const Tree tree(gather(sources, scene), sources.n, kernel);
  evaluate(
      points.size(),
      [&](std::size_t i, double& x, double& y, uint32_t& self, double& scale) {
        x = points[i].x;
        y = points[i].y;
        self = kNoDisc;
        scale = spec.A;
      },
      tree, spec, out, ex, stats);
}

}  // namespace crowddb
