// Prescribed boom-tip paths in time: via points from a CSV file (t,x,y,z), interpolated into tip
// position, velocity and acceleration at any time; the input of an offline redundancy planner.
// The format and the interpolation rules are specified in docs/path-format.md.
//
// Not to be confused with craneassist::scaling::TipPath, the per-cycle path-velocity
// decomposition of the joystick command: this is a whole path known in advance.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/input/file_error.hpp"

namespace craneassist::input {

// Tip state on a prescribed path, crane frame (x forward, y up, z lateral; origin as in the crane
// model).
struct PrescribedPathPoint {
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_m_s2 = Eigen::Vector3d::Zero();
};

// Rules on via points, shared by the reader and PrescribedPath::from_via_points.
struct PrescribedPathLimits {
  static constexpr double kMaxCoordinateM = 100.0;  // |x|, |y|, |z| at most this
  static constexpr double kMinTimeStepS = 1e-3;     // consecutive via times at least this apart
  static constexpr std::size_t kMaxViaPoints = 100'000;
};

// A tip path through via points (t_i, p_i): the tip passes p_i at time t_i.
//  - 2 via points: a straight line with a quintic rest-to-rest time law (Jazar): zero velocity
//    and acceleration at both ends, peak speed 1.875 L / T at mid-time.
//  - 3 or more: a cubic spline in time through the via points, each coordinate separately,
//    clamped with zero velocity at both ends (C2 inside; the acceleration at the ends is not
//    zero).
// Immutable and cheap to query: at() does not allocate and costs O(log n) in the via points.
class PrescribedPath {
 public:
  enum class Interpolation { kQuinticLine, kClampedCubicSpline };

  // Reads and validates a file; the source name in errors is path.string(). Throws FileError (the
  // field is the column: "t", "x", "y", "z").
  static PrescribedPath load_file(const std::filesystem::path& path);
  // Validates text in the path format; source_name is used in error messages. Throws FileError.
  static PrescribedPath parse(std::string_view text, std::string_view source_name);
  // Throws std::invalid_argument unless: equal sizes, at least 2 and at most kMaxViaPoints via
  // points, times finite, first >= 0, each at least kMinTimeStepS after the previous, coordinates
  // finite and within kMaxCoordinateM.
  static PrescribedPath from_via_points(std::vector<double> t_s, std::vector<Eigen::Vector3d> p_m);

  double start_time_s() const noexcept { return t_s_.front(); }
  double end_time_s() const noexcept { return t_s_.back(); }
  double duration_s() const noexcept { return t_s_.back() - t_s_.front(); }
  Interpolation interpolation() const noexcept {
    return t_s_.size() == 2 ? Interpolation::kQuinticLine : Interpolation::kClampedCubicSpline;
  }

  // Tip state at time t_s. Before the start and after the end the tip rests at the first or last
  // via point (zero velocity and acceleration); a NaN time gives the start point at rest. At the
  // start and end times themselves the velocity is zero and the acceleration is the path's own
  // (zero for the quintic line, the spline's end value otherwise).
  PrescribedPathPoint at(double t_s) const noexcept;

  // Largest tip speed over the path (exact for the quintic line; for the spline from sampling
  // each segment finely and refining the best sample, to about 1e-9 relative).
  double peak_speed_m_s() const noexcept { return peak_speed_m_s_; }
  // Arc length of the tip path (exact for the quintic line; for the spline from Simpson's rule on
  // the speed, to about 1e-9 relative).
  double length_m() const noexcept { return length_m_; }

  const std::vector<double>& via_times_s() const noexcept { return t_s_; }
  const std::vector<Eigen::Vector3d>& via_points_m() const noexcept { return p_m_; }

 private:
  PrescribedPath(std::vector<double> t_s, std::vector<Eigen::Vector3d> p_m);
  // Tip speed on spline segment i at local time u in [0, h_i].
  double segment_speed(std::size_t i, double u) const noexcept;
  PrescribedPathPoint segment_point(std::size_t i, double u) const noexcept;

  std::vector<double> t_s_;
  std::vector<Eigen::Vector3d> p_m_;
  // Spline only: second derivatives (accelerations) at the via points.
  std::vector<Eigen::Vector3d> a_knot_m_s2_;
  double peak_speed_m_s_ = 0.0;
  double length_m_ = 0.0;
};

// Writes the optional comment (each of its lines as a '# ' line), the header and the via points in
// the path format ('\n' line endings, shortest round-trip number form): parse() reads them back
// bit-exactly.
void write_prescribed_path(std::ostream& out, const PrescribedPath& path,
                           std::string_view comment = {});

}  // namespace craneassist::input
