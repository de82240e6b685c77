// A planar path p(s), s in [0, 1]: the composite C2 cubic Bezier curve through given via points
// ("Flow-limited path-following control of a double Ackermann steered hydraulic mobile
// manipulator", section IV, fig. 5), and the platform's offset path beside it (docs/mobile.md).
//
// Construction: segment i runs from via point P_i to P_i+1 over s in [i/n, (i+1)/n] with the
// Bezier control points P_i, P_i + D_i/3, P_i+1 - D_i+1/3, P_i+1, where the junction tangents
// D_i solve the natural-spline system (D_i-1 + 4 D_i + D_i+1 = 3 (P_i+1 - P_i-1), free ends):
// position, tangent and curvature are continuous at every junction (C2).
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

namespace craneassist::paths {

class CompositeBezierPath {
 public:
  // At least two via points, consecutive ones distinct; std::invalid_argument otherwise.
  explicit CompositeBezierPath(const std::vector<Eigen::Vector2d>& via_m);

  struct Point {
    Eigen::Vector2d p = Eigen::Vector2d::Zero();   // p(s)
    Eigen::Vector2d d1 = Eigen::Vector2d::Zero();  // p'(s)
    Eigen::Vector2d d2 = Eigen::Vector2d::Zero();  // p''(s)
  };
  // s clamped to [0, 1]; no allocation.
  void evaluate(double s, Point& out) const noexcept;

  int segments() const { return static_cast<int>(control_.size()); }
  // The four control points of each segment.
  const std::vector<std::array<Eigen::Vector2d, 4>>& control_points() const { return control_; }
  // Arc length, by Simpson's rule on 64 panels a segment.
  double length_m() const { return length_m_; }

 private:
  std::vector<std::array<Eigen::Vector2d, 4>> control_;
  double length_m_ = 0.0;
};

// The platform's reference at s on the path offset `offset_m` to the right of the tool path
// (the tool is offset_m to the left of the platform, left of its heading; negative: right):
// p_b(s) = p(s) - offset n(s), n the tool path's left normal. Both paths have the same heading
// phi_d(s) (eq. 7) and turn rate omega'(s) = dphi_d/ds (eq. 8); the platform's v'(s) = |p_b'(s)|
// (eq. 9) = |p'(s)| + offset omega'(s). v' <= 0 is a cusp of the offset path (the "pocket" the
// paper leaves out).
struct OffsetReference {
  Eigen::Vector2d tool = Eigen::Vector2d::Zero();      // p(s)
  Eigen::Vector2d platform = Eigen::Vector2d::Zero();  // p_b(s)
  double phi_rad = 0.0;                                // phi_d(s)
  double v_prime_m = 0.0;                              // v'(s), platform, m per unit s
  double omega_prime_rad = 0.0;                        // omega'(s), rad per unit s
};
void offset_reference(const CompositeBezierPath& path, double offset_m, double s,
                      OffsetReference& out) noexcept;

// Where the platform's offset path cannot be followed: the lowest v'(s) over s (a cusp at or
// below zero; NaN where the tool path itself stands still), and the highest |curvature|
// omega'/v' of the platform's path, each with its s, sampled `samples` times, at least
// kMinOffsetSamplesPerSegment times in every segment.
struct OffsetPathCheck {
  double min_v_prime_m = 0.0;
  double min_v_prime_s = 0.0;
  double max_curvature_1_m = 0.0;
  double max_curvature_s = 0.0;
};
inline constexpr int kMinOffsetSamplesPerSegment = 64;
OffsetPathCheck check_offset_path(const CompositeBezierPath& path, double offset_m,
                                  int samples = 4000);

}  // namespace craneassist::paths
