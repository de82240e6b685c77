#include "craneassist/input/prescribed_path.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <ostream>
#include <stdexcept>
#include <utility>

#include "csv_reader.hpp"
#include "text_fields.hpp"

namespace craneassist::input {
namespace {

using Limits = PrescribedPathLimits;

// Quintic rest-to-rest s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5: peak of ds/dtau, at tau = 1/2.
constexpr double kQuinticPeakRate = 1.875;
// Samples per spline segment for the peak speed and the arc length (even, for Simpson's rule).
constexpr int kSamplesPerSegment = 512;

using detail::format_number;
using detail::kMaxNumberChars;
using detail::number;

// ---- the file format: the shared CSV rules (csv_reader.hpp) and the via-point limits ----------

detail::CsvFormat make_path_format() {
  detail::CsvFormat format;
  format.columns = {{"t", detail::CsvKind::kTime},
                    {"x", detail::CsvKind::kNumber, Limits::kMaxCoordinateM, "m"},
                    {"y", detail::CsvKind::kNumber, Limits::kMaxCoordinateM, "m"},
                    {"z", detail::CsvKind::kNumber, Limits::kMaxCoordinateM, "m"}};
  format.max_rows = Limits::kMaxViaPoints;
  format.min_time_step_s = Limits::kMinTimeStepS;
  return format;
}

const detail::CsvFormat& path_format() {
  static const detail::CsvFormat format = make_path_format();
  return format;
}

// ---- via-point rules for from_via_points (the reader applies the same limits by path_format) ---

// Empty when t is acceptable after previous (nullptr for the first via point), else the reason.
std::string time_problem(double t, const double* previous) {
  if (!std::isfinite(t)) return "not a finite number";
  if (t < 0.0) return "negative time: " + number(t) + " s";
  if (previous != nullptr) {
    if (!(t > *previous)) {
      return "time not strictly increasing: " + number(t) + " s follows " + number(*previous) +
             " s";
    }
    if (t - *previous < Limits::kMinTimeStepS) {
      return "time step of " + number(t - *previous) + " s after " + number(*previous) +
             " s is below the minimum of " + number(Limits::kMinTimeStepS) + " s";
    }
  }
  return {};
}

std::string coordinate_problem(double c) {
  if (!std::isfinite(c)) return "not a finite number";
  if (std::abs(c) > Limits::kMaxCoordinateM) {
    return "magnitude of " + number(c) + " m exceeds the limit of " +
           number(Limits::kMaxCoordinateM) + " m";
  }
  return {};
}

// ---- clamped cubic spline ----------------------------------------------------------------------

// Second derivatives M_i at the knots of the cubic spline through (t_i, p_i) with zero first
// derivative at both ends (all three coordinates at once; tridiagonal, Thomas algorithm; the
// system is strictly diagonally dominant).
std::vector<Eigen::Vector3d> clamped_spline_accelerations(const std::vector<double>& t,
                                                          const std::vector<Eigen::Vector3d>& p) {
  const std::size_t n = t.size();
  std::vector<double> sub(n, 0.0), diag(n, 0.0), super(n, 0.0);
  std::vector<Eigen::Vector3d> rhs(n, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double h = t[i + 1] - t[i];
    const Eigen::Vector3d slope = (p[i + 1] - p[i]) / h;
    // Segment i contributes to rows i and i + 1.
    diag[i] += 2.0 * h;
    super[i] = h;
    rhs[i] += 6.0 * slope;
    sub[i + 1] = h;
    diag[i + 1] += 2.0 * h;
    rhs[i + 1] -= 6.0 * slope;
  }
  // Forward elimination, back substitution.
  for (std::size_t i = 1; i < n; ++i) {
    const double w = sub[i] / diag[i - 1];
    diag[i] -= w * super[i - 1];
    rhs[i] -= w * rhs[i - 1];
  }
  std::vector<Eigen::Vector3d> m(n);
  m[n - 1] = rhs[n - 1] / diag[n - 1];
  for (std::size_t i = n - 1; i-- > 0;) m[i] = (rhs[i] - super[i] * m[i + 1]) / diag[i];
  return m;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

PrescribedPath PrescribedPath::from_via_points(std::vector<double> t_s,
                                               std::vector<Eigen::Vector3d> p_m) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("PrescribedPath::from_via_points: " + what);
  };
  if (t_s.size() != p_m.size()) {
    fail(std::to_string(t_s.size()) + " times but " + std::to_string(p_m.size()) + " points");
  }
  if (t_s.size() < 2) fail("a path needs at least 2 via points, got " + std::to_string(t_s.size()));
  if (t_s.size() > Limits::kMaxViaPoints) {
    fail("too many via points (limit " + std::to_string(Limits::kMaxViaPoints) + ")");
  }
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    const std::string problem = time_problem(t_s[i], i == 0 ? nullptr : &t_s[i - 1]);
    if (!problem.empty()) fail("via point " + std::to_string(i) + ": t: " + problem);
    for (Eigen::Index k = 0; k < 3; ++k) {
      const std::string c = coordinate_problem(p_m[i][k]);
      if (!c.empty()) {
        fail("via point " + std::to_string(i) + ": " +
             path_format().columns[static_cast<std::size_t>(k) + 1].name + ": " + c);
      }
    }
  }
  return PrescribedPath(std::move(t_s), std::move(p_m));
}

PrescribedPath::PrescribedPath(std::vector<double> t_s, std::vector<Eigen::Vector3d> p_m)
    : t_s_(std::move(t_s)), p_m_(std::move(p_m)) {
  if (t_s_.size() == 2) {
    const double distance_m = (p_m_[1] - p_m_[0]).norm();
    length_m_ = distance_m;
    peak_speed_m_s_ = kQuinticPeakRate * distance_m / duration_s();
    return;
  }
  a_knot_m_s2_ = clamped_spline_accelerations(t_s_, p_m_);
  for (std::size_t i = 0; i + 1 < t_s_.size(); ++i) {
    const double h = t_s_[i + 1] - t_s_[i];
    const double du = h / kSamplesPerSegment;
    // Simpson's rule on the speed for the length; the best sample, refined by golden-section
    // search between its neighbours, for the peak speed.
    double simpson = 0.0;
    int best = 0;
    double best_speed = -1.0;
    for (int k = 0; k <= kSamplesPerSegment; ++k) {
      const double speed = segment_speed(i, k * du);
      const double weight = (k == 0 || k == kSamplesPerSegment) ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0);
      simpson += weight * speed;
      if (speed > best_speed) {
        best_speed = speed;
        best = k;
      }
    }
    length_m_ += simpson * du / 3.0;
    double lo = std::max(0, best - 1) * du, hi = std::min(kSamplesPerSegment, best + 1) * du;
    const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int iteration = 0; iteration < 60; ++iteration) {
      const double a = hi - ratio * (hi - lo), b = lo + ratio * (hi - lo);
      if (segment_speed(i, a) < segment_speed(i, b)) {
        lo = a;
      } else {
        hi = b;
      }
    }
    best_speed = std::max(best_speed, segment_speed(i, 0.5 * (lo + hi)));
    peak_speed_m_s_ = std::max(peak_speed_m_s_, best_speed);
  }
}

PrescribedPathPoint PrescribedPath::segment_point(std::size_t i, double u) const noexcept {
  // On [t_i, t_i+1], u = t - t_i: p = p_i + b u + M_i u^2 / 2 + (M_i+1 - M_i) u^3 / (6 h) with
  // b = (p_i+1 - p_i) / h - h (2 M_i + M_i+1) / 6.
  const double h = t_s_[i + 1] - t_s_[i];
  const Eigen::Vector3d& m0 = a_knot_m_s2_[i];
  const Eigen::Vector3d& m1 = a_knot_m_s2_[i + 1];
  const Eigen::Vector3d jerk = (m1 - m0) / h;
  const Eigen::Vector3d b = (p_m_[i + 1] - p_m_[i]) / h - h * (2.0 * m0 + m1) / 6.0;
  PrescribedPathPoint out;
  out.p_m = p_m_[i] + u * (b + u * (0.5 * m0 + u * jerk / 6.0));
  out.v_m_s = b + u * (m0 + 0.5 * u * jerk);
  out.a_m_s2 = m0 + u * jerk;
  return out;
}

double PrescribedPath::segment_speed(std::size_t i, double u) const noexcept {
  return segment_point(i, u).v_m_s.norm();
}

PrescribedPathPoint PrescribedPath::at(double t_s) const noexcept {
  PrescribedPathPoint out;
  if (std::isnan(t_s) || t_s < t_s_.front()) {
    out.p_m = p_m_.front();
    return out;
  }
  if (t_s > t_s_.back()) {
    out.p_m = p_m_.back();
    return out;
  }
  if (t_s_.size() == 2) {
    // Quintic rest-to-rest: s = 10 tau^3 - 15 tau^4 + 6 tau^5 from 0 to 1.
    const double duration = duration_s();
    const double tau = (t_s - t_s_[0]) / duration;
    const double s = tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
    const double ds = 30.0 * tau * tau * (1.0 + tau * (-2.0 + tau)) / duration;
    const double dds = 60.0 * tau * (1.0 + tau * (-3.0 + 2.0 * tau)) / (duration * duration);
    const Eigen::Vector3d delta = p_m_[1] - p_m_[0];
    out.p_m = p_m_[0] + s * delta;
    out.v_m_s = ds * delta;
    out.a_m_s2 = dds * delta;
    return out;
  }
  if (t_s == t_s_.back()) {
    // The end knot: the clamped end condition exactly, the spline's (non-zero) acceleration.
    out = segment_point(t_s_.size() - 2, t_s_.back() - t_s_[t_s_.size() - 2]);
    out.p_m = p_m_.back();
    out.v_m_s.setZero();
    return out;
  }
  // Segment i with t_i <= t < t_i+1.
  const auto after = std::upper_bound(t_s_.begin(), t_s_.end(), t_s);
  const auto i = static_cast<std::size_t>(after - t_s_.begin()) - 1;
  return segment_point(i, t_s - t_s_[i]);
}

PrescribedPath PrescribedPath::parse(std::string_view text, std::string_view source_name) {
  std::vector<double> t_s;
  std::vector<Eigen::Vector3d> p_m;
  const detail::CsvFile file =
      detail::read_csv(text, source_name, path_format(), [&](const detail::CsvRow& row) {
        t_s.push_back(row.values[0]);
        p_m.emplace_back(row.values[1], row.values[2], row.values[3]);
      });
  if (t_s.size() < 2) {
    throw FileError(std::string(source_name), file.last_line, "",
                    "a path needs at least 2 via points, got " + std::to_string(t_s.size()));
  }
  return PrescribedPath(std::move(t_s), std::move(p_m));
}

PrescribedPath PrescribedPath::load_file(const std::filesystem::path& path) {
  return parse(detail::read_file_text(path, "tip path"), path.string());
}

void write_prescribed_path(std::ostream& out, const PrescribedPath& path,
                           std::string_view comment) {
  std::string line;
  while (!comment.empty()) {
    const std::size_t end = comment.find('\n');
    std::string_view part = comment.substr(0, end);
    if (!part.empty() && part.back() == '\r') part.remove_suffix(1);
    out << '#';
    if (!part.empty()) out << ' ' << part;
    out << '\n';
    if (end == std::string_view::npos) break;
    comment.remove_prefix(end + 1);
  }
  out << detail::csv_header(path_format()) << '\n';
  std::array<char, kMaxNumberChars> buffer{};
  for (std::size_t i = 0; i < path.via_times_s().size(); ++i) {
    line.clear();
    line += format_number(path.via_times_s()[i], buffer);
    for (Eigen::Index k = 0; k < 3; ++k) {
      line += ',';
      line += format_number(path.via_points_m()[i][k], buffer);
    }
    line += '\n';
    out << line;
  }
}

}  // namespace craneassist::input
