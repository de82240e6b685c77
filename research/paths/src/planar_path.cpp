#include "craneassist/paths/planar_path.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace craneassist::paths {

CompositeBezierPath::CompositeBezierPath(const std::vector<Eigen::Vector2d>& via) {
  const std::size_t m = via.size();
  if (m < 2) throw std::invalid_argument("a Bezier path needs at least 2 via points");
  for (std::size_t i = 1; i < m; ++i) {
    if (!((via[i] - via[i - 1]).norm() > 0.0)) {
      throw std::invalid_argument("a Bezier path's consecutive via points must differ");
    }
  }
  // Natural-spline junction tangents: tridiagonal system, solved by the Thomas algorithm.
  std::vector<double> a(m, 1.0), b(m, 4.0), c(m, 1.0);
  std::vector<Eigen::Vector2d> r(m), d(m);
  b.front() = 2.0;
  b.back() = 2.0;
  a.front() = 0.0;
  c.back() = 0.0;
  r.front() = 3.0 * (via[1] - via[0]);
  r.back() = 3.0 * (via[m - 1] - via[m - 2]);
  for (std::size_t i = 1; i + 1 < m; ++i) r[i] = 3.0 * (via[i + 1] - via[i - 1]);
  for (std::size_t i = 1; i < m; ++i) {
    const double w = a[i] / b[i - 1];
    b[i] -= w * c[i - 1];
    r[i] -= w * r[i - 1];
  }
  d[m - 1] = r[m - 1] / b[m - 1];
  for (std::size_t i = m - 1; i-- > 0;) d[i] = (r[i] - c[i] * d[i + 1]) / b[i];
  control_.resize(m - 1);
  for (std::size_t i = 0; i + 1 < m; ++i) {
    control_[i] = {via[i], via[i] + d[i] / 3.0, via[i + 1] - d[i + 1] / 3.0, via[i + 1]};
  }
  // Arc length (Simpson).
  const int panels = 64 * segments();
  const double h = 1.0 / panels;
  Point pt;
  double sum = 0.0;
  for (int k = 0; k <= panels; ++k) {
    evaluate(k * h, pt);
    const double w = (k == 0 || k == panels) ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0);
    sum += w * pt.d1.norm();
  }
  length_m_ = sum * h / 3.0;
}

void CompositeBezierPath::evaluate(double s, Point& out) const noexcept {
  const int n = segments();
  const double x = std::clamp(std::isnan(s) ? 0.0 : s, 0.0, 1.0) * n;
  const int i = std::min(static_cast<int>(x), n - 1);
  const double u = x - i;
  const auto& b = control_[static_cast<std::size_t>(i)];
  const double v = 1.0 - u;
  out.p = v * v * v * b[0] + 3.0 * v * v * u * b[1] + 3.0 * v * u * u * b[2] + u * u * u * b[3];
  // d/ds = n d/du.
  out.d1 = 3.0 * n * (v * v * (b[1] - b[0]) + 2.0 * v * u * (b[2] - b[1]) + u * u * (b[3] - b[2]));
  out.d2 = 6.0 * n * n * (v * (b[2] - 2.0 * b[1] + b[0]) + u * (b[3] - 2.0 * b[2] + b[1]));
}

void offset_reference(const CompositeBezierPath& path, double offset_m, double s,
                      OffsetReference& out) noexcept {
  CompositeBezierPath::Point pt;
  path.evaluate(s, pt);
  const double speed2 = pt.d1.squaredNorm();
  const double speed = std::sqrt(speed2);
  out.phi_rad = std::atan2(pt.d1.y(), pt.d1.x());                                  // eq. 7
  out.omega_prime_rad = (pt.d1.x() * pt.d2.y() - pt.d1.y() * pt.d2.x()) / speed2;  // eq. 8
  const Eigen::Vector2d normal(-std::sin(out.phi_rad), std::cos(out.phi_rad));
  out.tool = pt.p;
  out.platform = pt.p - offset_m * normal;
  out.v_prime_m = speed + offset_m * out.omega_prime_rad;  // eq. 9 on the offset path
}

OffsetPathCheck check_offset_path(const CompositeBezierPath& path, double offset_m, int samples) {
  OffsetPathCheck check;
  check.min_v_prime_m = 1e300;
  OffsetReference r;
  // Every segment gets its share, however many there are (a long path's tight turn lies within
  // one segment).
  const int n = std::max(samples, kMinOffsetSamplesPerSegment * path.segments());
  for (int k = 0; k <= n; ++k) {
    const double s = static_cast<double>(k) / n;
    offset_reference(path, offset_m, s, r);
    // A NaN (the tool path stands still) is kept as the lowest: no path to follow there.
    if (std::isnan(r.v_prime_m) ? !std::isnan(check.min_v_prime_m)
                                : r.v_prime_m < check.min_v_prime_m) {
      check.min_v_prime_m = r.v_prime_m;
      check.min_v_prime_s = s;
    }
    if (r.v_prime_m > 0.0) {
      const double kappa = std::abs(r.omega_prime_rad / r.v_prime_m);
      if (kappa > check.max_curvature_1_m) {
        check.max_curvature_1_m = kappa;
        check.max_curvature_s = s;
      }
    }
  }
  return check;
}

}  // namespace craneassist::paths
