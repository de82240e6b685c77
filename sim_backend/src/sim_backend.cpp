#include "craneassist/sim_backend/sim_backend.hpp"

#include <ode/ode.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/ode_crane.hpp"
#include "craneassist/sim_backend/pump_model.hpp"
#include "craneassist/sim_backend/valve_section.hpp"

namespace craneassist::sim_backend {
namespace {

constexpr double kLoadPressureTimeConstantS = 0.005;  // stands in for oil compressibility
constexpr double kWorldErp = 0.2;
constexpr double kWorldCfm = 1e-10;

}  // namespace

struct SimBackend::Impl {
  Impl(const dynamics::CraneModel& m, const SimSettings& s)
      : model(m), settings(s), pump(m.pump), world(make_world(m)) {
    // A threading implementation of this world's own: ODE's shared default aborts when two
    // worlds step at the same time in different threads.
    threading = dThreadingAllocateSelfThreadedImplementation();
    dWorldSetStepThreadingImplementation(world, dThreadingImplementationGetFunctions(threading),
                                         threading);
    crane = std::make_unique<dynamics::OdeCrane>(model, world, s.q_initial);
    crane->enable_end_stops(true);
    const int n = model.dof();
    feedback.resize(static_cast<std::size_t>(n) + 1);
    for (int i = 1; i <= n; ++i) {
      dJointSetFeedback(crane->joint(i), &feedback[static_cast<std::size_t>(i)]);
      sections.emplace_back(model.valves,
                            model.cylinders[static_cast<std::size_t>(i - 1)].v_max_m_s, s.step_s);
    }
    spool_command.setZero(n);
    requested_velocity.setZero(n);
    demand.setZero(n);
    load_pressure.setZero(n);
    force.setZero(n);
    q.setZero(n);
    qdot.setZero(n);
    pump_result.delivered_fraction.setZero(n);
    load_alpha = 1.0 - std::exp(-s.step_s / kLoadPressureTimeConstantS);
    crane->read_state(q, qdot);
    // Start from the static holding loads so the first steps see the right pump pressure.
    settle_loads();
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

  // Holds every joint for a few steps so feedback carries the static loads.
  void settle_loads() {
    for (int k = 0; k < 3; ++k) step_physics(true);
    load_pressure.setZero();
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
      // Direction of the requested motion decides which chamber is pressurised; a closed
      // section reports the chamber that holds the load.
      const double dir = requested_velocity[i] != 0.0 ? requested_velocity[i] : force[i];
      const double p = std::copysign(1.0, dir) * force[i] / dynamics::flow_area_m2(cyl, dir);
      load_pressure[i] += alpha * (p - load_pressure[i]);
    }
  }

  void step_physics(bool hold) {
    const int n = model.dof();
    for (int i = 0; i < n; ++i) {
      const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
      const double arm = dynamics::cylinder_arm(cyl, q[i]);
      const double v = hold ? 0.0 : requested_velocity[i] * pump_result.delivered_fraction[i];
      // Relief pressure caps the force. A resistive load (force along the motion) is pushed by
      // the pump on the pressurised chamber; an over-running load (force against the motion,
      // e.g. a boom being lowered) and a held one are carried by the opposite chamber through
      // its load-holding valve, set at relief too.
      const bool resistive = v * force[i] > 0.0;
      const double area = v > 0.0 ? (resistive ? cyl.area_a_m2 : cyl.area_b_m2)
                                  : (v < 0.0 ? (resistive ? cyl.area_b_m2 : cyl.area_a_m2)
                                             : std::max(cyl.area_a_m2, cyl.area_b_m2));
      // The pump pushes at most at its pressure ceiling (relief; p_s for a constant-pressure
      // pump); the load-holding valves hold up to relief.
      const double p_cap = resistive ? supply_ceiling_pa : model.pump.max_pressure_pa;
      const double f_max = p_cap * area * std::abs(arm);
      const dJointID j = crane->joint(i + 1);
      if (model.joints[static_cast<std::size_t>(i)].type == dynamics::JointType::kPrismatic) {
        dJointSetSliderParam(j, dParamVel, v / arm);
        dJointSetSliderParam(j, dParamFMax, f_max);
      } else {
        dJointSetHingeParam(j, dParamVel, v / arm);
        dJointSetHingeParam(j, dParamFMax, f_max);
      }
    }
    dWorldStep(world, settings.step_s);
    crane->read_state(q, qdot);
  }

  void step() {
    const int n = model.dof();
    for (int i = 0; i < n; ++i) {
      const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
      requested_velocity[i] = sections[static_cast<std::size_t>(i)].step(spool_command[i]);
      demand[i] =
          dynamics::flow_area_m2(cyl, requested_velocity[i]) * std::abs(requested_velocity[i]);
    }
    pump.solve(demand, load_pressure, pump_result);
    step_physics(false);
    update_loads(load_alpha);
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
  JointVector spool_command, requested_velocity, demand, load_pressure, force, q, qdot;
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
  const Impl& s = *impl_;
  state.t_s = s.t_s;
  state.q = s.q;
  state.qdot = s.qdot;
  state.load_pressure_pa = s.load_pressure;
  state.pump.flow_m3_s = s.pump_result.flow_m3_s;
  state.pump.pressure_pa = s.pump_result.supply_pressure_pa;
  state.pump.power_w = s.pump_result.power_w;
  state.pump.energy_j = s.energy_j;
  state.pump.limit = s.pump_result.limit;
  state.valid = s.q.allFinite() && s.qdot.allFinite();
  return state.valid ? valves::BackendStatus::kOk : valves::BackendStatus::kFault;
}

valves::BackendStatus SimBackend::write(const valves::ValveCommand& command) {
  if (command.spool.size() != impl_->model.dof()) return valves::BackendStatus::kFault;
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

double SimBackend::time_s() const {
  return impl_->t_s;
}

const JointVector& SimBackend::cylinder_force_n() const {
  return impl_->force;
}

}  // namespace craneassist::sim_backend
