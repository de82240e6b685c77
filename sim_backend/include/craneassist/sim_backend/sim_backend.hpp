// The ODE-simulated crane behind the machine interface: rigid-body crane (dynamics::OdeCrane)
// driven by pressure-compensated valve sections and a load-sensing or constant-pressure pump
// without flow sharing (dynamics::Pump::mode).
//
// Each simulation step (config simulation.step, 1 ms by default):
//   1. every valve section turns its (delayed, lagged) spool into a requested cylinder velocity;
//   2. the pump shares what it can deliver by load pressure (pump_model.hpp);
//   3. each joint is driven as an ODE velocity motor at the delivered cylinder velocity, its force
//      capped at the relief pressure on the chamber that carries the load (the pressurised one for
//      a resistive load, at most p_s with a constant-pressure pump; the load-holding one for an
//      over-running or held load);
//   4. the joint stops are the cylinder end stops;
//   5. the motor reaction gives the cylinder force and, through a 5 ms first-order filter standing
//      in for oil compressibility, the load pressures for the next step.
// What the controller's model lacks (docs/loads.md): the load hangs on a body of its own, welded
// to the tip, whose mass may change during a run (set_payload_mass: a log grabbed or lost);
// load-holding valves hold a load the pump cannot move and let one beyond their port relief
// creep at the valve's relief flow, never fall; cylinder friction (Coulomb each way, viscous);
// both chambers' pressures measured with sensor noise and resolution; valve sections and joint
// sensors that differ from the model's (SimSettings::valves, joints;
// dynamics/machine_deviation.hpp). Pump flow, pressure, power and integrated energy are measured on
// the way.
#pragma once

#include <memory>
#include <optional>

#include "craneassist/dynamics/machine_deviation.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::sim_backend {

using dynamics::JointVector;

struct SimSettings {
  double step_s = 1e-3;
  JointVector q_initial;
  // Chamber pressure sensors: white noise of this standard deviation, then rounded to the
  // resolution (0: exact); the seed makes a run repeatable.
  double pressure_noise_pa = 0.0;
  double pressure_resolution_pa = 0.0;
  unsigned noise_seed = 1;
  double return_pressure_pa = 0.0;  // in the chamber that returns to tank
  // The machine's valve sections where they differ from the controller's model (spool lag and
  // delay, dead band, gain, shape, hysteresis), by joint index; the defaults: the model's.
  dynamics::ValveDeviations valves{};
  // The joint sensors' noise, resolution and delay and the feedback's transport delay and
  // jitter; the default: exact and at once.
  dynamics::JointSensing joints{};
  // The machine's two-axis swing sensor on the grapple's link (MachineState::swing_*;
  // docs/sway.md): white noise of this standard deviation on each angle, then rounded to the
  // resolution (0: exact). false: the machine has none (the swing is NaN, as on a machine without
  // one).
  bool swing_sensor = true;
  double swing_noise_rad = 0.0;
  double swing_resolution_rad = 0.0;
  // The machine's grapple when it differs from the controller's model (the model's grapple
  // otherwise): a longer rotator link, another brake.
  std::optional<dynamics::HangingGrapple> grapple{};
};

class SimBackend final : public valves::MachineInterface {
 public:
  // Throws std::invalid_argument on a bad step or initial configuration, or a constant-pressure
  // pump without a positive supply pressure.
  SimBackend(const dynamics::CraneModel& model, const SimSettings& settings);
  ~SimBackend() override;
  SimBackend(const SimBackend&) = delete;
  SimBackend& operator=(const SimBackend&) = delete;

  valves::BackendStatus read(valves::MachineState& state) override;
  valves::BackendStatus write(const valves::ValveCommand& command) override;
  void advance(double dt_s) override;
  const char* name() const override { return "sim"; }
  // The simulator starts active. Inactive, its spools are commanded neutral whatever is written.
  bool activate(double timeout_s, std::string* why) override;
  void safe_stop() noexcept override;

  // The most the pump may deliver from the next step on (at most the model's max_flow): what
  // another consumer on the same pump leaves, set between steps (a crane sharing its pump with
  // a wheeled base's hub motors, docs/mobile.md). No allocation.
  void set_pump_flow_limit(double flow_m3_s) noexcept;
  double pump_flow_limit() const noexcept;

  // The mass in the grapple from the next step on (kg, 0 to 100000; anything else is ignored):
  // a log grabbed, released or slipping out. The controller is not told. No allocation.
  void set_payload_mass(double mass_kg) noexcept;
  double payload_mass() const noexcept;
  // Whether a cylinder's load passed its load-holding valve's port relief in the last step (it
  // creeps at the valve's relief flow), and whether the pump could not move its load (stalled,
  // held by the valve).
  bool relief_passing(int joint) const noexcept;
  bool stalled(int joint) const noexcept;

  double time_s() const;
  // Cylinder forces of the last step (N, positive pushing the cylinder out).
  const JointVector& cylinder_force_n() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace craneassist::sim_backend
