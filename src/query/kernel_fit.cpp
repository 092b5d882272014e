// Least-squares fit of A e^{-k x} to alpha / x on an interval (DESIGN.md §4, thesis §2.2).
//
// Norm: the continuous L2 norm on [from, to] by composite 8-point Gauss-Legendre quadrature over
// geometrically growing panels (1/x is steep at the left end), or a discrete sum over equally
// spaced samples. Variable projection: for fixed k the best A is the linear least-squares
// solution A(k) = N(k) / D(k) with N = sum w e^{-kx} alpha/x and D = sum w e^{-2kx}, leaving the
// one-dimensional objective F(k) = sum w (alpha/x)^2 - N^2 / D. k is bracketed by a log-spaced
// scan over [1e-3/to, 1e3/from], narrowed by golden-section search, and finished by bisection on
// the sign of F'(k), whose closed form is -(2 N N' D - N^2 D') / D^2.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "crowddb/error.hpp"
#include "crowddb/query.hpp"

namespace crowddb {
namespace {

struct Nodes {
  std::vector<double> x, w;
};

Nodes continuous_nodes(double a, double b) {
  // 8-point Gauss-Legendre on [-1, 1].
  static constexpr std::array<double, 4> t = {0.1834346424956498, 0.5255324099163290,
                                              0.7966664774136267, 0.9602898564975363};
  static constexpr std::array<double, 4> v = {0.3626837833783620, 0.3137066458778873,
                                              0.2223810344533745, 0.1012285362903763};
  constexpr int panels = 400;
  Nodes n;
  const double ratio = std::log(b / a) / panels;
  double lo = a;
  for (int p = 1; p <= panels; ++p) {
    const double hi = p == panels ? b : a * std::exp(ratio * p);
    const double mid = (lo + hi) / 2, half = (hi - lo) / 2;
    for (std::size_t i = 0; i < t.size(); ++i)
      for (double s : {-1.0, 1.0}) {
        n.x.push_back(mid + s * half * t[i]);
        n.w.push_back(half * v[i]);
      }
    lo = hi;
  }
  return n;
}

Nodes sample_nodes(double a, double b, int samples) {
  Nodes n;
  for (int i = 0; i < samples; ++i) {
    n.x.push_back(i == samples - 1 ? b : a + (b - a) * i / (samples - 1));
    n.w.push_back(1.0);
  }
  return n;
}

struct Reduced {
  double A, F, dF;
};

Reduced reduced(const Nodes& n, double alpha, double k) {
  double N = 0, D = 0, dN = 0, dD = 0;
  for (std::size_t i = 0; i < n.x.size(); ++i) {
    const double x = n.x[i], w = n.w[i], e = std::exp(-k * x);
    N += w * e * alpha / x;
    dN -= w * e * alpha;
    D += w * e * e;
    dD -= 2 * w * x * e * e;
  }
  const double A = D > 0 ? N / D : 0;
  double F = 0;
  for (std::size_t i = 0; i < n.x.size(); ++i) {
    const double r = A * std::exp(-k * n.x[i]) - alpha / n.x[i];
    F += n.w[i] * r * r;
  }
  const double dF = D > 0 ? -(2 * N * dN * D - N * N * dD) / (D * D) : 0;
  return {A, F, dF};
}

}  // namespace

KernelFit fit_exp_kernel(double from, double to, double alpha, int samples) {
  if (!std::isfinite(from) || !std::isfinite(to) || !(from > 0) || !(to > from))
    throw Error(Error::Kind::usage, "fit-kernel: need 0 < from < to, both finite");
  if (!std::isfinite(alpha) || !(alpha > 0))
    throw Error(Error::Kind::usage, "fit-kernel: alpha must be finite and > 0");
  if (samples == 1 || samples < 0)
    throw Error(Error::Kind::usage, "fit-kernel: samples must be 0 (continuous) or >= 2");
  const Nodes nodes = samples == 0 ? continuous_nodes(from, to) : sample_nodes(from, to, samples);

  // Scan.
  const double klo = 1e-3 / to, khi = 1e3 / from;
  constexpr int steps = 600;
  const double step = std::log(khi / klo) / steps;
  int best = 0;
  double best_f = INFINITY;
  for (int i = 0; i <= steps; ++i) {
    const double f = reduced(nodes, alpha, klo * std::exp(step * i)).F;
    if (f < best_f) {
      best_f = f;
      best = i;
    }
  }
  double a = klo * std::exp(step * std::max(0, best - 1)),
         b = klo * std::exp(step * std::min(steps, best + 1));
  // Golden section on F.
  const double g = (std::sqrt(5.0) - 1) / 2;
  for (int it = 0; it < 60; ++it) {
    const double c = b - g * (b - a), d = a + g * (b - a);
    if (reduced(nodes, alpha, c).F < reduced(nodes, alpha, d).F)
      b = d;
    else
      a = c;
  }
  // Bisection on the sign of F' when it brackets a root (F is flat at the minimum: the derivative
  // locates it to full precision where F itself cannot).
  double k = (a + b) / 2;
  double lo = a * 0.999, hi = b * 1.001;
  if (reduced(nodes, alpha, lo).dF < 0 && reduced(nodes, alpha, hi).dF > 0) {
    for (int it = 0; it < 200 && hi - lo > 1e-17 * hi; ++it) {
      const double mid = (lo + hi) / 2;
      (reduced(nodes, alpha, mid).dF < 0 ? lo : hi) = mid;
    }
    k = (lo + hi) / 2;
  }
  const Reduced r = reduced(nodes, alpha, k);
  KernelFit fit;
  fit.A = r.A;
  fit.k = k;
  double wsum = 0;
  for (double w : nodes.w) wsum += w;
  fit.rms_error = std::sqrt(r.F / wsum);
  constexpr int grid = 20000;
  for (int i = 0; i <= grid; ++i) {
    const double x = i == grid ? to : from + (to - from) * i / grid;
    const double err = std::abs(fit.A * std::exp(-fit.k * x) - alpha / x);
    fit.max_abs_error = std::max(fit.max_abs_error, err);
    fit.max_rel_error = std::max(fit.max_rel_error, err * x / alpha);
  }
  return fit;
}

}  // namespace crowddb
