// The contract between the control loop and a machine, simulated or real (ros2_control's
// hardware_interface is the model): read the measured state, write valve commands. The loop
// never knows which backend it drives.
#pragma once

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

struct MachineState {
  double t_s = 0.0;
  JointVector q;                 // joint positions, rad or m
  JointVector qdot;              // joint rates
  JointVector load_pressure_pa;  // per cylinder; positive: resistive load (paper 004 sign)
  PumpMeasurement pump;
  bool valid = false;
};

// Normalised spool command per section: -1 (full retract) .. 0 (neutral) .. +1 (full extend),
// i.e. the valve current scaled to its range.
struct ValveCommand {
  JointVector spool;
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
};

}  // namespace craneassist::valves
