// The control pipeline per cycle: direction kept, bad input stops, no heap allocation.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <new>
#include <utility>
#include <vector>

#include "allocation_counter.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/controller.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/flow_polytope.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "csv_cells.hpp"
#include "still_state.hpp"

using namespace craneassist;

namespace {

using test::still_state;

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

constexpr dynamics::Resolution kAllResolutions[] = {
    dynamics::Resolution::kPinvJoint, dynamics::Resolution::kPinvActuator,
    dynamics::Resolution::kMinFlow, dynamics::Resolution::kMinLsPower};

using AdjustConfig = std::function<void(config::CraneConfig&)>;

config::CraneConfig default_config_adjusted(const AdjustConfig& adjust) {
  auto cfg = config::default_crane_config();
  if (adjust) adjust(cfg);
  return cfg;
}

// A controller on the default configuration (changed by adjust), reset to the initial pose with
// the machine standing still there.
struct Rig {
  config::CraneConfig cfg;
  control::Controller controller;
  valves::MachineState state;
  control::ControllerOutput out;

  explicit Rig(control::ScalingMode mode, const AdjustConfig& adjust = nullptr)
      : cfg(default_config_adjusted(adjust)),
        controller(cfg, {.mode = mode, .polytope = true}),
        state(still_state(cfg)) {
    controller.reset(state);
  }

  // `cycles` cycles of the command v, each running, with a machine that follows the reference
  // one valve delay (transport delay plus lag) late, as the real one does; the tracking-error
  // slow-down measures against that delayed reference.
  void follow_one_valve_delay_late(const Eigen::Vector3d& v, std::size_t cycles) {
    const auto lag = static_cast<std::size_t>(std::lround(
        (cfg.model.valves.delay_s + cfg.model.valves.time_constant_s) / controller.period_s()));
    std::vector<dynamics::JointVector> history(lag, state.q);
    for (std::size_t k = 0; k < cycles; ++k) {
      ASSERT_EQ(controller.update(state, v, out), control::ControllerStatus::kRunning);
      history[k % lag] = out.q_ref;
      state.q = history[(k + 1) % lag];
    }
  }

  // Cycles of the command v, with a machine that follows the reference, until the controller
  // reports kStopped (at most 500): check(status, out) holds in each, and the path acceleration
  // steps within the jerk bound. The stop takes more than 10 cycles and ends at rest with neutral
  // valves.
  template <class Check>
  void expect_jerk_limited_stop(const Eigen::Vector3d& v, Check check) {
    double prev_sddot = out.sddot;
    int stopping = 0;
    control::ControllerStatus status = control::ControllerStatus::kRunning;
    for (int k = 0; k < 500 && status != control::ControllerStatus::kStopped; ++k) {
      status = controller.update(state, v, out);
      check(status, out);
      EXPECT_LE(std::abs(out.sddot - prev_sddot),
                cfg.scaling.jerk_max_m_s3 * controller.period_s() * (1 + 1e-9));
      prev_sddot = out.sddot;
      stopping += status == control::ControllerStatus::kStopping;
      state.q = out.q_ref;
    }
    EXPECT_EQ(status, control::ControllerStatus::kStopped);
    EXPECT_GT(stopping, 10) << "a stop from speed takes time, not one cycle";
    EXPECT_EQ(out.sdot, 0.0);
    EXPECT_EQ(out.valves.spool.cwiseAbs().maxCoeff(), 0.0);
  }
};

}  // namespace

TEST(Controller, ReferenceKeepsTheCommandedDirection) {
  Rig rig(control::ScalingMode::kFlowOnly, [](config::CraneConfig& c) {
    c.model.pump.max_flow_m3_s = 50e-3 / 60.0;  // make the flow limit bind
  });
  auto& [cfg, controller, state, out] = rig;
  const Eigen::Vector3d v(0.6, 0.8, 1.2);
  int flow_limited = 0;
  for (int k = 0; k < 100; ++k) {
    ASSERT_EQ(controller.update(state, v, out), control::ControllerStatus::kRunning);
    EXPECT_LT(angle_deg(out.ref_tip_velocity_m_s, v), 1e-6);
    EXPECT_LE(out.scale, 1.0);
    flow_limited += out.limit == scaling::ActiveLimit::kFlow;
    for (int i = 0; i < 4; ++i) {
      EXPECT_LE(std::abs(out.valves.spool[i]), 1.0);
    }
    state.q = out.q_ref;  // a machine that follows perfectly
  }
  EXPECT_EQ(flow_limited, 100);
  EXPECT_NEAR(out.ref_tip_velocity_m_s.norm(), out.scale * v.norm(), 1e-9);
}

TEST(Controller, ScaleStaysWithinZeroAndOneWhenTheCommandFalls) {
  // Full scaling: the reference decelerates with bounded jerk after the stick eases from 0.8 to
  // 0.1 m/s, so for a while it is faster than the command; the scale (the limits' factor on the
  // command, 0..1 in the IDL) is then 1, not the ratio (which reached about 1.7 before).
  Rig rig(control::ScalingMode::kFull);
  auto& [cfg, controller, state, out] = rig;
  const Eigen::Vector3d fast(0.8, 0.0, 0.0), slow(0.1, 0.0, 0.0);
  rig.follow_one_valve_delay_late(fast, 200);
  double faster = 0.0;
  for (int k = 0; k < 100; ++k) {
    ASSERT_EQ(controller.update(state, slow, out), control::ControllerStatus::kRunning);
    faster = std::max(faster, out.ref_tip_velocity_m_s.norm() / slow.norm());
    EXPECT_GE(out.scale, 0.0);
    EXPECT_LE(out.scale, 1.0);
    state.q = out.q_ref;
  }
  EXPECT_GT(faster, 1.5) << "the reference outruns the eased command for a while";
}

TEST(Controller, InvalidInputStopsWithNeutralValves) {
  Rig rig(control::ScalingMode::kFlowOnly);
  auto& [cfg, controller, state, out] = rig;
  controller.update(state, Eigen::Vector3d(0.3, 0, 0), out);
  ASSERT_GT(out.valves.spool.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NE(controller.update(state, Eigen::Vector3d(NAN, 0, 0), out),
            control::ControllerStatus::kRunning);
  EXPECT_EQ(out.limit, scaling::ActiveLimit::kStaleInput);
  EXPECT_EQ(out.valves.spool.cwiseAbs().maxCoeff(), 0.0);
  state.valid = false;
  EXPECT_EQ(controller.update(state, Eigen::Vector3d(0.3, 0, 0), out),
            control::ControllerStatus::kStopped);
  EXPECT_EQ(out.valves.spool.cwiseAbs().maxCoeff(), 0.0);
  state.valid = true;
  state.q[2] = INFINITY;
  EXPECT_EQ(controller.update(state, Eigen::Vector3d(0.3, 0, 0), out),
            control::ControllerStatus::kStopped);
}

TEST(Controller, CycleDoesNotAllocate) {
  Rig rig(control::ScalingMode::kFull);
  auto& [cfg, controller, state, out] = rig;
  // Both chambers measured, changing: the crane scale runs and the dynamics' payload follows it.
  state.chamber_pressures = true;
  state.pressure_a_pa = dynamics::JointVector::Constant(4, 5e6);
  state.pressure_b_pa = dynamics::JointVector::Constant(4, 0.3e6);
  controller.update(state, Eigen::Vector3d(0.1, 0.1, 0.1), out);  // first call sizes the output
  const long before = craneassist::test::heap_allocations();
  for (int k = 0; k < 600; ++k) {
    state.pressure_a_pa.setConstant(5e6 + 2e4 * (k % 200));
    // The swing sensor measures a swing (the period is measured), and a dropout in the middle
    // hands the shaped reference over (shaping starts again after it on a seeded past).
    state.t_s = 0.01 * k;
    state.swing_radial_rad = 0.03 * std::sin(3.3 * state.t_s);
    state.swing_tangential_rad = 0.02 * std::cos(3.3 * state.t_s);
    const bool dropout = k >= 250 && k < 260;
    controller.update(state,
                      dropout ? Eigen::Vector3d(NAN, 0, 0)
                              : Eigen::Vector3d(0.3 * std::cos(0.01 * k), 0.2 * (k % 3),
                                                -0.4 * std::sin(0.01 * k)),
                      out);
    state.q = out.q_ref;
  }
  controller.update(state, Eigen::Vector3d(NAN, 0, 0), out);
  EXPECT_EQ(craneassist::test::heap_allocations() - before, 0);
  // The counter does count.
  auto* probe = new int(3);
  EXPECT_GT(craneassist::test::heap_allocations() - before, 0);
  delete probe;
}

TEST(Controller, CycleWithAConstantPressurePumpDoesNotAllocate) {
  Rig rig(control::ScalingMode::kFull, [](config::CraneConfig& c) {
    c.model.pump.mode = dynamics::PumpMode::kConstantPressure;
    c.model.pump.prime_mover_power_w = 10e3;  // make the p_s Q bound bind
  });
  auto& [cfg, controller, state, out] = rig;
  controller.update(state, Eigen::Vector3d(0.1, 0.1, 0.1), out);  // first call sizes the output
  int power_limited = 0;
  const long before = craneassist::test::heap_allocations();
  for (int k = 0; k < 200; ++k) {
    controller.update(state, Eigen::Vector3d(0.6, 0.4, -0.4), out);
    power_limited += out.limit == scaling::ActiveLimit::kPower;
    state.q = out.q_ref;
  }
  EXPECT_EQ(craneassist::test::heap_allocations() - before, 0);
  EXPECT_GT(power_limited, 20);
}

TEST(Controller, FullScalingKeepsDirectionAndJerkBound) {
  Rig rig(control::ScalingMode::kFull,
          [](config::CraneConfig& c) { config::set_payload_mass(c.model, 650.0); });
  auto& [cfg, controller, state, out] = rig;
  const Eigen::Vector3d v(0.2, 0.6, 0.5);
  double prev_sddot = 0.0;
  for (int k = 0; k < 300; ++k) {
    ASSERT_EQ(controller.update(state, v, out), control::ControllerStatus::kRunning);
    if (out.sdot > 0.0) {
      EXPECT_LT(angle_deg(out.ref_tip_velocity_m_s, v), 1e-9);
    }
    EXPECT_LE(std::abs(out.sdddot), cfg.scaling.jerk_max_m_s3 * (1 + 1e-9));
    EXPECT_LE(std::abs(out.sddot - prev_sddot),
              cfg.scaling.jerk_max_m_s3 * controller.period_s() * (1 + 1e-9));
    EXPECT_LE(out.sdot, v.norm() + 1e-9);
    prev_sddot = out.sddot;
    state.q = out.q_ref;
  }
  EXPECT_GT(out.sdot, 0.1);
}

TEST(Controller, FullScalingStaleInputIsAJerkLimitedStop) {
  Rig r(control::ScalingMode::kFull);
  r.follow_one_valve_delay_late(Eigen::Vector3d(0.4, 0.0, 0.3), 200);
  ASSERT_GT(r.out.sdot, 0.45);
  r.expect_jerk_limited_stop(Eigen::Vector3d(NAN, 0.0, 0.0),
                             [](control::ControllerStatus, const control::ControllerOutput& out) {
                               EXPECT_EQ(out.limit, scaling::ActiveLimit::kStaleInput);
                             });
}

TEST(Controller, AFailedDynamicsStepStopsInsteadOfThrowing) {
  // update() cannot throw (a throw inside would end this test binary); a failed ODE step (the
  // RigidBodyTerms test hook; on a machine: ODE out of memory) stops the reference jerk-limited
  // with the operator still commanding motion, reports it, and then holds with neutral valves.
  static_assert(noexcept(std::declval<control::Controller&>().update(
      std::declval<const valves::MachineState&>(), std::declval<const Eigen::Vector3d&>(),
      std::declval<control::ControllerOutput&>())));
  Rig r(control::ScalingMode::kFull);
  ASSERT_NE(r.controller.dynamics_for_testing(), nullptr);
  const Eigen::Vector3d v(0.4, 0.0, 0.3);
  // A machine one valve delay late (as in FullScalingStaleInputIsAJerkLimitedStop).
  r.follow_one_valve_delay_late(v, 200);
  ASSERT_GT(r.out.sdot, 0.45);

  r.controller.dynamics_for_testing()->fail_steps_for_testing(true);
  r.expect_jerk_limited_stop(
      v, [](control::ControllerStatus status, const control::ControllerOutput& out) {
        EXPECT_NE(status, control::ControllerStatus::kRunning);
        EXPECT_EQ(out.limit, scaling::ActiveLimit::kDynamicsFailed);
        EXPECT_STREQ(scaling::to_string(out.limit), "dynamics_failed");
        EXPECT_EQ(out.ref_power_w, 0.0);
      });
  // The machine at rest at the reference: measured at rest for the valves' lag, the valves ramp
  // to neutral.
  r.state.qdot.setZero();
  control::ControllerStatus stopped = control::ControllerStatus::kStopping;
  for (int k = 0; k < 60 && stopped != control::ControllerStatus::kStopped; ++k) {
    r.state.q = r.out.q_ref;
    stopped = r.controller.update(r.state, v, r.out);
  }
  EXPECT_EQ(stopped, control::ControllerStatus::kStopped);
  EXPECT_EQ(r.out.stop_end, control::StopEnd::kAtRest);

  // The dynamics back: the controller restarts from the measured pose and runs.
  r.controller.dynamics_for_testing()->fail_steps_for_testing(false);
  control::ControllerStatus status = control::ControllerStatus::kStopped;
  for (int k = 0; k < 50; ++k) {
    status = r.controller.update(r.state, v, r.out);
    r.state.q = r.out.q_ref;
  }
  EXPECT_EQ(status, control::ControllerStatus::kRunning);
  EXPECT_NE(r.out.limit, scaling::ActiveLimit::kDynamicsFailed);
  EXPECT_GT(r.out.sdot, 0.0);
}

// Largest joint acceleration of the reference while the operator swings the stick from one
// direction to a nearly opposite one, for a machine that follows the reference.
double peak_joint_acceleration_when_swinging(control::ScalingMode mode,
                                             int* turn_cycles = nullptr) {
  Rig rig(mode);
  auto& [cfg, controller, state, out] = rig;
  dynamics::JointVector previous = dynamics::JointVector::Zero(4);
  double peak = 0.0;
  for (int k = 0; k < 400; ++k) {
    const Eigen::Vector3d v =
        k < 200 ? Eigen::Vector3d(0.5, 0.0, 0.2) : Eigen::Vector3d(-0.4, 0.2, -0.1);
    controller.update(state, v, out);
    if (k > 0) {
      peak =
          std::max(peak, ((out.qdot_ref - previous) / controller.period_s()).cwiseAbs().maxCoeff());
    }
    if (turn_cycles != nullptr && k >= 200 && angle_deg(out.ref_tip_velocity_m_s, v) > 0.5) {
      ++*turn_cycles;
    }
    previous = out.qdot_ref;
    state.q = out.q_ref;
  }
  return peak;
}

TEST(Controller, SwingingTheStickKeepsJointAccelerationsBounded) {
  int turn_cycles = 0;
  const double blended =
      peak_joint_acceleration_when_swinging(control::ScalingMode::kFull, &turn_cycles);
  const double stepped = peak_joint_acceleration_when_swinging(control::ScalingMode::kFlowOnly);
  std::printf(
      "[ figures  ] stick reversal: peak joint acceleration %.3f (blended) vs %.3f "
      "(velocity steps), direction turned over %d cycles\n",
      blended, stepped, turn_cycles);
  EXPECT_LT(blended, 2.0) << "rad/s^2 or m/s^2";
  EXPECT_GT(stepped, 10.0 * blended);
  EXPECT_GT(turn_cycles, 10) << "the direction turns over time, not in one cycle";
}

TEST(Controller, EveryResolutionDrivesTheReferenceAlongTheCommand) {
  for (auto r : kAllResolutions) {
    Rig rig(control::ScalingMode::kFull,
            [r](config::CraneConfig& c) { c.redundancy.resolution = r; });
    auto& [cfg, controller, state, out] = rig;
    const Eigen::Vector3d v(0.3, 0.3, 0.4);
    const long before = craneassist::test::heap_allocations();
    for (int k = 0; k < 200; ++k) {
      ASSERT_EQ(controller.update(state, v, out), control::ControllerStatus::kRunning);
      if (out.sdot > 0.0) {
        // The reference tip velocity is J(q_ref) f' sdot: check it against the Jacobian.
        dynamics::KinematicsData kin;
        dynamics::TaskJacobian jac;
        dynamics::tip_jacobian(cfg.model, kin, state.q, jac);
        EXPECT_LT(angle_deg(jac * out.qdot_ref, v), 0.5) << dynamics::to_string(r);
      }
      state.q = out.q_ref;
    }
    EXPECT_GT(out.sdot, 0.3) << dynamics::to_string(r);
    EXPECT_EQ(craneassist::test::heap_allocations() - before, 0)
        << dynamics::to_string(r) << ": the control cycle allocated";
  }
}

// Every resolution keeps the reference's cylinder accelerations within their limits while the
// operator moves the tip out, up, sideways and back: the piecewise-optimal resolutions switch
// between breakpoints (a cylinder coming to rest), and the switch must not step a cylinder's
// velocity.
TEST(Controller, EveryResolutionRespectsCylinderAccelerationLimits) {
  for (auto r : kAllResolutions) {
    Rig rig(control::ScalingMode::kFull,
            [r](config::CraneConfig& c) { c.redundancy.resolution = r; });
    auto& [cfg, controller, state, out] = rig;
    const std::array<Eigen::Vector3d, 4> moves = {
        Eigen::Vector3d(0.6, 0.0, 0.0), Eigen::Vector3d(0.0, 0.5, 0.3),
        Eigen::Vector3d(-0.5, -0.2, 0.2), Eigen::Vector3d(0.2, -0.4, -0.4)};
    dynamics::JointVector v_prev = dynamics::JointVector::Zero(4), arms(4), v_cyl(4);
    double worst = 0.0;  // largest cylinder acceleration over its limit
    int worst_cylinder = -1;
    for (int k = 0; k < 1200; ++k) {
      controller.update(state, moves[static_cast<std::size_t>(k / 300)], out);
      dynamics::cylinder_arms(cfg.model, out.q_ref, arms);
      v_cyl = arms.cwiseProduct(out.qdot_ref);
      if (k > 0) {
        for (int i = 0; i < 4; ++i) {
          const double a = std::abs(v_cyl[i] - v_prev[i]) / controller.period_s();
          const double ratio = a / cfg.model.cylinders[static_cast<std::size_t>(i)].a_max_m_s2;
          if (ratio > worst) {
            worst = ratio;
            worst_cylinder = i;
          }
        }
      }
      v_prev = v_cyl;
      state.q = out.q_ref;
    }
    std::printf("[ figures  ] %s: peak cylinder acceleration %.2f of its limit (cylinder %d)\n",
                dynamics::to_string(r), worst, worst_cylinder + 1);
    // The jerk-limited path deceleration after a direction change may overshoot the bound by a
    // few per cent (the filter cannot meet a falling bound at once); a velocity step would be
    // many times the limit.
    EXPECT_LT(worst, 1.1) << dynamics::to_string(r);
  }
}

TEST(Controller, PolytopeFiguresOfEachCycle) {
  // Each cycle's polytope is the one at the configuration the cycle resolved at (the previous
  // reference), with the reserves of the scaling in use; its LP speed is along the stick. The
  // flow-only prescaling scales the command uniformly, so its reference speed is the speed
  // along its resolution whenever the flow or a cylinder limits it.
  for (const auto mode : {control::ScalingMode::kFull, control::ScalingMode::kFlowOnly}) {
    Rig rig(mode, [](config::CraneConfig& c) { c.model.pump.max_flow_m3_s = 120e-3 / 60.0; });
    auto& [cfg, controller, state, out] = rig;
    const double reserve = cfg.control.flow_reserve;
    const dynamics::FlowPolytopeSettings settings{
        .flow_reserve = reserve,
        .cylinder_speed_reserve = mode == control::ScalingMode::kFull ? reserve : 0.0};
    dynamics::FlowPolytope poly(4, 3);
    dynamics::KinematicsData kin;
    dynamics::TaskJacobian jacobian;
    dynamics::JointVector arms;
    dynamics::JointVelocitySet set;
    const Eigen::Vector3d v(1.2, 0.9, -0.8);  // more than the pump gives at this pose
    int limited = 0;
    for (int k = 0; k < 200; ++k) {
      const dynamics::JointVector q = state.q;  // = the controller's reference
      ASSERT_EQ(controller.update(state, v, out), control::ControllerStatus::kRunning);
      dynamics::cylinder_arms(cfg.model, q, arms);
      dynamics::tip_jacobian(cfg.model, kin, q, jacobian);
      dynamics::joint_velocity_set(cfg.model, q, arms, settings, set);
      poly.update(set, jacobian);
      poly.build_hull();
      EXPECT_EQ(out.polytope_volume_m3_s3, poly.volume());
      EXPECT_GT(out.polytope_volume_m3_s3, 0.0);
      EXPECT_EQ(out.polytope_dim, 3);  // a solid: its measure is the volume, no area
      EXPECT_EQ(out.polytope_area_m2_s2, 0.0);
      EXPECT_EQ(out.avail_speed_m_s, poly.max_speed(v));
      EXPECT_GT(out.avail_speed_resolved_m_s, 0.0);
      EXPECT_LE(out.avail_speed_resolved_m_s, out.avail_speed_m_s * (1 + 1e-9));
      const double ref_speed = out.ref_tip_velocity_m_s.norm();
      if (mode == control::ScalingMode::kFlowOnly) {
        EXPECT_LE(ref_speed, out.avail_speed_resolved_m_s * (1 + 1e-9));
        if (out.limit == scaling::ActiveLimit::kFlow ||
            out.limit == scaling::ActiveLimit::kCylinderSpeed) {
          EXPECT_NEAR(ref_speed, out.avail_speed_resolved_m_s, 1e-9 * ref_speed);
          ++limited;
        }
      } else {
        limited += out.sdot > 0.0;
      }
      state.q = out.q_ref;
    }
    EXPECT_GT(limited, 100) << control::to_string(mode);
    // The stick released: the LP keeps the last stick direction.
    const dynamics::JointVector q = state.q;
    controller.update(state, Eigen::Vector3d::Zero(), out);
    dynamics::cylinder_arms(cfg.model, q, arms);
    dynamics::tip_jacobian(cfg.model, kin, q, jacobian);
    dynamics::joint_velocity_set(cfg.model, q, arms, settings, set);
    poly.update(set, jacobian);
    EXPECT_EQ(out.avail_speed_m_s, poly.max_speed(v));
    EXPECT_GT(out.avail_speed_m_s, 0.0);
  }
}

TEST(Controller, PlanarArmReportsThePolytopeAreaInItsPlane) {
  // A planar arm's tip polytope is flat: the cycle reports dimension 2, no volume, and the area
  // of the polygon of its plane's own 2 x n task (planar_task_basis), computed here apart, at
  // poses across its range. (The controller does not move a planar arm: its resolution needs
  // three independent Jacobian columns, docs/polytope.md; the polytope does not.) Stretched out
  // it is singular: a segment, no area.
  const auto cfg = config::planar_2r_config();
  control::Controller controller(cfg, {.mode = control::ScalingMode::kFlowOnly, .polytope = true});
  control::ControllerOutput out;
  const auto basis = dynamics::planar_task_basis(cfg.model);
  ASSERT_TRUE(basis.has_value());
  const dynamics::FlowPolytopeSettings settings{.flow_reserve = cfg.control.flow_reserve};
  dynamics::FlowPolytope plane(cfg.model.dof(), 2);
  dynamics::KinematicsData kin;
  dynamics::TaskJacobian jacobian;
  dynamics::JointVector arms;
  dynamics::JointVelocitySet set;
  const Eigen::Vector3d v(0.3, -0.2, 0.0);  // in the arm's plane (x, y)
  std::vector<double> areas;
  for (const double shoulder : {-0.5, 0.2, 0.9, 1.6}) {
    for (const double elbow : {-1.2, -0.6, 0.3}) {
      valves::MachineState state = still_state(cfg);
      state.q << shoulder, elbow;
      controller.reset(state);
      controller.update(state, v, out);
      dynamics::cylinder_arms(cfg.model, state.q, arms);
      dynamics::tip_jacobian(cfg.model, kin, state.q, jacobian);
      dynamics::joint_velocity_set(cfg.model, state.q, arms, settings, set);
      plane.update(set, *basis * jacobian);
      plane.build_hull();
      ASSERT_EQ(plane.dimension(), 2);
      EXPECT_EQ(out.polytope_dim, 2);
      EXPECT_EQ(out.polytope_volume_m3_s3, 0.0);
      EXPECT_GT(out.polytope_area_m2_s2, 0.0);
      EXPECT_NEAR(out.polytope_area_m2_s2, plane.area(), 1e-9 * plane.area());
      EXPECT_NEAR(out.avail_speed_m_s, plane.max_speed(*basis * v), 1e-9 * out.avail_speed_m_s);
      areas.push_back(out.polytope_area_m2_s2);
    }
  }
  // The poses differ: not one figure checked twelve times.
  EXPECT_GT(*std::max_element(areas.begin(), areas.end()),
            1.5 * *std::min_element(areas.begin(), areas.end()));
  valves::MachineState stretched = still_state(cfg);
  stretched.q << 0.5, 0.0;
  controller.reset(stretched);
  controller.update(stretched, v, out);
  EXPECT_EQ(out.polytope_dim, 1);
  EXPECT_EQ(out.polytope_volume_m3_s3, 0.0);
  EXPECT_EQ(out.polytope_area_m2_s2, 0.0);
}

TEST(CsvLog, PushDoesNotAllocateAndEveryRowArrives) {
  const auto path = std::filesystem::temp_directory_path() / "craneassist_test_log.csv";
  control::CsvLog log(path, 4, 64);
  control::LogRow row;
  row.active_limit = "none";
  row.pump_limit = "none";
  const long before = craneassist::test::heap_allocations();
  std::size_t refused = 0;
  for (int k = 0; k < 1000; ++k) {
    row.t = k * 0.01;
    // The ring is small: a push may be refused (the control loop would drop the row and move
    // on; the count says so). The test retries so every row arrives.
    while (!log.push(row)) {
      ++refused;
      std::this_thread::yield();
    }
  }
  EXPECT_EQ(craneassist::test::heap_allocations() - before, 0);
  EXPECT_EQ(log.close(), refused);
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, control::CsvLog::header(4));
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 1000);
}

TEST(CsvLog, TheBasesColumnsFollowWhenThereIsABase) {
  const auto path = std::filesystem::temp_directory_path() / "craneassist_test_base_log.csv";
  {
    control::CsvLog log(path, 4, 64, /*base=*/true);
    control::LogRow row;
    row.active_limit = "none";
    row.pump_limit = "none";
    row.base_pose = {1.5, -2.25, 0.125};
    row.base_velocity = {0.3, 0.05};
    row.base_command = {0.32, 0.06};
    row.base_motor_flow = {1e-4, 2e-4, 3e-4, 4e-4};
    row.base_flow_sum_m3s = 1e-3;
    row.base_flow_max_m3s = 1.05e-3;
    ASSERT_TRUE(log.push(row));
  }
  std::ifstream in(path);
  std::string header, line;
  std::getline(in, header);
  std::getline(in, line);
  EXPECT_EQ(header, control::CsvLog::header(4, true));
  EXPECT_EQ(header.rfind(control::CsvLog::header(4), 0), 0u);  // the fixed base's columns first
  const auto cells = test::csv_cells(line);
  const auto names = test::csv_cells(header);
  ASSERT_EQ(cells.size(), names.size());
  const auto at = [&](const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? -1.0
                             : std::stod(cells[static_cast<std::size_t>(it - names.begin())]);
  };
  EXPECT_DOUBLE_EQ(at("base_x"), 1.5);
  EXPECT_DOUBLE_EQ(at("base_y"), -2.25);
  EXPECT_DOUBLE_EQ(at("base_phi"), 0.125);
  EXPECT_DOUBLE_EQ(at("base_omega_cmd"), 0.06);
  EXPECT_DOUBLE_EQ(at("base_flow_rr_m3s"), 4e-4);
  EXPECT_DOUBLE_EQ(at("base_flow_max_m3s"), 1.05e-3);
}

TEST(CsvLog, UnwritablePathIsReported) {
  try {
    control::CsvLog log("/nonexistent-dir/log.csv", 4);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/log.csv"), std::string::npos);
  }
}
