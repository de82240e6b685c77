// The contract between the control loop and a machine, simulated or real (ros2_control's
// hardware_interface is the model): a lifecycle (activate, safe stop, deactivate), read the
// measured state, write valve commands. No caller asks which backend it drives.
#pragma once

#include <limits>
#include <string>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::valves {

using dynamics::JointVector;

// Which pump limit holds the delivered flow below the demand (none when demand is met).
enum class PumpLimit { kNone, kMaxFlow, kPower, kRelief };
const char* to_string(PumpLimit limit);

struct PumpMeasurement {
  double flow_m3_s = 0.0;
  double pressure_pa = 0.0;  // supply pressure
  double power_w = 0.0;      // hydraulic power at the pump outlet, pressure * flow
  double energy_j = 0.0;     // integrated since the start
  PumpLimit limit = PumpLimit::kNone;
};

// The wheeled base under the crane, on a machine that has one (docs/mobile.md): its pose in the
// world (x, y, heading), its motion, and the hub motors' steering angles and flows (front left,
// front right, rear left, rear right).
struct BaseMeasurement {
  bool present = false;  // false: a crane on a fixed base; the rest is zero
  double x_m = 0.0, y_m = 0.0, phi_rad = 0.0;
  double v_m_s = 0.0, omega_rad_s = 0.0;
  double steer_rad[4] = {0.0, 0.0, 0.0, 0.0};
  double motor_flow_m3_s[4] = {0.0, 0.0, 0.0, 0.0};
  double motor_flow_sum_m3_s = 0.0;
  double drive_max_flow_m3_s = 0.0;  // Q_max of the drive pump
  bool shared_pump = false;          // the crane's pump flow counts against the same Q_max
};

struct MachineState {
  double t_s = 0.0;
  JointVector q;                 // joint positions, rad or m
  JointVector qdot;              // joint rates
  JointVector load_pressure_pa;  // per cylinder; positive: resistive load (paper 004 sign)
  // Each cylinder's piston-side (A) and rod-side (B) chamber pressures, NaN for a chamber the
  // machine does not measure; chamber_pressures: some cylinder has both measured. The crane
  // scale weighs the load from the cylinders that have (dynamics::PayloadEstimator).
  JointVector pressure_a_pa, pressure_b_pa;
  bool chamber_pressures = false;
  // The simulator's truth: the mass in the grapple (NaN on a machine, which does not know it).
  double payload_truth_kg = std::numeric_limits<double>::quiet_NaN();
  // The hanging grapple's swing (docs/sway.md), rad: the hanger's angle from the vertical, and
  // its two components, towards the load's reach (radial: the grapple further out than the tip)
  // and across it (tangential: towards a positive slew). NaN where nothing measures it (a rigid
  // tip; a machine without a swing sensor).
  double swing_rad = std::numeric_limits<double>::quiet_NaN();
  double swing_radial_rad = std::numeric_limits<double>::quiet_NaN();
  double swing_tangential_rad = std::numeric_limits<double>::quiet_NaN();
  PumpMeasurement pump;
  BaseMeasurement base;
  bool valid = false;
};

// Normalised spool command per section: -1 (full retract) .. 0 (neutral) .. +1 (full extend),
// i.e. the valve current scaled to its range.
struct ValveCommand {
  JointVector spool;
  // The wheeled base's velocity command (forward speed, yaw rate), on a machine that has one
  // (sim --base); ignored by a crane on a fixed base. Zero: stand still.
  double drive_v_m_s = 0.0;
  double drive_omega_rad_s = 0.0;
  // The load a replay puts in a simulated crane's grapple from this cycle on (its load_kg column;
  // docs/replay-format.md); NaN: unchanged. A real machine ignores it.
  double simulated_load_kg = std::numeric_limits<double>::quiet_NaN();
};

enum class BackendStatus { kOk, kNoData, kFault };
const char* to_string(BackendStatus status);

class MachineInterface {
 public:
  virtual ~MachineInterface() = default;
  // Latest measurement. Must not block or allocate.
  virtual BackendStatus read(MachineState& state) = 0;
  // Valve command for the coming cycle. Must not block or allocate.
  virtual BackendStatus write(const ValveCommand& command) = 0;
  // Lets dt_s of machine time pass: the simulator integrates, a real machine does nothing (the
  // loop's clock paces it).
  virtual void advance(double dt_s) = 0;
  virtual const char* name() const = 0;
  // How often a written command reaches the valves, s: 0 when every write does (the simulator);
  // a bus backend sends at its own cycle and the valves hold the latest command in between. The
  // valve control must not rely on a single cycle's command then (ReferenceFollower).
  virtual double command_period_s() const { return 0.0; }
  // True when the machine moves in real time whatever the loop does (a real machine): the loop
  // must then be paced at its period. The simulator waits for advance().
  virtual bool real_time() const { return false; }

  // Lifecycle (ros2_control's activate/deactivate). While inactive every valve is held in its
  // safe state (neutral, or blocked where the valve has that state) whatever is written. The
  // simulator starts active; a bus machine starts inactive.
  //
  // Makes the machine ready to move: a bus machine waits up to timeout_s for every joint's
  // feedback, then enables its valves (a deliberate enable also clears a latched fault). May
  // block: call it before the loop. False, with the reason in *why, when it cannot.
  virtual bool activate(double timeout_s, std::string* why) = 0;
  // Every valve to its safe state now, and held there until activate(). For the control
  // thread: non-blocking, allocation-free. The loop calls it when a stop cannot bring the crane
  // to rest in time.
  virtual void safe_stop() noexcept = 0;
  // The normal end of a run, after the loop has brought the crane to rest: safe_stop(), then
  // the backend's own threads end (a bus machine's watchdog, its traffic log). May block
  // briefly.
  virtual void deactivate() { safe_stop(); }
  // Whether a fault has latched that only a deliberate activate() clears (a bus machine's lost
  // feedback, bus-off), and its text for the operator ("" when none; not for the control
  // thread).
  virtual bool faulted() const { return false; }
  virtual std::string fault_text() const { return {}; }
};

}  // namespace craneassist::valves
