#include "steer/passing.hpp"

#include <algorithm>
#include <bit>
#include <numbers>

#include "index/row_buckets.hpp"
#include "steer/passing_lanes.hpp"
#include "util/cpu.hpp"
#include "util/executor.hpp"

namespace crowddb::steer {
namespace {

constexpr std::size_t kBuildGrain = 8192;  // rows per chunk of the grid's build
constexpr double kMinCell = 1;             // [m] about half the lane's width
// Rows per cell at the mean density. Larger cells mean fewer bands per lane and more rows per
// band (filtered without branches). Measured on airport-20k (keeping to a side, ms per 100 ticks,
// one thread, min of 4 interleaved): 0.5 -> 278, 1 -> 247, 2 -> 227, 4 -> 208, 8 -> 218; at 10^6
// rows (2 threads, 5 ticks) the build and probes 250 + 379 ms at 0.5, 240 + 297 at 4.
constexpr double kRowsPerCell = 4;
constexpr uint32_t kBatch = 32;  // rows filtered at once before any is asked in full

// The lane's rectangle over a band of cells: its corners in order round it, from the lowest (b)
// to the opposite one (t, the highest), run two chains, each through one of the other two
// corners (m); along a chain x is linear in y on either side of m. Each m is its chain's extreme
// in x: the corners are right angles, so the two edges out of b both rise and step in x to
// opposite sides, and each chain runs on parallel to the other's first edge. So over a band, the
// left boundary is least, and the right one greatest, where the band comes nearest its middle
// corner's height: each chain is read once, at its m's height clamped into the band, and the
// lesser of the two readings is the band's least x, the greater its greatest, whichever chain is
// the left one. (It replaced clipping the four edges to every band: the lanes' geometry was most of
// what a look-ahead finding nobody costs.) Read only within [y_b, y_t], where each reading
// interpolates between two corners: rounding may leave a middle corner a hair above t, and the
// lanes' margin covers that sliver.
struct Chain {
  double xm, ym;        // its middle corner
  double below, above;  // dx / dy from b to m and from m to t (0 where level or not finite)
  double at(double y) const { return xm + (y - ym) * (y <= ym ? below : above); }
};

double chain_slope(double x0, double y0, double x1, double y1) {
  const double dy = y1 - y0;
  const double s = dy != 0 ? (x1 - x0) / dy : 0.0;
  // A level segment, or one so nearly level that the quotient overflows, is read as m's own x
  // wherever it is read: m being its chain's extreme, never a narrower range.
  return std::isfinite(s) ? s : 0.0;
}

// The larger, or NaN when either is (std::max would drop a NaN in its second argument): the
// widest radius bounds every lane, and a NaN must not leave it narrower.
double widest(double a, double b) {
  return a != a || b != b ? NAN : std::max(a, b);
}

// A pseudo-angle of direction (x, y), not both zero: in [0, 4), increasing with the angle from
// the x axis counter-clockwise (the "diamond angle": cheaper than atan2, and only its order is
// used). Its sixteenth (0..15) is a row's heading class.
double diamond_angle(double x, double y) {
  const double s = std::abs(x) + std::abs(y);
  if (y >= 0) return x >= 0 ? y / s : 1 - x / s;
  return x < 0 ? 2 - y / s : 3 + x / s;
}

}  // namespace

int heading_class_reference(double x, double y) {
  return std::min(15, static_cast<int>(diamond_angle(x, y) * 4));
}

namespace {

// diamond_angle(x, y) * scale, truncated, without branches (which quadrant a wish points into is
// a coin toss to the predictor, and every row asks once a tick). In each quadrant diamond_angle
// adds a base to a numerator over s that is |y| or |x|: 1 - x / s is 1 + |x| / s exactly for
// x < 0, 2 - y / s is 2 + |y| / s, and y / s, 3 + x / s differ from 0 + |y| / s, 3 + |x| / s only
// in the sign of a zero numerator, which the truncation does not see. So the same bin, from
// integer selects.
int diamond_bin(double x, double y, double scale) {
  const double ax = std::abs(x), ay = std::abs(y), s = ax + ay;
  const uint64_t up = y >= 0, right = x >= 0;    // (x < 0 is !right: the heading is never NaN)
  const uint64_t pick_y = 0 - (up ^ right ^ 1);  // all ones in the quadrants that divide |y|
  const double q = std::bit_cast<double>((std::bit_cast<uint64_t>(ay) & pick_y) |
                                         (std::bit_cast<uint64_t>(ax) & ~pick_y));
  const auto base = static_cast<double>(2 * (up ^ 1) + (up ^ right));
  return static_cast<int>((base + q / s) * scale);
}

// opposite_classes' table: one mask per 1/256 of the diamond angle, the union of
// opposite_classes_exact over that bin and the bins on either side (a wish binned into a
// neighbour by rounding is still covered), drawn at 16 directions per bin. An arc's ends move
// with the direction, less than a class between two of them, so the union has no gap. Built on
// first use (about 12,000 exact masks).
constexpr int kOppositeBins = 256;
struct OppositeTable {
  uint16_t mask[kOppositeBins] = {};
  OppositeTable() {
    constexpr int kSteps = 16;
    for (int b = 0; b < kOppositeBins; ++b)
      for (int k = -kSteps; k <= 2 * kSteps; ++k) {
        // The direction at diamond angle a (its quadrant q, fraction f), on the unit diamond.
        double a = (b + static_cast<double>(k) / kSteps) * (4.0 / kOppositeBins);
        a = a < 0 ? a + 4 : (a >= 4 ? a - 4 : a);
        const int q = std::min(3, static_cast<int>(a));
        const double f = a - q;
        const double x[4] = {1 - f, -f, f - 1, f}, y[4] = {f, 1 - f, -f, f - 1};
        const double len = std::hypot(x[q], y[q]);
        mask[b] |= opposite_classes_exact(x[q] / len, y[q] / len);
      }
  }
};

}  // namespace

int heading_class(double x, double y) {
  return std::min(15, diamond_bin(x, y, 4));
}

uint16_t opposite_classes_exact(double ux, double uy) {
  constexpr double kArc = (60.0 + 2.0) * std::numbers::pi / 180;
  const double c = std::cos(kArc), s = std::sin(kArc);
  const double bx = -ux, by = -uy;
  const int from = heading_class(bx * c + by * s, -bx * s + by * c);  // turned clockwise
  const int to = heading_class(bx * c - by * s, bx * s + by * c);     // counter-clockwise
  uint16_t mask = 0;
  for (int k = from;; k = (k + 1) % 16) {
    mask |= static_cast<uint16_t>(1u << k);
    if (k == to) break;
  }
  return mask;
}

uint16_t opposite_classes(double ux, double uy) {
  static const OppositeTable table;
  return table.mask[std::min(kOppositeBins - 1, diamond_bin(ux, uy, kOppositeBins / 4))];
}

#if (CROWDDB_PASSING_AVX2 && !defined(__AVX2__)) || \
    (CROWDDB_PASSING_AVX2_NATIVE && defined(__AVX2__))
#define CROWDDB_PASSING_DISPATCH 1
// passing_lanes_avx2.cpp: whole vectors of four (see kPassingPad).
uint32_t passing_filter_avx2(const PassingColumns& c, uint32_t lo, uint32_t hi, const LaneQuery& q,
                             double same_way2, double side_reach, uint32_t* pick);
#endif

bool passing_lanes_avx2() {
#if CROWDDB_PASSING_DISPATCH
  return cpu_has_avx2();
#else
  return false;
#endif
}

uint32_t passing_filter_lanes(const PassingColumns& c, uint32_t lo, uint32_t hi, const LaneQuery& q,
                              double same_way2, double side_reach, uint32_t* pick,
                              PassingLanes lanes) {
#if CROWDDB_PASSING_DISPATCH
  if (lanes == PassingLanes::widest && passing_lanes_avx2())
    return passing_filter_avx2(c, lo, hi, q, same_way2, side_reach, pick);
#else
  (void)lanes;
#endif
  return passing_filter(c, lo, hi, q, same_way2, side_reach, pick);
}

bool passing_ahead_naive(const PassingView& v, std::size_t i, double ux, double uy, double look) {
  for (std::size_t j = 0; j < v.x.size(); ++j)
    if (j != i && passing(v, i, j, ux, uy, look)) return true;
  return false;
}

// The cells by a product with the inverse cell, clamped into the grid (the lane's margins cover
// its rounding).
inline int64_t PassingLookahead::col(double x) const {
  return index::cell_by_product(x - x0_, inv_cell_, W_);
}

inline int64_t PassingLookahead::row(double y) const {
  return index::cell_by_product(y - y0_, inv_cell_, H_);
}

// A counting sort into cells (index/row_buckets.hpp): the bounding box, each row's cell and
// heading class, and the copies in chunks on every thread; the placement and the cells' masks in
// one pass in row order (the layout is that of one thread).
void PassingLookahead::build(const PassingView& v, Executor& ex) {
  const std::size_t n = v.x.size();
  rows_.resize(n);
  if (n == 0) {
    start_.assign(2, 0);
    classes_.assign(1, 0);
    W_ = H_ = 1;
    return;
  }
  const auto [xmin, ymin, xmax, ymax] = index::bounding_box(v.x, v.y, ex);
  const double w = std::max(xmax - xmin, 1e-9), h = std::max(ymax - ymin, 1e-9);
  // About kRowsPerCell rows per cell at the mean density, and at least kMinCell. Bounded by the
  // rows, however sparse, large or thin the world: with c the cell, w h / c^2 <= n / 4 and
  // w / c, h / c <= 2n, so W H <= (w / c + 2)(h / c + 2) <= n / 4 + 2 (2n + 2n) + 4 < 9n + 4.
  const auto rows = static_cast<double>(n);
  double cell =
      std::max({kMinCell, std::sqrt(kRowsPerCell * w * h / rows), std::max(w, h) / (2 * rows)});
  if (!std::isfinite(cell)) cell = std::max(w, h);
  x0_ = xmin;
  y0_ = ymin;
  cell_ = cell;
  inv_cell_ = 1 / cell;
  W_ = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(w / cell)) + 1);
  H_ = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(h / cell)) + 1);
  const auto cells = static_cast<std::size_t>(W_ * H_);
  cell_of_.resize(n);
  class_of_.resize(n);
  std::vector<double> chunk_rmax((n + kBuildGrain - 1) / kBuildGrain, 0);
  ex.for_each_chunk(n, kBuildGrain, [&](std::size_t b, std::size_t e) {
    double rm = 0;  // the chunk's, written once at its end (the entries share cache lines)
    for (std::size_t i = b; i < e; ++i) {
      rm = widest(rm, v.radius[i]);
      cell_of_[i] = row(v.y[i]) * W_ + col(v.x[i]);
      // The row's heading class as a bit; standing rows pass nobody. A wish so small or so
      // large that its square leaves the doubles' range makes passing()'s angle test
      // meaningless (0 >= 0): such a row may be passing in any direction.
      const double wx = v.wish_x[i], wy = v.wish_y[i], w2 = wx * wx + wy * wy;
      class_of_[i] = wx == 0 && wy == 0 ? uint16_t{0}
                     : w2 > 1e-280 && w2 < 1e280
                         ? static_cast<uint16_t>(1u << heading_class(wx, wy))
                         : uint16_t{0xFFFF};
    }
    chunk_rmax[b / kBuildGrain] = rm;
  });
  rmax_ = 0;
  for (const double r : chunk_rmax) rmax_ = widest(rmax_, r);
  index::bucket_rows(cell_of_, cells, start_, rows_);
  for (auto* c : {&cx_, &cy_, &cr_, &cwx_, &cwy_}) c->resize(n + kPassingPad, 0.0);
  ex.for_each_chunk(n, kBuildGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t a = b; a < e; ++a) {
      const uint32_t i = rows_[a];
      cx_[a] = v.x[i];
      cy_[a] = v.y[i];
      cr_[a] = v.radius[i];
      cwx_[a] = v.wish_x[i];
      cwy_[a] = v.wish_y[i];
    }
  });
  classes_.assign(cells, 0);
  for (std::size_t i = 0; i < n; ++i)
    classes_[static_cast<std::size_t>(cell_of_[i])] |= class_of_[i];
}

uint32_t PassingLookahead::find(const PassingView& v, std::size_t i, double ux, double uy,
                                double look, uint64_t& tests, uint32_t hint) const {
  if (rows_.size() < 2 || look <= 0) return kNobody;
  if (hint < rows_.size() && hint != i) {
    ++tests;
    if (passing(v, i, hint, ux, uy, look)) return hint;
  }
  const double px = v.x[i], py = v.y[i];
  // Nobody lies farther than the grid's farthest corner: no need to draw the lane longer.
  const double gx =
      std::max(std::abs(px - x0_), std::abs(x0_ + static_cast<double>(W_) * cell_ - px));
  const double gy =
      std::max(std::abs(py - y0_), std::abs(y0_ + static_cast<double>(H_) * cell_ - py));
  const double len = std::min(look, gx + gy);
  const double ri = v.radius[i];
  const double half = ri + rmax_ + kSideReach;
  if (!(half < INFINITY && look == look)) {
    // A radius or a look that is not a finite number (not from a validated scene) leaves the
    // lane without a shape, and passing() without a bound across or ahead: every row is asked.
    for (std::size_t j = 0; j < rows_.size(); ++j) {
      ++tests;
      if (j != i && passing(v, i, j, ux, uy, look)) return static_cast<uint32_t>(j);
    }
    return kNobody;
  }
  const PassingColumns C{cx_.data(), cy_.data(), cr_.data(), cwx_.data(), cwy_.data()};
  const LaneQuery q{px, py, ux, uy, look, ri};
  const PassingLanes lanes = passing_lanes_avx2() ? PassingLanes::widest : PassingLanes::scalar;
  const uint16_t against = opposite_classes(ux, uy);
  // The lane ahead, widened by eps on every side against rounding: it decides only which rows
  // are looked at; passing() decides the answer.
  // The band edges y0 + cy cell round relative to the grid's origin and extent as well.
  const double eps = 1e-7 * (1 + std::abs(px) + std::abs(py) + len + half + std::abs(x0_) +
                             std::abs(y0_) + static_cast<double>(W_ + H_) * cell_);
  const double nx = -uy * (half + eps), ny = ux * (half + eps);
  const double bx = px - eps * ux, by = py - eps * uy;                          // back middle
  const double fx = bx + (len + 2 * eps) * ux, fy = by + (len + 2 * eps) * uy;  // front middle
  const double qx[4] = {bx + nx, bx - nx, fx - nx, fx + nx};
  const double qy[4] = {by + ny, by - ny, fy - ny, fy + ny};
  int lowest = 0;
  for (int c = 1; c < 4; ++c) lowest = qy[c] < qy[lowest] ? c : lowest;
  const int b = lowest, t = (lowest + 2) & 3;
  Chain chains[2];
  for (int k = 0; k < 2; ++k) {
    const int m = (b + 1 + 2 * k) & 3;
    chains[k] = {qx[m], qy[m], chain_slope(qx[b], qy[b], qx[m], qy[m]),
                 chain_slope(qx[m], qy[m], qx[t], qy[t])};
  }
  const double yb = qy[b], yt = qy[t];
  const int64_t cy0 = row(yb - eps);
  const int64_t cy1 = row(std::max({qy[0], qy[1], qy[2], qy[3]}) + eps);
  for (int64_t cy = cy0; cy <= cy1; ++cy) {
    // The band of cells; the grid's edge bands reach to infinity (row() clamps into them).
    const double ylo = cy == 0 ? -INFINITY : y0_ + static_cast<double>(cy) * cell_ - eps;
    const double yhi = cy == H_ - 1 ? INFINITY : y0_ + static_cast<double>(cy + 1) * cell_ + eps;
    const double ya = std::max(ylo, yb), yz = std::min(yhi, yt);
    if (ya > yz) continue;
    const double x0 = chains[0].at(std::clamp(chains[0].ym, ya, yz));
    const double x1 = chains[1].at(std::clamp(chains[1].ym, ya, yz));
    const double xmin = std::min(x0, x1), xmax = std::max(x0, x1);
    // The band's cells from xmin to xmax hold one run of rows in memory; it is read only when
    // one of them holds a heading coming towards the query. passing()'s first three tests on
    // the copies (passing_lanes.hpp): the same expressions on the same values, so a row they
    // reject passing() would reject too. The few left are asked in full.
    const auto base = static_cast<std::size_t>(cy * W_);
    const std::size_t c0 = base + static_cast<std::size_t>(col(xmin - eps));
    const std::size_t c1 = base + static_cast<std::size_t>(col(xmax + eps));
    uint16_t held = 0;
    for (std::size_t c = c0; c <= c1; ++c) held |= classes_[c];
    if (!(held & against)) continue;
    {
      const uint32_t lo = start_[c0], hi = start_[c1 + 1];
      tests += hi - lo;
      for (uint32_t a0 = lo; a0 < hi; a0 += kBatch) {
        const uint32_t a1 = std::min(hi, a0 + kBatch);
        uint32_t pick[kBatch + kPassingPad];
        const uint32_t m =
            passing_filter_lanes(C, a0, a1, q, kSameWay * kSameWay, kSideReach, pick, lanes);
        for (uint32_t u = 0; u < m; ++u) {
          const uint32_t j = rows_[pick[u]];
          if (j != i && passing(v, i, j, ux, uy, look)) return j;
        }
      }
    }
  }
  return kNobody;
}

}  // namespace crowddb::steer
