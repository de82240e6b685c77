#include "craneassist/dynamics/null_space_resolution.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>

#include "craneassist/dynamics/hydraulics.hpp"

namespace craneassist::dynamics {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTinyComponent = 1e-12;  // a null-vector component this small is zero
constexpr double kSlack = 1e-12;          // bound tolerance on f
constexpr double kOuterTau = 1e3;         // |tau| searched when nothing else bounds it
constexpr int kSearchIterations = 80;     // golden-section / bisection steps (1e-17 of the box)
constexpr double kAtEndShare = 1e12;      // per unit rate of a joint moving into an end it is at
constexpr double kSanityFactor = 4.0;     // searches stay within this times the cylinder speeds

struct Interval {
  double lo = -kInf, hi = kInf;
  bool empty() const { return !(lo <= hi); }
  Interval cut(const Interval& other) const {
    return {std::max(lo, other.lo), std::min(hi, other.hi)};
  }
};

// The tau interval keeping lower <= p + tau n <= upper, joint by joint.
Interval linear_interval(const SolutionLine& line, const JointRateBounds& b) {
  Interval iv;
  for (Eigen::Index i = 0; i < line.p.size(); ++i) {
    const double lower = b.lower[i], upper = b.upper[i];
    if (std::abs(line.n[i]) <= kTinyComponent) {
      if (line.p[i] < lower - kSlack || line.p[i] > upper + kSlack) return {kInf, -kInf};
      continue;
    }
    double t1 = (lower - line.p[i]) / line.n[i];
    double t2 = (upper - line.p[i]) / line.n[i];
    if (t1 > t2) std::swap(t1, t2);
    iv.lo = std::max(iv.lo, t1);
    iv.hi = std::min(iv.hi, t2);
  }
  return iv;
}

// Finite version of an interval for searches.
Interval bounded(const Interval& iv) {
  return {std::isfinite(iv.lo) ? iv.lo : -kOuterTau, std::isfinite(iv.hi) ? iv.hi : kOuterTau};
}

// Minimum of a convex function over [lo, hi] by golden-section search.
template <typename F>
double convex_argmin(F&& g, double lo, double hi) {
  constexpr double kRatio = 0.6180339887498949;
  double a = lo, b = hi;
  double x1 = b - kRatio * (b - a), x2 = a + kRatio * (b - a);
  double g1 = g(x1), g2 = g(x2);
  for (int k = 0; k < kSearchIterations && b - a > 1e-15 * (1.0 + std::abs(a)); ++k) {
    if (g1 <= g2) {
      b = x2;
      x2 = x1;
      g2 = g1;
      x1 = b - kRatio * (b - a);
      g1 = g(x1);
    } else {
      a = x1;
      x1 = x2;
      g1 = g2;
      x2 = a + kRatio * (b - a);
      g2 = g(x2);
    }
  }
  return 0.5 * (a + b);
}

// The set where a convex function is within a relative tolerance of its minimum over [lo, hi]:
// an interval (a point when the minimum is sharp, wider on flat stretches, where the cost then
// decides).
template <typename F>
Interval convex_argmin_set(F&& g, double lo, double hi) {
  const double t_min = convex_argmin(g, lo, hi);
  const double g_min = g(t_min);
  const double level = g_min + 1e-9 * std::max(1.0, std::abs(g_min));
  Interval out{t_min, t_min};
  if (g(lo) <= level) {
    out.lo = lo;
  } else {
    double a = lo, b = t_min;
    for (int k = 0; k < kSearchIterations; ++k) {
      const double m = 0.5 * (a + b);
      (g(m) > level ? a : b) = m;
    }
    out.lo = b;
  }
  if (g(hi) <= level) {
    out.hi = hi;
  } else {
    double a = t_min, b = hi;
    for (int k = 0; k < kSearchIterations; ++k) {
      const double m = 0.5 * (a + b);
      (g(m) > level ? b : a) = m;
    }
    out.hi = a;
  }
  return out;
}

class Line {
 public:
  Line(const CraneModel& model, const NullSpaceProblem& problem)
      : model_(model),
        problem_(problem),
        line_(*problem.line),
        arms_(*problem.dc_dq),
        reference_rate_squared_(std::max(problem.line->p.squaredNorm(), 1e-300)) {}

  void joint_rates(double tau, JointVector& f) const { f = line_.p + tau * line_.n; }

  double flow(double tau) const {
    double q = 0.0;
    for (int i = 0; i < model_.dof(); ++i) {
      const double v = arms_[i] * (line_.p[i] + tau * line_.n[i]);
      q += cylinder_flow_m3_s(model_.cylinders[static_cast<std::size_t>(i)], v);
    }
    return q;
  }

  // Largest share of a position bound used (1: at the bound). The bounds scale with the path
  // speed they allow, so minimising this maximises the path speed at which every joint still
  // stops before its end. A joint at its end (bound 0) moving towards it counts as a huge share.
  double position_load(double tau) const {
    double worst = 0.0;
    for (int i = 0; i < model_.dof(); ++i) {
      const double f = line_.p[i] + tau * line_.n[i];
      const double bound = f >= 0.0 ? problem_.position.upper[i] : -problem_.position.lower[i];
      const double magnitude = std::abs(f);
      if (!(magnitude > 0.0)) continue;
      worst = std::max(worst, bound > 0.0 ? magnitude / bound : kAtEndShare * magnitude);
    }
    return worst;
  }

  // Sum of squared excesses over the hand-over bounds, in cylinder speed per unit path speed.
  double handover_excess(double tau) const {
    double sum = 0.0;
    for (int i = 0; i < model_.dof(); ++i) {
      const double f = line_.p[i] + tau * line_.n[i];
      const double over =
          std::max({f - problem_.handover.upper[i], problem_.handover.lower[i] - f, 0.0});
      sum += over * over * arms_[i] * arms_[i];
    }
    return sum;
  }

  // Largest share of a hydraulic limit used (1: at the limit).
  double hydraulic_load(double tau) const {
    double worst = 0.0;
    for (int i = 0; i < model_.dof(); ++i) {
      const double f = line_.p[i] + tau * line_.n[i];
      const double limit = f >= 0.0 ? problem_.hydraulic.upper[i] : -problem_.hydraulic.lower[i];
      if (limit <= 0.0) {
        if (std::abs(f) > kSlack) return kInf;
        continue;
      }
      if (std::isfinite(limit)) worst = std::max(worst, std::abs(f) / limit);
    }
    if (std::isfinite(problem_.flow_limit_m2)) {
      worst = std::max(worst, flow(tau) / problem_.flow_limit_m2);
    }
    return worst;
  }

  // The part of iv where the pump flow stays within its limit (convex, so one interval).
  Interval flow_interval(const Interval& iv) const {
    if (!std::isfinite(problem_.flow_limit_m2)) return iv;
    const double limit = problem_.flow_limit_m2;
    const Interval box = bounded(iv);
    const double t_min = convex_argmin([this](double t) { return flow(t); }, box.lo, box.hi);
    if (flow(t_min) > limit) return {kInf, -kInf};
    Interval out = box;
    if (flow(box.lo) > limit) {
      double a = box.lo, b = t_min;
      for (int k = 0; k < kSearchIterations; ++k) {
        const double m = 0.5 * (a + b);
        (flow(m) > limit ? a : b) = m;
      }
      out.lo = b;
    }
    if (flow(box.hi) > limit) {
      double a = t_min, b = box.hi;
      for (int k = 0; k < kSearchIterations; ++k) {
        const double m = 0.5 * (a + b);
        (flow(m) > limit ? b : a) = m;
      }
      out.hi = a;
    }
    if (!std::isfinite(iv.lo) && out.lo <= box.lo) out.lo = iv.lo;
    if (!std::isfinite(iv.hi) && out.hi >= box.hi) out.hi = iv.hi;
    return out;
  }

  double avoidance(double tau) const {
    if (problem_.avoid_weight.size() != model_.dof()) return 0.0;
    double sum = 0.0;
    for (int i = 0; i < model_.dof(); ++i) {
      const double w = problem_.avoid_weight[i];
      if (!(w > 0.0)) continue;
      // Joint rate towards the near end (the sign is the joint's: +1 upper, -1 lower).
      const double towards = problem_.avoid_sign[i] * (line_.p[i] + tau * line_.n[i]);
      if (towards > 0.0) sum += w * towards * towards;
    }
    return sum / reference_rate_squared_;
  }

  double cost(Resolution resolution, double tau, JointVector& f) const {
    joint_rates(tau, f);
    return resolution_cost(model_, resolution, f, arms_, problem_.cylinder_force);
  }

 private:
  const CraneModel& model_;
  const NullSpaceProblem& problem_;
  const SolutionLine& line_;
  const JointVector& arms_;
  // |p|^2: the avoidance term is in the units of the joint-rate norm relative to the
  // minimum-norm solution, so that with pinv-joint it is Chan and Dubey's weighted least norm.
  double reference_rate_squared_;
};

// Exact minimum over [a, b] of cost / scale + avoidance: both are linear or quadratic between the
// breakpoints (a joint at rest), so each piece is a parabola known from three interior values;
// the breakpoints themselves are evaluated exactly (min-ls-power may jump there).
double minimise_objective(const CraneModel& model, Resolution resolution, const Line& line,
                          const SolutionLine& sl, double a, double b, double scale) {
  JointVector f(model.dof());
  auto objective = [&](double tau) {
    return line.cost(resolution, tau, f) / scale + line.avoidance(tau);
  };
  if (!(b > a)) return a;
  std::array<double, kMaxJoints + 2> points{};
  std::size_t count = 0;
  points[count++] = a;
  for (int i = 0; i < model.dof(); ++i) {
    if (std::abs(sl.n[i]) <= kTinyComponent) continue;
    const double t = -sl.p[i] / sl.n[i];
    if (t > a && t < b) points[count++] = t;
  }
  points[count++] = b;
  for (std::size_t k = 1; k + 1 < count; ++k) {  // insertion sort of the breakpoints
    for (std::size_t j = k; j > 1 && points[j] < points[j - 1]; --j) {
      std::swap(points[j], points[j - 1]);
    }
  }

  double best_tau = a, best = objective(a);
  auto consider = [&](double tau) {
    const double value = objective(tau);
    if (value < best) {
      best = value;
      best_tau = tau;
    }
  };
  for (std::size_t k = 0; k + 1 < count; ++k) {
    const double t0 = points[k], t1 = points[k + 1];
    consider(t1);
    const double h = t1 - t0;
    if (!(h > 0.0)) continue;
    const double mid = t0 + 0.5 * h;
    const double y1 = objective(t0 + 0.25 * h), y2 = objective(mid), y3 = objective(t0 + 0.75 * h);
    const double curvature = 0.5 * (y1 + y3 - 2.0 * y2);
    const double slope = 0.5 * (y3 - y1);
    if (curvature > 0.0) {
      consider(std::clamp(mid - 0.25 * h * slope / (2.0 * curvature), t0, t1));
    }
    consider(mid);
  }
  return best_tau;
}

}  // namespace

bool solution_line(const TaskJacobian& jacobian, const Eigen::Vector3d& task, SolutionLine& out) {
  if (jacobian.cols() != 4) return false;
  const Eigen::Matrix3d jjt = jacobian * jacobian.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(jjt, Eigen::EigenvaluesOnly);
  const double largest = eig.eigenvalues().maxCoeff();
  const double smallest = std::max(eig.eigenvalues().minCoeff(), 0.0);
  if (!(largest > 0.0)) return false;
  out.conditioning = std::sqrt(smallest / largest);
  if (out.conditioning < 1e-7) return false;
  // Null vector: the signed 3x3 minors (the generalised cross product of the three rows).
  out.n.resize(4);
  for (int i = 0; i < 4; ++i) {
    Eigen::Matrix3d minor;
    int c = 0;
    for (int j = 0; j < 4; ++j) {
      if (j != i) minor.col(c++) = jacobian.col(j);
    }
    out.n[i] = (i % 2 == 0 ? 1.0 : -1.0) * minor.determinant();
  }
  const double norm = out.n.norm();
  if (!(norm > 0.0)) return false;
  out.n /= norm;
  out.p = jacobian.transpose() * jjt.partialPivLu().solve(task);
  return out.p.allFinite();
}

void resolve_null_space(const CraneModel& model, Resolution resolution,
                        const NullSpaceProblem& problem, NullSpaceResult& out) {
  const SolutionLine& sl = *problem.line;
  const Line line(model, problem);

  out.status = NullSpaceStatus::kOptimal;

  auto fallback = [&](const Interval& set, NullSpaceStatus status) {
    out.status = status;
    return set;
  };
  // Every search stays within rates a few times what the cylinders deliver at the intended
  // speed: beyond them a solution means nothing, and on a flat stretch of a fallback the cost
  // would otherwise pick arbitrary rates.
  JointRateBounds scratch;  // fixed capacity: no allocation
  scratch.upper = kSanityFactor * problem.hydraulic.upper;
  scratch.lower = kSanityFactor * problem.hydraulic.lower;
  Interval sane = linear_interval(sl, scratch);
  if (sane.empty()) {
    const Interval box = bounded(Interval{});
    sane = convex_argmin_set([&line](double t) { return line.hydraulic_load(t); }, box.lo, box.hi);
  }

  // 1. Ends: the side of a joint whose bound is 0 is closed.
  for (int i = 0; i < model.dof(); ++i) {
    scratch.upper[i] = problem.position.upper[i] > 0.0 ? kInf : 0.0;
    scratch.lower[i] = problem.position.lower[i] < 0.0 ? -kInf : 0.0;
  }
  Interval allowed = sane.cut(linear_interval(sl, scratch));
  if (allowed.empty()) {
    const Interval box = bounded(sane);
    allowed = fallback(
        convex_argmin_set([&line](double t) { return line.position_load(t); }, box.lo, box.hi),
        NullSpaceStatus::kPositionLimit);
    out.hard_lo = allowed.lo;
    out.hard_hi = allowed.hi;
  } else {
    const Interval hard = bounded(allowed);
    out.hard_lo = hard.lo;
    out.hard_hi = hard.hi;
    // 3 and 4. Position bounds, cylinder speeds and pump flow at the intended path speed.
    Interval feasible = allowed.cut(linear_interval(sl, problem.position));
    const bool position_ok = !feasible.empty();
    feasible = feasible.cut(linear_interval(sl, problem.hydraulic));
    if (!feasible.empty()) feasible = line.flow_interval(feasible);
    if (feasible.empty()) {
      // The path cannot run at the intended speed: the tau that lets it run fastest under both
      // (each load is the share of its bound used at the intended speed).
      const Interval box = bounded(allowed);
      auto load = [&line](double t) {
        return std::max(line.position_load(t), line.hydraulic_load(t));
      };
      allowed = convex_argmin_set(load, box.lo, box.hi);
      const double mid = 0.5 * (allowed.lo + allowed.hi);
      out.status = !position_ok || line.position_load(mid) >= line.hydraulic_load(mid)
                       ? NullSpaceStatus::kPositionLimit
                       : NullSpaceStatus::kHydraulicLimit;
    } else {
      allowed = feasible;
      // 5. Hand-over bounds.
      if (problem.handover.upper.size() == model.dof()) {
        const Interval handover = allowed.cut(linear_interval(sl, problem.handover));
        if (handover.empty()) {
          const Interval box = bounded(allowed);
          allowed =
              fallback(convex_argmin_set([&line](double t) { return line.handover_excess(t); },
                                         box.lo, box.hi),
                       NullSpaceStatus::kHandover);
        } else {
          allowed = handover;
        }
      }
    }
  }

  // 6. Cost plus end avoidance, exactly.
  const Interval box = bounded(allowed);
  JointVector f(model.dof());
  double scale = 1.0;
  if (problem.avoid_weight.size() == model.dof() && problem.avoid_weight.maxCoeff() > 0.0) {
    const double reference = line.cost(resolution, std::clamp(0.0, box.lo, box.hi), f);
    scale = reference > 1e-300 ? reference : 1.0;
  }
  out.tau = minimise_objective(model, resolution, line, sl, box.lo, box.hi, scale);
  out.cost = line.cost(resolution, out.tau, out.f);
}

}  // namespace craneassist::dynamics
