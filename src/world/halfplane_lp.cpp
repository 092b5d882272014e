#include "world/halfplane_lp.hpp"

#include <cmath>
#include <vector>

namespace crowddb {
namespace {

// Parallel lines: |sin| of the angle between a line and a normal below this are treated as
// parallel (the 1-D bound would divide by ~0).
constexpr double kParallel = 1e-12;
// Two doubles in the lanes of one register (GCC's and clang's vector extensions; SSE2 on x86-64).
typedef double V2d __attribute__((vector_size(16)));

struct Goal2 {
  bool direction;  // true: maximise v . (x, y); false: the point closest to (x, y)
  double x, y;
};

// The optimum on the line of plane i, constrained by planes [0, i) and the disc. Returns false
// when that part of the line is empty.
bool on_line(std::span<const HalfPlane> planes, std::size_t i, double R, const Goal2& goal,
             double& rx, double& ry) {
  const HalfPlane& h = planes[i];
  const double dx = -h.ny, dy = h.nx;  // the line's direction: L(t) = p + t d
  // Disc: |p + t d|^2 <= R^2.
  const double pd = h.px * dx + h.py * dy;
  const double disc = pd * pd - (h.px * h.px + h.py * h.py) + R * R;
  if (disc < 0) return false;
  const double root = std::sqrt(disc);
  // {lo, -hi}, both raised by max: a > 0 bounds t from below (lane 0), a < 0 from above (lane
  // 1, negated). Without branches, in the lanes of a vector: the sign of a is a coin toss to the
  // predictor, and the loop runs for every violated plane of every row. lo only rises and hi only
  // falls, so an interval found empty half way stays empty: the answer an early return gives.
  V2d lohi = {-pd - root, -(-pd + root)};
  const V2d none = {-INFINITY, -INFINITY};
  bool outside = false;  // line i lies outside a parallel plane j
  for (std::size_t j = 0; j < i; ++j) {
    const HalfPlane& g = planes[j];
    const double a = dx * g.nx + dy * g.ny;  // t a >= b
    const double b = (g.px - h.px) * g.nx + (g.py - h.py) * g.ny;
    outside |= (std::abs(a) <= kParallel) & (b > 0);
    const double t = b / a;  // (not taken when |a| <= kParallel)
    const V2d sa = {a, -a}, st = {t, -t};
    const V2d cand = sa > kParallel ? st : none;
    lohi = lohi < cand ? cand : lohi;
  }
  const double lo = lohi[0], hi = -lohi[1];
  if (outside || lo > hi) return false;
  double t;
  if (goal.direction) {
    t = dx * goal.x + dy * goal.y > 0 ? hi : lo;
  } else {
    t = (goal.x - h.px) * dx + (goal.y - h.py) * dy;
    t = t < lo ? lo : (t > hi ? hi : t);
  }
  rx = h.px + t * dx;
  ry = h.py + t * dy;
  return true;
}

// The 2-D program over planes[0, m): returns m on success, else the index of the plane whose line
// had no room (result holds the optimum of the planes before it).
std::size_t lp2(std::span<const HalfPlane> planes, double R, const Goal2& goal, double& rx,
                double& ry) {
  if (goal.direction) {
    rx = goal.x * R;
    ry = goal.y * R;
  } else {
    const double len2 = goal.x * goal.x + goal.y * goal.y;
    if (len2 > R * R) {
      const double s = R / std::sqrt(len2);
      rx = goal.x * s;
      ry = goal.y * s;
    } else {
      rx = goal.x;
      ry = goal.y;
    }
  }
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const HalfPlane& h = planes[i];
    if ((rx - h.px) * h.nx + (ry - h.py) * h.ny >= 0) continue;
    const double keep_x = rx, keep_y = ry;
    if (!on_line(planes, i, R, goal, rx, ry)) {
      rx = keep_x;
      ry = keep_y;
      return i;
    }
  }
  return planes.size();
}

double violation(const HalfPlane& h, double x, double y) {
  return -((x - h.px) * h.nx + (y - h.py) * h.ny);
}

// The 3-D fallback from plane `from` on: minimise the largest violation of planes [hard, end)
// keeping planes [0, hard). When plane i is violated more than the current optimum's largest
// violation d, the new optimum violates i exactly as much as the worst earlier plane it ties
// with: it lies in every "j no worse than i" half-plane, at the point that violates i least.
void lp3(std::span<const HalfPlane> planes, std::size_t hard, std::size_t from, double R,
         double& rx, double& ry) {
  double worst = 0;
  thread_local std::vector<HalfPlane> sub;  // reused: the fallback runs for many rows a tick
  for (std::size_t i = from; i < planes.size(); ++i) {
    const HalfPlane& pi = planes[i];
    if (violation(pi, rx, ry) <= worst) continue;
    sub.assign(planes.begin(), planes.begin() + static_cast<std::ptrdiff_t>(hard));
    for (std::size_t j = hard; j < i; ++j) {
      const HalfPlane& pj = planes[j];
      // violation_j(v) <= violation_i(v)  <=>  v . (n_j - n_i) >= p_j . n_j - p_i . n_i
      const double mx = pj.nx - pi.nx, my = pj.ny - pi.ny;
      const double len = std::sqrt(mx * mx + my * my);
      if (len <= kParallel) continue;  // same normal: j is the weaker of the two here
      const double c = (pj.px * pj.nx + pj.py * pj.ny - pi.px * pi.nx - pi.py * pi.ny) / len;
      const double nx = mx / len, ny = my / len;
      sub.push_back({nx * c, ny * c, nx, ny});
    }
    const double keep_x = rx, keep_y = ry;
    if (lp2(sub, R, {true, pi.nx, pi.ny}, rx, ry) < sub.size()) {
      // Only rounding can make this fail (the previous optimum satisfies every bisector).
      rx = keep_x;
      ry = keep_y;
    }
    worst = violation(pi, rx, ry);
  }
}

}  // namespace

LpResult solve_velocity_lp(std::span<const HalfPlane> planes, std::size_t hard, double max_speed,
                           double pref_x, double pref_y) {
  LpResult r;
  const std::size_t failed = lp2(planes, max_speed, {false, pref_x, pref_y}, r.vx, r.vy);
  if (failed == planes.size()) return r;
  r.feasible = false;
  if (failed < hard) {
    // Only rounding can empty the hard planes (zero satisfies each): stand still.
    r.vx = r.vy = 0;
    return r;
  }
  lp3(planes, hard, failed, max_speed, r.vx, r.vy);
  return r;
}

}  // namespace crowddb
