#include "craneassist/mhsb/mhsb_simulator.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/hydraulics.hpp"
#include "craneassist/dynamics/ode_crane.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"

namespace craneassist::mhsb {
namespace {

constexpr double kWorldErp = 0.2;  // as SimBackend
constexpr double kWorldCfm = 1e-10;
constexpr double kMinArm = 1e-9;  // m/rad: no torque arm

std::size_t at(int i) {
  return static_cast<std::size_t>(i);
}

// Orifice Q = k sign(dp) sqrt(|dp|), laminar (linear, same value at the transition) below
// dp_laminar so that dQ/dp stays finite at dp = 0.
double orifice(double k, double dp, double dp_laminar, double inv_sqrt_laminar) {
  const double a = std::abs(dp);
  if (a >= dp_laminar) return std::copysign(k * std::sqrt(a), dp);
  return k * dp * inv_sqrt_laminar;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("MHSB simulator: " + what);
}

}  // namespace

const char* to_string(MhsbStepStatus status) {
  switch (status) {
    case MhsbStepStatus::kOk:
      return "ok";
    case MhsbStepStatus::kInvalidReference:
      return "invalid_reference";
    case MhsbStepStatus::kDynamicsFailed:
      return "dynamics_failed";
  }
  return "?";
}

struct MhsbSimulator::Impl {
  Impl(const dynamics::CraneModel& m, const MhsbSettings& s, const JointVector& q_initial)
      : model(m), settings(s), mhsb(*m.mhsb), n(m.dof()), terms(m) {
    const MhsbPlantSettings& p = settings.plant;
    p0 = model.pump.supply_pressure_pa;
    pt = mhsb.tank_pressure_pa;
    p_relief = model.pump.max_pressure_pa;
    k_valve = mhsb.valve.rated_flow_m3_s / std::sqrt(mhsb.valve.rated_pressure_drop_pa);
    force_gain_scale = settings.controller.force_gain_rated_flow_m3_s / mhsb.valve.rated_flow_m3_s;
    k_check = p.check_rated_flow_m3_s / std::sqrt(p.check_rated_drop_pa);
    k_relief = p.relief_rated_flow_m3_s / p.relief_override_pa;
    inv_sqrt_laminar = 1.0 / std::sqrt(p.laminar_drop_pa);
    check_laminar = 0.25 * p.check_rated_drop_pa;
    inv_sqrt_check = 1.0 / std::sqrt(check_laminar);
    pumps = mhsb.modules;
    w_max = p.servo_pump_max_speed_rad_s > 0.0
                ? p.servo_pump_max_speed_rad_s
                : (mhsb.servo_pump_max_flow_m3_s + mhsb.valve.leakage_m3_s) /
                      p.servo_pump_displacement_m3_rad;
    mech_steps = static_cast<int>(std::lround(settings.controller.period_s / p.mechanical_step_s));
    spool_alpha = model.valves.time_constant_s > 0.0
                      ? 1.0 - std::exp(-p.mechanical_step_s / model.valves.time_constant_s)
                      : 1.0;
    pump_alpha = p.servo_pump_time_constant_s > 0.0
                     ? 1.0 - std::exp(-p.mechanical_step_s / p.servo_pump_time_constant_s)
                     : 1.0;

    for (JointVector* v :
         {&q,     &qdot,      &c_min,        &stroke,    &p_a,      &p_b,    &p_s,
          &spool, &spool_cmd, &int_position, &int_force, &int_pump, &tau_ff, &tau_g,
          &zero,  &force_avg, &pump_flow,    &velocity,  &piston,   &arm}) {
      v->setZero(n);
    }
    for (int j = 0; j < n; ++j) {
      const auto& cyl = model.cylinders[at(j)];
      const auto& joint = model.joints[at(j)];
      c_min[j] = std::min(dynamics::cylinder_length(cyl, joint.q_min),
                          dynamics::cylinder_length(cyl, joint.q_max));
      stroke[j] = cyl.stroke_m;
    }
    held.q = q_initial;
    held.qdot.setZero(n);
    held.qddot.setZero(n);
    held.modes.dof = n;
    modes.dof = n;
    pump_joint.fill(-1);

    MhsbState& st = state;
    for (JointVector* v :
         {&st.q, &st.qdot, &st.q_error, &st.cylinder_m, &st.p_a_pa, &st.p_b_pa, &st.p_supply_pa,
          &st.p_target_pa, &st.force_n, &st.force_ref_n, &st.spool_command, &st.spool}) {
      v->setZero(n);
    }

    dynamics::ensure_ode_initialized();
    world = dWorldCreate();
    dWorldSetGravity(world, model.gravity_m_s2.x(), model.gravity_m_s2.y(), model.gravity_m_s2.z());
    dWorldSetERP(world, kWorldErp);
    dWorldSetCFM(world, kWorldCfm);
    threading = dThreadingAllocateSelfThreadedImplementation();
    dWorldSetStepThreadingImplementation(world, dThreadingImplementationGetFunctions(threading),
                                         threading);
    crane = std::make_unique<dynamics::OdeCrane>(model, world, q_initial);
    crane->enable_end_stops(true);
    // The first dWorldStep sizes ODE's step arena: take it here, then put the arm back.
    if (!dWorldStep(world, p.mechanical_step_s)) {
      throw std::runtime_error("MHSB simulator: ODE could not take its first step");
    }
    crane->set_state(q_initial, zero);
    crane->read_state(q, qdot);

    // Chamber pressures that hold the gravity load with the valve closed.
    terms.gravity(q, tau_g);
    p_main = p0;
    for (int j = 0; j < n; ++j) {
      const auto& cyl = model.cylinders[at(j)];
      const double a = dynamics::cylinder_arm(cyl, q[j]);
      const double f = std::abs(a) > kMinArm ? tau_g[j] / a : 0.0;
      const double a1 = cyl.area_a_m2;
      const double a2 = cyl.area_b_m2;
      p_b[j] = std::clamp((p0 * a1 - f) / (a1 + a2), 0.0, p0);
      p_a[j] = (f + a2 * p_b[j]) / a1;
      if (p_a[j] < 0.0) {
        p_a[j] = 0.0;
        p_b[j] = -f / a2;
      }
      p_s[j] = p0;
    }
    update_kinematics();
    fill_state();
  }

  ~Impl() {
    crane.reset();
    dWorldSetStepThreadingImplementation(world, nullptr, nullptr);
    dWorldDestroy(world);
    dThreadingFreeImplementation(threading);
  }

  bool reference_valid(const MhsbReference& r) const {
    if (r.q.size() != n || r.qdot.size() != n || r.qddot.size() != n) return false;
    if (!r.q.allFinite() || !r.qdot.allFinite() || !r.qddot.allFinite()) return false;
    return r.modes.dof == n && r.modes.modules() <= pumps;
  }

  // Switching valves: a joint leaving N gets its boosted node at the main line's pressure; modules
  // stay with the joint they fed while it still needs them, free ones go to joints that need more.
  void apply_modes(const mhsb::ModePattern& next) {
    std::array<int, dynamics::kMaxJoints> need{};
    for (int j = 0; j < n; ++j) {
      need[at(j)] = mhsb::modules_used(next.mode[at(j)]);
      if (next.mode[at(j)] != modes.mode[at(j)]) {
        int_pump[j] = 0.0;
        if (!mhsb::is_boost(modes.mode[at(j)])) p_s[j] = p_main;
      }
    }
    for (int k = 0; k < pumps; ++k) {
      const int j = pump_joint[at(k)];
      if (j >= 0 && need[at(j)] > 0) {
        --need[at(j)];
      } else {
        pump_joint[at(k)] = -1;
      }
    }
    for (int k = 0; k < pumps; ++k) {
      if (pump_joint[at(k)] >= 0) continue;
      for (int j = 0; j < n; ++j) {
        if (need[at(j)] > 0) {
          pump_joint[at(k)] = j;
          --need[at(j)];
          break;
        }
      }
    }
    modes = next;
  }

  double supply_pa(int j) const { return mhsb::is_boost(modes.mode[at(j)]) ? p_s[j] : p_main; }

  // Cylinder positions, velocities and torque arms at the present (q, qdot).
  void update_kinematics() {
    for (int j = 0; j < n; ++j) {
      const auto& cyl = model.cylinders[at(j)];
      arm[j] = dynamics::cylinder_arm(cyl, q[j]);
      velocity[j] = arm[j] * qdot[j];
      piston[j] = std::clamp(dynamics::cylinder_length(cyl, q[j]) - c_min[j], 0.0, stroke[j]);
    }
  }

  // The cascade controller (paper 001 section 4.1, Figure 11).
  MhsbStepStatus control(const MhsbReference& r) {
    MhsbStepStatus status = MhsbStepStatus::kOk;
    if (reference_valid(r)) {
      held.q = r.q;
      held.qdot = r.qdot;
      held.qddot = r.qddot;
      held.modes = r.modes;
    } else {
      status = MhsbStepStatus::kInvalidReference;
      held.qdot.setZero();
      held.qddot.setZero();
    }
    apply_modes(held.modes);

    // Gravity compensation (and the reference's inertial force): tau = H(q) qddot_ref + g(q).
    dynamics::PathTerms& pt_out = path_terms_out;
    if (terms.path_terms(q, held.qddot, zero, 0.0, pt_out)) {
      tau_g = pt_out.b;
      tau_ff = pt_out.m + pt_out.b;
    } else {
      status = MhsbStepStatus::kDynamicsFailed;
    }

    const MhsbControllerSettings& c = settings.controller;
    const double dt = c.period_s;
    const double leak = mhsb.valve.leakage_m3_s;
    for (int j = 0; j < n; ++j) {
      const auto& cyl = model.cylinders[at(j)];
      const double a = std::abs(arm[j]) > kMinArm ? arm[j] : kMinArm;
      const double arm_ref = dynamics::cylinder_arm(cyl, held.q[j]);
      const double e =
          dynamics::cylinder_length(cyl, held.q[j]) - dynamics::cylinder_length(cyl, q[j]);
      const double v_ref = arm_ref * held.qdot[j];
      // Position loop: desired cylinder force.
      int_position[j] = std::clamp(int_position[j] + c.position_ki_n_m_s * e * dt,
                                   -c.position_integral_limit_n, c.position_integral_limit_n);
      const double f_ref = tau_ff[j] / a + c.position_kp_n_m * e + int_position[j] +
                           c.position_kd_n_s_m * (v_ref - velocity[j]);
      // Force loop: spool.
      const double a1 = cyl.area_a_m2;
      const double a2 = cyl.area_b_m2;
      const double f = a1 * p_a[j] - a2 * p_b[j];
      const double ps = supply_pa(j);
      const double dp_min = settings.plant.laminar_drop_pa;
      double x_ff = 0.0;
      if (v_ref > 0.0) {
        x_ff = a1 * v_ref / (k_valve * std::sqrt(std::max(ps - p_a[j], dp_min)));
      } else if (v_ref < 0.0) {
        x_ff = a2 * v_ref / (k_valve * std::sqrt(std::max(ps - p_b[j], dp_min)));
      }
      const double ef = f_ref - f;
      int_force[j] = std::clamp(int_force[j] + force_gain_scale * c.force_ki_1_n_s * ef * dt,
                                -c.force_integral_limit, c.force_integral_limit);
      spool_cmd[j] = std::clamp(
          c.flow_feedforward * x_ff + force_gain_scale * c.force_kp_1_n * ef + int_force[j], -1.0,
          1.0);

      // Servo-pump loop: pressure target from the desired force (or the gravity load).
      double p_target = 0.0;
      double w_cmd = 0.0;
      const int sp = mhsb::modules_used(modes.mode[at(j)]);
      if (sp > 0) {
        const double f_g = tau_g[j] / a;
        // Moving: through the valve opened to pressure_target_opening; at rest: the side the
        // gravity load presses on.
        double v = v_ref / c.pressure_target_opening;
        if (v_ref == 0.0) v = f_g >= 0.0 ? 0.0 : -1e-12;
        const double f_p = c.pressure_target_from_force_ref ? f_ref : f_g;
        p_target = mhsb::required_supply_pressure_pa(cyl, mhsb.valve, pt, f_p, v);
        p_target += c.pressure_target_margin_pa;
        const double w_total_max = sp * w_max;
        const double ep = p_target - ps;
        int_pump[j] =
            std::clamp(int_pump[j] + c.pump_ki_rad_s2_pa * ep * dt, -w_total_max, w_total_max);
        const double w_ff = p_target > p_main ? (dynamics::cylinder_flow_m3_s(cyl, v_ref) + leak) /
                                                    settings.plant.servo_pump_displacement_m3_rad
                                              : 0.0;
        w_cmd = std::clamp(w_ff + c.pump_kp_rad_s_pa * ep + int_pump[j], 0.0, w_total_max) / sp;
      } else {
        int_pump[j] = 0.0;
      }
      for (int k = 0; k < pumps; ++k) {
        if (pump_joint[at(k)] == j) pump_cmd[at(k)] = w_cmd;
      }
      state.q_error[j] = held.q[j] - q[j];
      state.force_ref_n[j] = f_ref;
      state.p_target_pa[j] = p_target;
    }
    for (int k = 0; k < pumps; ++k) {
      if (pump_joint[at(k)] < 0) pump_cmd[at(k)] = 0.0;
    }
    return status;
  }

  // One rigid-body step with its hydraulic substeps. False: the ODE step failed.
  bool advance_mechanical() {
    const MhsbPlantSettings& p = settings.plant;
    const double h = p.mechanical_step_s;
    const int subs = p.hydraulic_substeps;
    const double dt = h / subs;
    const double beta = p.bulk_modulus_pa;
    const double leak = mhsb.valve.leakage_m3_s;
    const double eta = mhsb.servo_pump_efficiency;
    const double dp_lam = p.laminar_drop_pa;

    for (int j = 0; j < n; ++j) spool[j] += spool_alpha * (spool_cmd[j] - spool[j]);
    pump_flow.setZero();
    for (int k = 0; k < pumps; ++k) {
      pump_speed[at(k)] += pump_alpha * (pump_cmd[at(k)] - pump_speed[at(k)]);
      const int j = pump_joint[at(k)];
      if (j >= 0) pump_flow[j] += p.servo_pump_displacement_m3_rad * pump_speed[at(k)];
    }
    force_avg.setZero();

    for (int s = 0; s < subs; ++s) {
      double draw = 0.0;      // flow out of the main line
      double sp_power = 0.0;  // servo-pump input power
      double relief_w = 0.0;  // dissipated in the reliefs
      const double tau = (s + 0.5) * dt;
      for (int j = 0; j < n; ++j) {
        const auto& cyl = model.cylinders[at(j)];
        const double a1 = cyl.area_a_m2;
        const double a2 = cyl.area_b_m2;
        const bool boost = mhsb::is_boost(modes.mode[at(j)]);
        const double ps = boost ? p_s[j] : p_main;
        const double x = spool[j];
        const double kx = k_valve * std::abs(x);
        double q_pa = 0.0, q_pb = 0.0, q_at = 0.0, q_bt = 0.0;
        if (x > 0.0) {
          q_pa = orifice(kx, ps - p_a[j], dp_lam, inv_sqrt_laminar);
          q_bt = orifice(kx, p_b[j] - pt, dp_lam, inv_sqrt_laminar);
        } else if (x < 0.0) {
          q_pb = orifice(kx, ps - p_b[j], dp_lam, inv_sqrt_laminar);
          q_at = orifice(kx, p_a[j] - pt, dp_lam, inv_sqrt_laminar);
        }
        const double q_leak = leak * std::clamp((ps - pt) / p.leakage_full_drop_pa, 0.0, 1.0);
        const double from_supply = q_pa + q_pb + q_leak;
        if (boost) {
          const double dp_check = p_main - ps - p.check_cracking_pa;
          const double q_check =
              dp_check > 0.0 ? orifice(k_check, dp_check, check_laminar, inv_sqrt_check) : 0.0;
          const double q_rel = ps > p_relief ? k_relief * (ps - p_relief) : 0.0;
          p_s[j] +=
              dt * beta / p.supply_node_volume_m3 * (pump_flow[j] + q_check - from_supply - q_rel);
          p_s[j] = std::max(p_s[j], 0.0);
          draw += pump_flow[j] + q_check;
          const double lift = ps - p_main;
          sp_power += lift >= 0.0 ? lift * pump_flow[j] / eta : lift * pump_flow[j] * eta;
          relief_w += q_rel * (ps - pt);
        } else {
          draw += from_supply;
        }
        const double v = velocity[j];
        const double xp = std::clamp(piston[j] + v * tau, 0.0, stroke[j]);
        const double va = p.chamber_dead_volume_m3 + a1 * xp;
        const double vb = p.chamber_dead_volume_m3 + a2 * (stroke[j] - xp);
        p_a[j] = std::max(p_a[j] + dt * beta / va * (q_pa - q_at - a1 * v), 0.0);
        p_b[j] = std::max(p_b[j] + dt * beta / vb * (q_pb - q_bt + a2 * v), 0.0);
        force_avg[j] += a1 * p_a[j] - a2 * p_b[j];
      }
      const double q_pump =
          model.pump.max_flow_m3_s * std::clamp((p0 - p_main) / p.compensator_band_pa, 0.0, 1.0);
      const double q_rel_main = p_main > p_relief ? k_relief * (p_main - p_relief) : 0.0;
      relief_w += q_rel_main * (p_main - pt);
      main_flow = q_pump;
      state.main_energy_j += p_main * q_pump * dt;
      state.servo_pump_energy_j += sp_power * dt;
      state.relief_energy_j += relief_w * dt;
      p_main =
          std::max(p_main + dt * beta / p.main_line_volume_m3 * (q_pump - draw - q_rel_main), 0.0);
    }

    for (int j = 0; j < n; ++j) {
      const double f = force_avg[j] / subs - p.cylinder_viscous_friction_n_s_m * velocity[j];
      tau_cmd[j] = f * arm[j];
    }
    crane->add_joint_efforts(tau_cmd);
    const bool ok = dWorldStep(world, h) != 0;
    crane->read_state(q, qdot);
    update_kinematics();
    return ok;
  }

  void fill_state() {
    MhsbState& st = state;
    st.q = q;
    st.qdot = qdot;
    st.cylinder_m = piston;
    st.p_a_pa = p_a;
    st.p_b_pa = p_b;
    for (int j = 0; j < n; ++j) {
      const auto& cyl = model.cylinders[at(j)];
      st.p_supply_pa[j] = supply_pa(j);
      st.force_n[j] = cyl.area_a_m2 * p_a[j] - cyl.area_b_m2 * p_b[j];
    }
    st.spool_command = spool_cmd;
    st.spool = spool;
    st.modes = modes;
    st.pump_speed_rad_s = pump_speed;
    st.pump_joint = pump_joint;
    st.p_main_pa = p_main;
    st.main_flow_m3_s = main_flow;
  }

  MhsbStepStatus step(const MhsbReference& r) {
    MhsbStepStatus status = control(r);
    const double main_before = state.main_energy_j;
    const double sp_before = state.servo_pump_energy_j;
    for (int k = 0; k < mech_steps; ++k) {
      if (!advance_mechanical()) status = MhsbStepStatus::kDynamicsFailed;
    }
    const double dt = settings.controller.period_s;
    state.t_s += dt;
    state.main_power_w = (state.main_energy_j - main_before) / dt;
    state.servo_pump_power_w = (state.servo_pump_energy_j - sp_before) / dt;
    fill_state();
    return status;
  }

  dynamics::CraneModel model;
  MhsbSettings settings;
  dynamics::Mhsb mhsb;
  int n = 0;
  dynamics::RigidBodyTerms terms;
  dWorldID world = nullptr;
  dThreadingImplementationID threading = nullptr;
  std::unique_ptr<dynamics::OdeCrane> crane;

  double p0 = 0.0, pt = 0.0, p_relief = 0.0;
  double k_valve = 0.0, k_check = 0.0, k_relief = 0.0, inv_sqrt_laminar = 0.0;
  double force_gain_scale = 1.0;  // the force loop's gains for this valve size
  double check_laminar = 0.0, inv_sqrt_check = 0.0;
  int pumps = 0;
  double w_max = 0.0;
  int mech_steps = 1;
  double spool_alpha = 1.0, pump_alpha = 1.0;

  // Plant state.
  JointVector q, qdot, c_min, stroke, p_a, p_b, p_s, spool, velocity, piston, arm;
  double p_main = 0.0;
  double main_flow = 0.0;
  std::array<double, kMaxServoPumps> pump_speed{};
  std::array<int, kMaxServoPumps> pump_joint{};
  mhsb::ModePattern modes;
  // Controller state and outputs.
  MhsbReference held;
  JointVector spool_cmd, int_position, int_force, int_pump, tau_ff, tau_g, zero;
  std::array<double, kMaxServoPumps> pump_cmd{};
  // Step buffers.
  JointVector force_avg, pump_flow;
  JointVector tau_cmd = JointVector::Zero(dynamics::kMaxJoints);
  dynamics::PathTerms path_terms_out;
  MhsbState state;
};

MhsbSimulator::MhsbSimulator(const dynamics::CraneModel& model, const MhsbSettings& settings,
                             const JointVector& q_initial) {
  require(model.mhsb.has_value(), "the crane has no hydraulics.mhsb");
  require(model.pump.mode == dynamics::PumpMode::kConstantPressure &&
              model.pump.supply_pressure_pa > 0.0,
          "hydraulics.pump must be constant-pressure with a positive supply_pressure (P0)");
  require(model.dof() >= 1 && model.dof() <= dynamics::kMaxJoints, "1 to 6 joints");
  require(q_initial.size() == model.dof() && q_initial.allFinite(),
          "the initial configuration needs one finite value per joint");
  const dynamics::Mhsb& m = *model.mhsb;
  require(m.modules >= 0 && m.modules <= kMaxServoPumps,
          "hydraulics.mhsb.modules must be 0 to " + std::to_string(kMaxServoPumps));
  require(m.valve.rated_flow_m3_s > 0.0 && m.valve.rated_pressure_drop_pa > 0.0,
          "hydraulics.mhsb.servo_valve needs a positive rated flow and pressure drop");
  require(m.servo_pump_efficiency > 0.0, "hydraulics.mhsb.servo_pump_efficiency must be > 0");
  for (const auto& c : model.cylinders) {
    require(c.area_a_m2 > 0.0 && c.area_b_m2 > 0.0 && c.stroke_m > 0.0,
            "cylinder '" + c.name + "' needs positive areas and stroke");
  }
  const MhsbPlantSettings& p = settings.plant;
  const MhsbControllerSettings& c = settings.controller;
  require(c.period_s > 0.0 && p.mechanical_step_s > 0.0 && p.mechanical_step_s <= c.period_s,
          "the mechanical step must be in (0, control period]");
  const double ratio = c.period_s / p.mechanical_step_s;
  require(std::abs(ratio - std::round(ratio)) < 1e-9 * ratio,
          "the mechanical step must divide the control period");
  require(p.hydraulic_substeps >= 1, "hydraulic_substeps must be >= 1");
  require(p.bulk_modulus_pa > 0.0 && p.chamber_dead_volume_m3 > 0.0 &&
              p.supply_node_volume_m3 > 0.0 && p.main_line_volume_m3 > 0.0,
          "bulk modulus and volumes must be positive");
  require(p.compensator_band_pa > 0.0 && p.laminar_drop_pa > 0.0 && p.leakage_full_drop_pa > 0.0 &&
              p.check_rated_drop_pa > 0.0 && p.check_rated_flow_m3_s > 0.0 &&
              p.relief_override_pa > 0.0 && p.relief_rated_flow_m3_s > 0.0 &&
              p.servo_pump_displacement_m3_rad > 0.0,
          "valve and pump parameters must be positive");
  require(c.pressure_target_opening > 0.0 && c.pressure_target_opening <= 1.0,
          "pressure_target_opening must be in (0, 1]");
  impl_ = std::make_unique<Impl>(model, settings, q_initial);
}

MhsbSimulator::~MhsbSimulator() = default;

MhsbStepStatus MhsbSimulator::step(const MhsbReference& reference) noexcept {
  return impl_->step(reference);
}

const MhsbState& MhsbSimulator::state() const {
  return impl_->state;
}
const dynamics::CraneModel& MhsbSimulator::model() const {
  return impl_->model;
}
const MhsbSettings& MhsbSimulator::settings() const {
  return impl_->settings;
}
int MhsbSimulator::dof() const {
  return impl_->n;
}
int MhsbSimulator::servo_pumps() const {
  return impl_->pumps;
}
double MhsbSimulator::servo_pump_max_speed_rad_s() const {
  return impl_->w_max;
}

void write_mhsb_csv_header(std::ostream& out, int dof, int pumps) {
  out << "t_s";
  for (int j = 1; j <= dof; ++j) {
    for (const char* col : {"q_ref", "q", "q_error", "mode", "spool_command", "spool", "p_a_pa",
                            "p_b_pa", "p_supply_pa", "p_target_pa", "force_n", "force_ref_n"}) {
      out << ",j" << j << '_' << col;
    }
  }
  for (int k = 1; k <= pumps; ++k) out << ",sp" << k << "_joint,sp" << k << "_speed_rad_s";
  out << ",p_main_pa,main_flow_m3_s,main_power_w,servo_pump_power_w,energy_j\n";
}

void write_mhsb_csv_row(std::ostream& out, const MhsbState& s, const MhsbReference& r, int pumps) {
  out << s.t_s;
  for (int j = 0; j < static_cast<int>(s.q.size()); ++j) {
    out << ',' << (j < r.q.size() ? r.q[j] : 0.0) << ',' << s.q[j] << ',' << s.q_error[j] << ','
        << mhsb::to_string(s.modes.mode[at(j)]) << ',' << s.spool_command[j] << ',' << s.spool[j]
        << ',' << s.p_a_pa[j] << ',' << s.p_b_pa[j] << ',' << s.p_supply_pa[j] << ','
        << s.p_target_pa[j] << ',' << s.force_n[j] << ',' << s.force_ref_n[j];
  }
  for (int k = 0; k < pumps; ++k) {
    out << ',' << s.pump_joint[at(k)] + 1 << ',' << s.pump_speed_rad_s[at(k)];
  }
  out << ',' << s.p_main_pa << ',' << s.main_flow_m3_s << ',' << s.main_power_w << ','
      << s.servo_pump_power_w << ',' << s.energy_j() << '\n';
}

MhsbRunSummary run_mhsb_reference(MhsbSimulator& sim, const MhsbReferenceFunction& reference,
                                  double duration_s, std::ostream* csv) {
  const int n = sim.dof();
  const double period = sim.settings().controller.period_s;
  const auto periods = std::lround(duration_s / period);
  MhsbRunSummary sum;
  sum.max_abs_error.setZero(n);
  sum.max_p_supply_pa.setZero(n);
  const double main0 = sim.state().main_energy_j;
  const double sp0 = sim.state().servo_pump_energy_j;
  MhsbReference ref;
  ref.q.setZero(n);
  ref.qdot.setZero(n);
  ref.qddot.setZero(n);
  ref.modes.dof = n;
  if (csv) write_mhsb_csv_header(*csv, n, sim.servo_pumps());
  for (long k = 0; k < periods; ++k) {
    reference(static_cast<double>(k) * period, ref);
    const MhsbStepStatus status = sim.step(ref);
    if (status == MhsbStepStatus::kInvalidReference) ++sum.invalid_references;
    if (status == MhsbStepStatus::kDynamicsFailed) ++sum.dynamics_failures;
    const MhsbState& s = sim.state();
    sum.max_abs_error = sum.max_abs_error.cwiseMax(s.q_error.cwiseAbs());
    sum.max_p_supply_pa = sum.max_p_supply_pa.cwiseMax(s.p_supply_pa);
    if (csv) write_mhsb_csv_row(*csv, s, ref, sim.servo_pumps());
  }
  sum.duration_s = static_cast<double>(periods) * period;
  sum.max_abs_error_any = n > 0 ? sum.max_abs_error.maxCoeff() : 0.0;
  sum.main_energy_j = sim.state().main_energy_j - main0;
  sum.servo_pump_energy_j = sim.state().servo_pump_energy_j - sp0;
  sum.energy_j = sum.main_energy_j + sum.servo_pump_energy_j;
  return sum;
}

}  // namespace craneassist::mhsb
