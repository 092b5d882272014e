// One pair's contribution to the potential field and its gradient (DESIGN.md §4), shared by the
// naive path and by indices that fall back to exact pair sums (leaves, near fields).
#pragma once

#include <cmath>
#include <numbers>

#include "crowddb/query.hpp"

namespace crowddb {

inline double sgn(double v) {
  return static_cast<double>((v > 0) - (v < 0));
}

// Precomputed per-spec constants.
struct PairKernel {
  explicit PairKernel(const PotentialSpec& s) : spec(s) {
    const int m = s.radial_frames;
    for (int j = 0; j < m && j < kMaxFrames; ++j) {
      const double th = j * std::numbers::pi / (2.0 * m);
      cos_[j] = std::cos(th);
      sin_[j] = std::sin(th);
    }
    radial_scale = std::numbers::pi / (4.0 * m);
  }

  // Adds c * K(d(p, q)) and its gradient w.r.t. p into (pot, gx, gy); dx = x_p - x_q.
  // `c` already holds A * c_p * c_q.
  void add(double dx, double dy, double c, double& pot, double& gx, double& gy) const {
    double d, ddx, ddy;  // distance and its gradient with respect to p
    switch (spec.metric) {
      case Metric::l1:
        d = std::fabs(dx) + std::fabs(dy);
        ddx = sgn(dx);
        ddy = sgn(dy);
        break;
      case Metric::l2:
        d = std::sqrt(dx * dx + dy * dy);
        ddx = d > 0 ? dx / d : 0.0;
        ddy = d > 0 ? dy / d : 0.0;
        break;
      case Metric::radial:
      default: {
        double s = 0, gxs = 0, gys = 0;
        for (int j = 0; j < spec.radial_frames; ++j) {
          const double u = dx * cos_[j] + dy * sin_[j];
          const double w = -dx * sin_[j] + dy * cos_[j];
          s += std::fabs(u) + std::fabs(w);
          gxs += sgn(u) * cos_[j] - sgn(w) * sin_[j];
          gys += sgn(u) * sin_[j] + sgn(w) * cos_[j];
        }
        d = radial_scale * s;
        ddx = radial_scale * gxs;
        ddy = radial_scale * gys;
        break;
      }
    }
    double k, dk;  // K(d) and K'(d)
    if (spec.kernel == Kernel::exp) {
      k = std::exp(-spec.k * d);
      dk = -spec.k * k;
    } else if (d > spec.inv_floor) {
      k = 1.0 / d;
      dk = -k * k;
    } else {
      k = 1.0 / spec.inv_floor;
      dk = 0;
    }
    pot += c * k;
    gx += c * dk * ddx;
    gy += c * dk * ddy;
  }

  static constexpr int kMaxFrames = 16;
  PotentialSpec spec;
  double cos_[kMaxFrames]{}, sin_[kMaxFrames]{};
  double radial_scale = 0;
};

}  // namespace crowddb
