// The crane on wheels behind the machine interface (sim --base, docs/mobile.md#live): the ODE
// crane (SimBackend) standing on the simulated wheeled base (MobileBaseSim). write() takes the
// crane's spools and the base's velocity command (ValveCommand::drive_*); read() gives the
// crane's joints and pump as on a fixed base (the tip controller works in the crane's frame) and
// the base's pose, motion and hub-motor flows (MachineState::base), from which the tip's world
// position follows (dynamics::world_from_crane_base).
//
// With a shared pump (BaseConfig::shared_with_crane) the drive and the crane draw on one pump of
// the drive's Q_max, the drive first: each simulation step the base moves, then the crane's pump
// may deliver at most what the motors leave (SimBackend::set_pump_flow_limit), so the summed
// motor and crane flow never exceeds Q_max.
//
// read(), write() and advance() allocate nothing and throw nothing.
#pragma once

#include "craneassist/sim_backend/mobile_base_sim.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

namespace craneassist::sim_backend {

class MobileCraneBackend final : public valves::MachineInterface {
 public:
  // The base starts at rest at `initial`. Throws as SimBackend does.
  MobileCraneBackend(const dynamics::CraneModel& crane, const SimSettings& settings,
                     const dynamics::MobileBaseModel& base, const dynamics::BasePose& initial,
                     bool shared_pump);

  valves::BackendStatus read(valves::MachineState& state) override;
  valves::BackendStatus write(const valves::ValveCommand& command) override;
  void advance(double dt_s) override;
  const char* name() const override { return "sim"; }
  bool activate(double timeout_s, std::string* why) override;
  // The crane's spools neutral and the base's command zero (it comes to rest through its lag).
  void safe_stop() noexcept override;

  const SimBackend& crane() const noexcept { return crane_; }
  const MobileBaseSim& base() const noexcept { return base_; }
  bool shared_pump() const noexcept { return shared_pump_; }

 private:
  SimBackend crane_;
  MobileBaseSim base_;
  double step_s_;
  bool shared_pump_;
  bool active_ = true;
};

// The base part of a measurement (MachineState::base) from the simulated base.
void fill_base_measurement(const MobileBaseSim& base, bool shared_pump,
                           valves::BaseMeasurement& out) noexcept;

}  // namespace craneassist::sim_backend
