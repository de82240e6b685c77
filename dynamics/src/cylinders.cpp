#include "craneassist/dynamics/cylinders.hpp"

#include <cmath>

#include "craneassist/dynamics/hydraulics.hpp"

namespace craneassist::dynamics {
namespace {

// Polynomial value and first two derivatives, coefficients highest power first.
struct PolyEval {
  double value = 0.0, d1 = 0.0, d2 = 0.0;
};

PolyEval eval_poly(const std::vector<double>& coeffs, double x) {
  PolyEval r;
  for (double c : coeffs) {  // Horner for value and derivatives together
    r.d2 = r.d2 * x + 2.0 * r.d1;
    r.d1 = r.d1 * x + r.value;
    r.value = r.value * x + c;
  }
  return r;
}

}  // namespace

double cylinder_length(const Cylinder& cyl, double q) {
  switch (cyl.linkage) {
    case LinkageType::kConstantArm:
      return cyl.c0_m + cyl.arm_m * q;
    case LinkageType::kTriangle: {
      const double b = q + cyl.angle_offset_rad;
      return std::sqrt(cyl.l1_m * cyl.l1_m + cyl.l2_m * cyl.l2_m -
                       2.0 * cyl.l1_m * cyl.l2_m * std::cos(b));
    }
    case LinkageType::kPolynomial:
      return eval_poly(cyl.poly_coeffs, q).value;
  }
  return 0.0;
}

double cylinder_arm(const Cylinder& cyl, double q) {
  switch (cyl.linkage) {
    case LinkageType::kConstantArm:
      return cyl.arm_m;
    case LinkageType::kTriangle: {
      const double b = q + cyl.angle_offset_rad;
      return cyl.l1_m * cyl.l2_m * std::sin(b) / cylinder_length(cyl, q);
    }
    case LinkageType::kPolynomial:
      return eval_poly(cyl.poly_coeffs, q).d1;
  }
  return 0.0;
}

double cylinder_arm_slope(const Cylinder& cyl, double q) {
  switch (cyl.linkage) {
    case LinkageType::kConstantArm:
      return 0.0;
    case LinkageType::kTriangle: {
      // r = k sin b / c, dc/db = r  =>  dr/db = (k cos b - r^2) / c
      const double b = q + cyl.angle_offset_rad;
      const double c = cylinder_length(cyl, q);
      const double r = cyl.l1_m * cyl.l2_m * std::sin(b) / c;
      return (cyl.l1_m * cyl.l2_m * std::cos(b) - r * r) / c;
    }
    case LinkageType::kPolynomial:
      return eval_poly(cyl.poly_coeffs, q).d2;
  }
  return 0.0;
}

void cylinder_lengths(const CraneModel& model, const JointVector& q, JointVector& c) {
  c.resize(model.dof());
  for (int i = 0; i < model.dof(); ++i) c[i] = cylinder_length(model.cylinders[i], q[i]);
}

void cylinder_arms(const CraneModel& model, const JointVector& q, JointVector& dc_dq) {
  dc_dq.resize(model.dof());
  for (int i = 0; i < model.dof(); ++i) dc_dq[i] = cylinder_arm(model.cylinders[i], q[i]);
}

double pump_flow_demand(const CraneModel& model, const JointVector& v) {
  double q = 0.0;
  for (int i = 0; i < model.dof(); ++i) q += cylinder_flow_m3_s(model.cylinders[i], v[i]);
  return q;
}

}  // namespace craneassist::dynamics
