#include "craneassist/sim_backend/mobile_crane_backend.hpp"

#include <algorithm>
#include <cmath>

namespace craneassist::sim_backend {

void fill_base_measurement(const MobileBaseSim& base, bool shared_pump,
                           valves::BaseMeasurement& out) noexcept {
  const MobileBaseState& s = base.state();
  out.present = true;
  out.x_m = s.pose.x_m;
  out.y_m = s.pose.y_m;
  out.phi_rad = s.pose.phi_rad;
  out.v_m_s = s.velocity.v_m_s;
  out.omega_rad_s = s.velocity.omega_rad_s;
  for (std::size_t i = 0; i < 4; ++i) {
    out.steer_rad[i] = s.wheels.steer_rad[i];
    out.motor_flow_m3_s[i] = s.wheels.flow_m3_s[i];
  }
  out.motor_flow_sum_m3_s = s.wheels.flow_sum_m3_s;
  out.drive_max_flow_m3_s = base.model().pump_max_flow_m3_s;
  out.shared_pump = shared_pump;
}

MobileCraneBackend::MobileCraneBackend(const dynamics::CraneModel& crane,
                                       const SimSettings& settings,
                                       const dynamics::MobileBaseModel& base,
                                       const dynamics::BasePose& initial, bool shared_pump)
    : crane_(crane, settings),
      base_(base, initial),
      step_s_(settings.step_s),
      shared_pump_(shared_pump) {
  if (shared_pump_) crane_.set_pump_flow_limit(base.pump_max_flow_m3_s);
}

valves::BackendStatus MobileCraneBackend::read(valves::MachineState& state) {
  const valves::BackendStatus status = crane_.read(state);
  fill_base_measurement(base_, shared_pump_, state.base);
  return status;
}

valves::BackendStatus MobileCraneBackend::write(const valves::ValveCommand& command) {
  base_.command(active_ && std::isfinite(command.drive_v_m_s) &&
                        std::isfinite(command.drive_omega_rad_s)
                    ? dynamics::BaseVelocity{command.drive_v_m_s, command.drive_omega_rad_s}
                    : dynamics::BaseVelocity{});
  return crane_.write(command);
}

void MobileCraneBackend::advance(double dt_s) {
  if (!shared_pump_) {
    crane_.advance(dt_s);
    base_.advance(dt_s);
    return;
  }
  // One pump, the drive first: the base's step, then the crane's with what the motors leave.
  const long steps = std::max(1L, std::lround(dt_s / step_s_));
  const double h = dt_s / static_cast<double>(steps);
  for (long k = 0; k < steps; ++k) {
    base_.advance(h);
    crane_.set_pump_flow_limit(base_.model().pump_max_flow_m3_s -
                               base_.state().wheels.flow_sum_m3_s);
    crane_.advance(h);
  }
}

bool MobileCraneBackend::activate(double timeout_s, std::string* why) {
  active_ = true;
  return crane_.activate(timeout_s, why);
}

void MobileCraneBackend::safe_stop() noexcept {
  active_ = false;
  base_.command({});
  crane_.safe_stop();
}

}  // namespace craneassist::sim_backend
