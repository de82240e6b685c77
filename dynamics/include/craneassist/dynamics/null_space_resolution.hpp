// Redundancy resolution of a 3-D tip task with four joints, exactly, on the solution line.
//
// Every joint-rate vector f with J f = u lies on one line, f(tau) = p + tau n, with p = J^+ u
// (the minimum-norm solution) and n the unit vector spanning the null space of J (one dimension:
// four joints, three task coordinates). Every joint rate, every cylinder velocity r_i f_i and the
// pump flow are then functions of the single number tau, and each requirement becomes an
// interval or a convex function of tau. The resolution takes them in order of priority, like the
// saturation in the null space (SNS) of F. Flacco, A. De Luca and O. Khatib, "Motion control of
// redundant robots under joint constraints: saturation in the null space" (ICRA 2012), but solved
// exactly because the null space is a line:
//
//   1. ends (hard): a joint at an end (its position bound is 0 on that side) does not move
//      towards it. Infeasible only at a corner of the workspace. The result reports this
//      interval: a caller that moves towards the optimum gradually (TipPath does, so that the
//      joints' accelerations and jerks stay bounded) keeps within it.
//   2. (reserved: the caller's smoothing, see above)
//   3. position bounds: a joint moving towards an end may not move faster, per metre of tip path,
//      than lets it stop before the end (the caller shapes these from the distance to the end,
//      Flacco's velocity bounds from position limits), and
//   4. hydraulic bounds: each cylinder's speed and the pump flow at the intended path speed.
//      Both scale with the path speed they allow. When 3 and 4 cannot all be met, the path cannot
//      run at the intended speed (at the edge of the workspace along this direction, or at the
//      hydraulics' limit): tau minimises the largest share of a bound used, which lets the path
//      run fastest under both.
//   5. hand-over bounds (soft): tighter position bounds from which the other joints can take a
//      joint's motion over through the null space within their accelerations, before it nears
//      its end. Infeasible: the smallest sum of squared excesses (in cylinder speed).
//   6. the resolution's own cost (resolutions.hpp) plus an end-avoidance term that grows as a
//      joint nears an end: sum_i weight_i max(0, s_i f_i)^2 / |p|^2, the joint rate towards
//      its near end (s_i = +1 upper, -1 lower) relative to the minimum-norm solution (with
//      pinv-joint exactly the weighted least norm of T. F. Chan and R. V. Dubey, "A weighted
//      least-norm solution based scheme for avoiding joint limits for redundant joint
//      manipulators", IEEE TRA 1995; here added to any cost). The cost is divided by its value
//      at the line's minimum-norm point; with every weight zero the resolution is the plain
//      optimum.
// A fallback (steps 1, 3 to 5) keeps every tau that minimises its measure, so that on a flat
// stretch the later steps and the cost still decide.
// Between breakpoints (a cylinder at rest) every cost is linear or quadratic in tau and so is the
// avoidance term, so step 6 is solved exactly piece by piece. No allocation, bounded work.
#pragma once

#include <limits>

#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/redundancy.hpp"
#include "craneassist/dynamics/resolutions.hpp"

namespace craneassist::dynamics {

// f(tau) = p + tau n with J f = u for every tau.
struct SolutionLine {
  JointVector p;  // J^+ u, orthogonal to n
  JointVector n;  // unit null vector of J
  // Smallest singular value of J relative to its largest: near 0, J is close to losing rank (a
  // singular pose) and p grows without bound.
  double conditioning = 0.0;
};

// Builds the line for a 3 x 4 Jacobian. False (line unusable) when J has fewer than three
// independent columns or the model does not have four joints.
bool solution_line(const TaskJacobian& jacobian, const Eigen::Vector3d& task, SolutionLine& out);

struct NullSpaceProblem {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  const SolutionLine* line = nullptr;
  const JointVector* dc_dq = nullptr;           // torque arms at q
  const JointVector* cylinder_force = nullptr;  // min-ls-power: forces at the present loads
  JointRateBounds position;                     // 1, 3: per joint, on f (0: at that end)
  JointRateBounds hydraulic;                    // 4: per joint, on f (cylinder speeds)
  double flow_limit_m2 = kInf;                  // 4: pump flow per unit path speed, m^3/s / (m/s)
  JointRateBounds handover;                     // 5: per joint, on f; empty: none
  JointVector avoid_weight;                     // 6: >= 0; empty: no avoidance term
  JointVector avoid_sign;                       // 6: +1 the near end is the upper, -1 the lower
};

enum class NullSpaceStatus {
  kOptimal,         // every hard bound met; the cost minimum over what is left
  kHandover,        // every hard bound met; a hand-over bound is exceeded
  kHydraulicLimit,  // position bounds met; cylinder speeds or pump flow cannot all be met
  kPositionLimit,   // the position bounds cannot all be met (edge of the workspace)
};

struct NullSpaceResult {
  JointVector f;
  double tau = 0.0;
  NullSpaceStatus status = NullSpaceStatus::kOptimal;
  double cost = 0.0;  // the resolution's cost at f (resolution_cost)
  // Step 1's interval of tau (within rates the cylinders could deliver): no joint moves into an
  // end it is at.
  double hard_lo = 0.0, hard_hi = 0.0;
};

void resolve_null_space(const CraneModel& model, Resolution resolution,
                        const NullSpaceProblem& problem, NullSpaceResult& out);

}  // namespace craneassist::dynamics
