#include "craneassist/sim_backend/sim_backend.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/hydraulics.hpp"
#include "craneassist/dynamics/ode_crane.hpp"
#include "craneassist/dynamics/pendulum.hpp"
#include "craneassist/sim_backend/pump_model.hpp"
#include "craneassist/sim_backend/valve_section.hpp"

namespace craneassist::sim_backend {
namespace {

constexpr double kLoadPressureTimeConstantS = 0.005;  // stands in for oil compressibility
constexpr double kWorldErp = 0.2;
constexpr double kWorldCfm = 1e-10;
constexpr double kMinLoadBodyKg = 1e-3;  // the load body of a crane with nothing at its tip
// Cylinder speed over which the Coulomb friction builds up (tanh), m/s.
constexpr double kFrictionSmoothingM_S = 1e-3;
// The load-holding valve's hysteresis: it closes again when the load falls below this share of
// its setting; a stalled section tries to move again below this share of the pump's force.
constexpr double kReseatShare = 0.98;
constexpr double kSaturatedShare = 0.999;  // a motor force at this share of its cap is saturated
constexpr double kReliefOverride =
    2.0;  // a load-holding valve's pressure at most this x its setting
// A cylinder faster than the load-holding valve lets it in the load's direction by this much is
// creeping (m/s).
constexpr double kCreepSlackM_S = 1e-4;

// The crane's bodies without the load body's: the payload and every body at the tip point.
dynamics::CraneModel without_tip_load(const dynamics::CraneModel& m) {
  dynamics::CraneModel out = m;
  out.bodies.clear();
  for (const auto& b : m.bodies) {
    const bool tip = b.frame == m.dof() && b.com_m.norm() < dynamics::kAtTipM;
    if (!(tip || dynamics::is_payload(b))) out.bodies.push_back(b);
  }
  return out;
}

// What a sensor reads of x: with white noise of this standard deviation, then rounded to the
// resolution (each 0: none).
double sensed(double x, double noise, double resolution, std::mt19937& rng,
              std::normal_distribution<double>& normal) {
  if (noise > 0.0) x += noise * normal(rng);
  if (resolution > 0.0) x = resolution * std::round(x / resolution);
  return x;
}

// The machine's model: the controller's, with the machine's own grapple where it differs.
dynamics::CraneModel with_plant_grapple(const dynamics::CraneModel& m, const SimSettings& s) {
  dynamics::CraneModel out = m;
  if (s.grapple) out.grapple = *s.grapple;
  return out;
}

}  // namespace

struct SimBackend::Impl {
  Impl(const dynamics::CraneModel& m, const SimSettings& s)
      : model(with_plant_grapple(m, s)), settings(s), pump(m.pump), world(make_world(m)) {
    // A threading implementation of this world's own: ODE's shared default aborts when two
    // worlds step at the same time in different threads.
    threading = dThreadingAllocateSelfThreadedImplementation();
    dWorldSetStepThreadingImplementation(world, dThreadingImplementationGetFunctions(threading),
                                         threading);
    crane = std::make_unique<dynamics::OdeCrane>(without_tip_load(model), world, s.q_initial);
    crane->enable_end_stops(true);
    make_load_body(s.q_initial);
    rng.seed(s.noise_seed);
    swing_rng.seed(s.noise_seed + 1);
    const int n = model.dof();
    feedback.resize(static_cast<std::size_t>(n) + 1);
    for (int i = 1; i <= n; ++i) {
      const auto k = static_cast<std::size_t>(i - 1);
      dJointSetFeedback(crane->joint(i), &feedback[static_cast<std::size_t>(i)]);
      sections.emplace_back(model.valves, s.valves[k], model.cylinders[k].v_max_m_s, s.step_s);
    }
    spool_command.setZero(n);
    requested_velocity.setZero(n);
    demand.setZero(n);
    load_pressure.setZero(n);
    force.setZero(n);
    q.setZero(n);
    qdot.setZero(n);
    pump_result.delivered_fraction.setZero(n);
    force_filtered.setZero(n);
    pressure_a.setZero(n);
    pressure_b.setZero(n);
    creep.fill(false);
    stall.fill(false);
    load_alpha = 1.0 - std::exp(-s.step_s / kLoadPressureTimeConstantS);
    crane->read_state(q, qdot);
    // The joint readings of the last steps, for the sensors' and the feedback's delay.
    const auto& js = s.joints;
    const double late_s = js.delay_s + js.feedback_delay_s + js.feedback_jitter_s;
    history_q.assign(static_cast<std::size_t>(std::ceil(late_s / s.step_s - 1e-9)) + 1, q);
    history_qdot.assign(history_q.size(), qdot);
    joint_rng.seed(s.noise_seed + 2);
    // Start from the static holding loads so the first steps see the right pump pressure.
    settle_loads();
  }

  // The joints as the machine's sensors and its feedback report them (SimSettings::joints).
  void measure_joints(JointVector& q_out, JointVector& qdot_out) {
    const auto& js = settings.joints;
    if (js.exact()) {
      q_out = q;
      qdot_out = qdot;
      return;
    }
    double late_s = js.delay_s + js.feedback_delay_s;
    if (js.feedback_jitter_s > 0.0) late_s += js.feedback_jitter_s * uniform(joint_rng);
    const auto size = history_q.size();
    const auto back =
        std::min(static_cast<std::size_t>(std::lround(late_s / settings.step_s)), size - 1);
    const std::size_t k = (history_head + size - back) % size;
    q_out = history_q[k];
    qdot_out = history_qdot[k];
    for (int i = 0; i < model.dof(); ++i) {
      const bool angle =
          model.joints[static_cast<std::size_t>(i)].type == dynamics::JointType::kRevolute;
      q_out[i] =
          sensed(q_out[i], angle ? js.angle_noise_rad : js.length_noise_m,
                 angle ? js.angle_resolution_rad : js.length_resolution_m, joint_rng, joint_normal);
    }
  }

  void record_joints() {
    history_head = (history_head + 1) % history_q.size();
    history_q[history_head] = q;
    history_qdot[history_head] = qdot;
  }

  ~Impl() {
    crane.reset();
    dWorldSetStepThreadingImplementation(world, nullptr, nullptr);
    dWorldDestroy(world);
    dThreadingFreeImplementation(threading);
  }

  static dWorldID make_world(const dynamics::CraneModel& m) {
    dynamics::ensure_ode_initialized();
    dWorldID w = dWorldCreate();
    dWorldSetGravity(w, m.gravity_m_s2.x(), m.gravity_m_s2.y(), m.gravity_m_s2.z());
    dWorldSetERP(w, kWorldErp);
    dWorldSetCFM(w, kWorldCfm);
    return w;
  }

  // The grapple, rotator and payload. Rigid: one body welded to the tip (a fixed joint), so that
  // the payload can change while the crane moves. Hanging (model.grapple): the grapple and
  // rotator hang below the tip on a universal joint (the two-axis link) and the payload, a body
  // of its own, is welded to the grapple at its depth.
  void make_load_body(const JointVector& q0) {
    dynamics::tip_bodies(model, tip_mass_kg, tip_inertia);
    dynamics::KinematicsData kin;
    dynamics::forward_kinematics(model, kin, q0);
    const Eigen::Isometry3d& tip = kin.frames[static_cast<std::size_t>(model.dof())];
    payload_kg = dynamics::payload_mass_kg(model);
    const auto& g = model.grapple;
    if (!g.hangs()) {
      load_body = make_body(tip.translation(), tip.linear());
      apply_load_mass();
      load_joint = dJointCreateFixed(world, nullptr);
      dJointAttach(load_joint, load_body, crane->body(model.dof()));
      dJointSetFixed(load_joint);
      return;
    }
    const Eigen::Vector3d down = dynamics::down_direction(model);
    // The link's axes: one across the boom plane, fixed to the boom (the lift and tilt joints'
    // axis stays horizontal in every pose), one along it, fixed to the grapple (any axis across
    // the first where gravity runs along it).
    const Eigen::Vector3d across = kin.frames[1].linear().col(2);
    Eigen::Vector3d along = down.cross(across);
    if (along.norm() < 1e-6) along = across.unitOrthogonal();
    along.normalize();
    const Eigen::Matrix3d upright = Eigen::Matrix3d::Identity();
    load_body = make_body(tip.translation() + g.com_below_m * down, upright);
    payload_body = make_body(tip.translation() + g.load_below_m * down, upright);
    apply_load_mass();
    load_joint = dJointCreateUniversal(world, nullptr);
    dJointAttach(load_joint, crane->body(model.dof()), load_body);
    dJointSetUniversalAnchor(load_joint, tip.translation().x(), tip.translation().y(),
                             tip.translation().z());
    dJointSetUniversalAxis1(load_joint, across.x(), across.y(), across.z());
    dJointSetUniversalAxis2(load_joint, along.x(), along.y(), along.z());
    payload_joint = dJointCreateFixed(world, nullptr);
    dJointAttach(payload_joint, payload_body, load_body);
    dJointSetFixed(payload_joint);
  }

  dBodyID make_body(const Eigen::Vector3d& position, const Eigen::Matrix3d& rotation) {
    dBodyID body = dBodyCreate(world);
    dMatrix3 r;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) r[4 * row + col] = rotation(row, col);
      r[4 * row + 3] = 0.0;
    }
    dBodySetPosition(body, position.x(), position.y(), position.z());
    dBodySetRotation(body, r);
    return body;
  }

  static void set_mass(dBodyID body, double mass_kg, const Eigen::Vector3d& inertia) {
    dMass mass;
    dMassSetParameters(&mass, mass_kg, 0.0, 0.0, 0.0, inertia.x(), inertia.y(), inertia.z(), 0.0,
                       0.0, 0.0);
    dBodySetMass(body, &mass);
  }

  void apply_load_mass() {
    if (payload_body != nullptr) {
      // The grapple keeps its own mass; the payload is a point at its depth (a small inertia
      // floor keeps ODE's inverse defined).
      const double mg = std::max(tip_mass_kg, kMinLoadBodyKg);
      set_mass(load_body, mg, tip_inertia.cwiseMax(1e-3 * mg));
      const double mp = std::max(payload_kg, kMinLoadBodyKg);
      set_mass(payload_body, mp, Eigen::Vector3d::Constant(1e-3 * mp));
      return;
    }
    const double m = std::max(tip_mass_kg + payload_kg, kMinLoadBodyKg);
    // A point payload adds no inertia of its own; a small floor keeps ODE's inverse defined.
    set_mass(load_body, m, tip_inertia.cwiseMax(1e-3 * m));
  }

  // The link's damping (its brake or friction), as torques against each axis's rate.
  void damp_link() {
    const double c = model.grapple.damping_n_m_s_rad;
    if (payload_body == nullptr || c <= 0.0) return;
    dJointAddUniversalTorques(load_joint, -c * dJointGetUniversalAngle1Rate(load_joint),
                              -c * dJointGetUniversalAngle2Rate(load_joint));
  }

  // The hanger's swing from the vertical and its components towards and across the reach.
  void measure_swing(valves::MachineState& state) const {
    // Nothing hangs, or the machine measures no swing (NaN).
    if (payload_body == nullptr || !settings.swing_sensor) return;
    dVector3 anchor;
    dJointGetUniversalAnchor(load_joint, anchor);
    const dReal* c = dBodyGetPosition(load_body);
    const Eigen::Vector3d r(c[0] - anchor[0], c[1] - anchor[1], c[2] - anchor[2]);
    const Eigen::Vector3d down = dynamics::down_direction(model);
    Eigen::Vector3d radial, tangential;
    dynamics::swing_axes(Eigen::Vector3d(anchor[0], anchor[1], anchor[2]), radial, tangential);
    const double vertical = r.dot(down);
    // The two-axis sensor: each angle with its noise and resolution; the swing from them.
    state.swing_radial_rad = sensed(std::atan2(r.dot(radial), vertical), settings.swing_noise_rad,
                                    settings.swing_resolution_rad, swing_rng, swing_normal);
    state.swing_tangential_rad =
        sensed(std::atan2(r.dot(tangential), vertical), settings.swing_noise_rad,
               settings.swing_resolution_rad, swing_rng, swing_normal);
    state.swing_rad = dynamics::swing_angle(state.swing_radial_rad, state.swing_tangential_rad);
  }

  // Holds every joint for a few steps so feedback carries the static loads.
  void settle_loads() {
    for (int k = 0; k < 3; ++k) step_physics(true);
    load_pressure.setZero();
    force_filtered.setZero();
    update_loads(1.0);
  }

  // Motor reaction along the joint axis on the child body: the actuator's generalized effort.
  double joint_effort(int i) const {
    const dJointFeedback& fb = feedback[static_cast<std::size_t>(i)];
    const dJointID j = crane->joint(i);
    const Eigen::Vector3d f(fb.f1[0], fb.f1[1], fb.f1[2]);
    if (model.joints[static_cast<std::size_t>(i - 1)].type == dynamics::JointType::kPrismatic) {
      dVector3 axis;
      dJointGetSliderAxis(j, axis);
      return Eigen::Vector3d(axis[0], axis[1], axis[2]).dot(f);
    }
    dVector3 axis, anchor;
    dJointGetHingeAxis(j, axis);
    dJointGetHingeAnchor(j, anchor);
    const dReal* com = dBodyGetPosition(crane->body(i));
    const Eigen::Vector3d t(fb.t1[0], fb.t1[1], fb.t1[2]);
    const Eigen::Vector3d r(com[0] - anchor[0], com[1] - anchor[1], com[2] - anchor[2]);
    return Eigen::Vector3d(axis[0], axis[1], axis[2]).dot(t + r.cross(f));
  }

  // Cylinder forces from the last step's motor reactions; load pressures (filtered) from them.
  void update_loads(double alpha) {
    for (int i = 0; i < model.dof(); ++i) {
      const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
      const double arm = dynamics::cylinder_arm(cyl, q[i]);
      // At an end of its range the cylinder rests on its mechanical stop, and the joint's
      // reaction includes the stop's push away from it: that part is steel, not oil. Without
      // this, a cylinder standing on its stop would read a load pressure far beyond relief and
      // its section would never open to drive it off the stop.
      double effort = joint_effort(i + 1);
      const auto& joint = model.joints[static_cast<std::size_t>(i)];
      constexpr double kAtStop = 1e-4;  // rad or m
      if (joint.q_max > joint.q_min) {
        if (q[i] <= joint.q_min + kAtStop) effort = std::min(effort, 0.0);
        if (q[i] >= joint.q_max - kAtStop) effort = std::max(effort, 0.0);
      }
      force[i] = effort / arm;
      force_filtered[i] += alpha * (force[i] - force_filtered[i]);
      // Direction of the requested motion decides which chamber is pressurised; a closed
      // section reports the chamber that holds the load.
      const double dir = requested_velocity[i] != 0.0 ? requested_velocity[i] : force[i];
      const double p = dynamics::load_pressure_pa(cyl, force[i], dir);
      load_pressure[i] += alpha * (p - load_pressure[i]);
    }
  }

  void step_physics(bool hold) {
    const int n = model.dof();
    const double hold_relief_pa = dynamics::load_holding_relief_pa(model);
    for (int i = 0; i < n; ++i) {
      const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
      const double arm = dynamics::cylinder_arm(cyl, q[i]);
      const double v = hold ? 0.0 : requested_velocity[i] * pump_result.delivered_fraction[i];
      // The last step's cylinder force (positive pushing the cylinder out) says which chamber
      // carries the load and how hard the load pushes: the load moves the cylinder the other way.
      const double f = force[i];
      const double hold_area = f >= 0.0 ? cyl.area_a_m2 : cyl.area_b_m2;
      const double load_dir = f >= 0.0 ? -1.0 : 1.0;
      // The load-holding valve carries up to its port relief setting; beyond it the valve opens
      // and the load runs ahead of what the section meters by at most the valve's relief flow:
      // the cylinder never falls freely. Creeping, the cylinder's speed moves towards that bound
      // within its acceleration limit, the valve's pressure rising up to twice its setting (its
      // override); the valve closes again when the load falls below its setting.
      const double f_hold = hold_relief_pa * hold_area;
      const double v_now = qdot[i] * arm;  // the cylinder's present speed
      const double v_allowed =
          std::max(v * load_dir, 0.0) + model.load_holding.relief_flow_m3_s / hold_area;
      if (hold || (creep[i] && std::abs(f) < kReseatShare * f_hold)) creep[i] = false;
      if (!hold && model.load_holding.relief_flow_m3_s > 0.0 &&
          v_now * load_dir > v_allowed + kCreepSlackM_S) {
        creep[i] = true;
      }
      // The pump pushes a motion whose force is along it (a resistive load, or the inertia of a
      // start); a held or over-running cylinder rests on its load-holding valve.
      const bool pushing = v != 0.0 && v * f >= 0.0;
      double v_target = v;
      double f_max = 0.0;
      if (creep[i]) {
        stall[i] = false;
        const double dv = cyl.a_max_m_s2 * settings.step_s;
        v_target = std::clamp(load_dir * v_allowed, v_now - dv, v_now + dv);
        f_max = kReliefOverride * f_hold;
      } else if (pushing) {
        // A resistive load is pushed by the pump, at most at its pressure ceiling (relief; p_s for
        // a constant-pressure pump). A load it cannot move (the pump at its ceiling, the cylinder
        // going back against the command) stalls the section: the load-holding valve (a check
        // valve towards the pump) keeps it from going back.
        const double f_push = supply_ceiling_pa * (v > 0.0 ? cyl.area_a_m2 : cyl.area_b_m2);
        stall[i] = stall[i] ? std::abs(f) >= kReseatShare * f_push
                            : std::abs(f) >= kSaturatedShare * f_push && v_now * v < 0.0;
        v_target = stall[i] ? 0.0 : v;
        f_max = stall[i] ? f_hold : f_push;
      } else {
        // An over-running load (force against the motion, e.g. a boom being lowered) and a held
        // one are carried by the chamber that holds the load, through its load-holding valve.
        stall[i] = false;
        f_max = f_hold;
      }
      f_max *= std::abs(arm);
      const dJointID j = crane->joint(i + 1);
      // Seal and guide friction against the cylinder's motion.
      const double friction_effort =
          -dynamics::friction_force_n(cyl.friction, v_now, kFrictionSmoothingM_S) * arm;
      if (model.joints[static_cast<std::size_t>(i)].type == dynamics::JointType::kPrismatic) {
        dJointSetSliderParam(j, dParamVel, v_target / arm);
        dJointSetSliderParam(j, dParamFMax, f_max);
        if (friction_effort != 0.0) dJointAddSliderForce(j, friction_effort);
      } else {
        dJointSetHingeParam(j, dParamVel, v_target / arm);
        dJointSetHingeParam(j, dParamFMax, f_max);
        if (friction_effort != 0.0) dJointAddHingeTorque(j, friction_effort);
      }
    }
    damp_link();
    dWorldStep(world, settings.step_s);
    crane->read_state(q, qdot);
  }

  // Both chambers from the (filtered) cylinder force: the one that returns to tank at the return
  // pressure, the other carrying the force; then the sensors' noise and resolution.
  void measure_chambers() {
    const double p_ret = settings.return_pressure_pa;
    for (int i = 0; i < model.dof(); ++i) {
      const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
      const double f = force_filtered[i];
      double pa = p_ret, pb = p_ret;
      if (f >= 0.0) {
        pa = (f + p_ret * cyl.area_b_m2) / cyl.area_a_m2;
      } else {
        pb = (p_ret * cyl.area_a_m2 - f) / cyl.area_b_m2;
      }
      pressure_a[i] = sensor(pa);
      pressure_b[i] = sensor(pb);
    }
  }

  double sensor(double p) {
    return std::max(
        sensed(p, settings.pressure_noise_pa, settings.pressure_resolution_pa, rng, normal), 0.0);
  }

  void step() {
    const int n = model.dof();
    for (int i = 0; i < n; ++i) {
      const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
      requested_velocity[i] = sections[static_cast<std::size_t>(i)].step(spool_command[i]);
      demand[i] = dynamics::cylinder_flow_m3_s(cyl, requested_velocity[i]);
    }
    pump.solve(demand, load_pressure, pump_result);
    step_physics(false);
    update_loads(load_alpha);
    if (!settings.joints.exact()) record_joints();  // exact readings need no history
    t_s += settings.step_s;
    energy_j += pump_result.power_w * settings.step_s;
  }

  dynamics::CraneModel model;
  SimSettings settings;
  PumpModel pump;
  dWorldID world;
  dThreadingImplementationID threading = nullptr;
  std::unique_ptr<dynamics::OdeCrane> crane;
  std::vector<dJointFeedback> feedback;
  std::vector<ValveSection> sections;
  std::vector<JointVector> history_q, history_qdot;  // ring, newest at history_head
  std::size_t history_head = 0;
  std::mt19937 joint_rng{3};
  std::normal_distribution<double> joint_normal{0.0, 1.0};
  std::uniform_real_distribution<double> uniform{0.0, 1.0};
  JointVector spool_command, requested_velocity, demand, load_pressure, force, q, qdot;
  JointVector force_filtered, pressure_a, pressure_b;
  std::array<bool, dynamics::kMaxJoints> creep{}, stall{};
  dBodyID load_body = nullptr;  // the grapple (rigid: with the payload)
  dJointID load_joint = nullptr;
  dBodyID payload_body = nullptr;  // hanging grapple only
  dJointID payload_joint = nullptr;
  double tip_mass_kg = 0.0;
  Eigen::Vector3d tip_inertia = Eigen::Vector3d::Zero();
  double payload_kg = 0.0;
  std::mt19937 rng{1};
  std::normal_distribution<double> normal{0.0, 1.0};
  // The swing sensor's own noise (the pressure sensors' sequence unchanged); measured in a const
  // read, like a sensor.
  mutable std::mt19937 swing_rng{2};
  mutable std::normal_distribution<double> swing_normal{0.0, 1.0};
  bool active = true;  // inactive: the spools are commanded neutral
  PumpResult pump_result;
  double load_alpha = 1.0;
  double supply_ceiling_pa = dynamics::supply_pressure_ceiling_pa(model.pump);
  double t_s = 0.0;
  double energy_j = 0.0;
};

SimBackend::SimBackend(const dynamics::CraneModel& model, const SimSettings& settings) {
  if (!(settings.step_s > 0.0 && settings.step_s <= 0.01)) {
    throw std::invalid_argument("simulation step must be in (0, 10 ms]");
  }
  if (settings.q_initial.size() != model.dof()) {
    throw std::invalid_argument("initial configuration has the wrong number of joints");
  }
  if (model.pump.mode == dynamics::PumpMode::kConstantPressure &&
      !(model.pump.supply_pressure_pa > 0.0)) {
    throw std::invalid_argument("a constant-pressure pump needs a positive supply pressure");
  }
  impl_ = std::make_unique<Impl>(model, settings);
}

SimBackend::~SimBackend() = default;

valves::BackendStatus SimBackend::read(valves::MachineState& state) {
  Impl& s = *impl_;
  state.t_s = s.t_s;
  s.measure_joints(state.q, state.qdot);
  state.load_pressure_pa = s.load_pressure;
  impl_->measure_chambers();
  state.pressure_a_pa = s.pressure_a;
  state.pressure_b_pa = s.pressure_b;
  state.chamber_pressures = true;
  state.payload_truth_kg = s.payload_kg;
  s.measure_swing(state);
  state.pump.flow_m3_s = s.pump_result.flow_m3_s;
  state.pump.pressure_pa = s.pump_result.supply_pressure_pa;
  state.pump.power_w = s.pump_result.power_w;
  state.pump.energy_j = s.energy_j;
  state.pump.limit = s.pump_result.limit;
  state.valid = state.q.allFinite() && state.qdot.allFinite();
  return state.valid ? valves::BackendStatus::kOk : valves::BackendStatus::kFault;
}

valves::BackendStatus SimBackend::write(const valves::ValveCommand& command) {
  if (command.spool.size() != impl_->model.dof()) return valves::BackendStatus::kFault;
  if (std::isfinite(command.simulated_load_kg)) set_payload_mass(command.simulated_load_kg);
  if (!impl_->active) return valves::BackendStatus::kOk;  // held neutral until activate()
  impl_->spool_command = command.spool;
  return valves::BackendStatus::kOk;
}

bool SimBackend::activate(double, std::string*) {
  impl_->active = true;
  return true;
}

void SimBackend::safe_stop() noexcept {
  impl_->active = false;
  impl_->spool_command.setZero();
}

void SimBackend::advance(double dt_s) {
  const auto steps = std::lround(dt_s / impl_->settings.step_s);
  for (long k = 0; k < steps; ++k) impl_->step();
}

void SimBackend::set_pump_flow_limit(double flow_m3_s) noexcept {
  impl_->pump.set_flow_limit(flow_m3_s);
}

double SimBackend::pump_flow_limit() const noexcept {
  return impl_->pump.flow_limit();
}

void SimBackend::set_payload_mass(double mass_kg) noexcept {
  if (!(mass_kg >= 0.0 && mass_kg <= 1e5) || mass_kg == impl_->payload_kg) return;
  impl_->payload_kg = mass_kg;
  impl_->apply_load_mass();
}

double SimBackend::payload_mass() const noexcept {
  return impl_->payload_kg;
}

bool SimBackend::relief_passing(int joint) const noexcept {
  return joint >= 0 && joint < impl_->model.dof() && impl_->creep[static_cast<std::size_t>(joint)];
}

bool SimBackend::stalled(int joint) const noexcept {
  return joint >= 0 && joint < impl_->model.dof() && impl_->stall[static_cast<std::size_t>(joint)];
}

double SimBackend::time_s() const {
  return impl_->t_s;
}

const JointVector& SimBackend::cylinder_force_n() const {
  return impl_->force;
}

}  // namespace craneassist::sim_backend
