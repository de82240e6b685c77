// The Modular Hydraulic Servo Booster arm simulated (paper 001 section 4; docs/mhsb-simulator.md):
// the rigid arm in ODE (dynamics::OdeCrane: gravity, payload, end stops), each joint driven by its
// cylinder's force through the torque arm, the MHSB circuit per actuator (servo-valve, chambers
// with oil compressibility, the supply node in N, DB or SB: the main pump line, or one or two
// servo-pumps in series with it behind a check valve, a relief) and the paper's cascade controller
// (position PI with gravity compensation -> desired force -> servo-valve PI; servo-pump speed PI
// tracking the pressure the gravity load needs; in N the servo-pumps stand).
//
// One step() is one control period (250 Hz, 4 ms, as the paper's local controllers); inside it the
// rigid body steps at plant.mechanical_step_s and the pressures at plant.hydraulic_substeps per
// rigid-body step (explicit Euler; docs/mhsb-simulator.md says why these steps are stable and
// accurate). step() allocates nothing and throws nothing.
//
// Cylinder conventions as in mhsb/mhsb.hpp: chamber A is the piston side (area_a_m2), B the rod
// side; the force F = A_A p_A - A_B p_B pushes the rod out; the spool x > 0 connects supply to A
// and B to tank.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <ostream>

#include "craneassist/dynamics/model.hpp"
#include "craneassist/mhsb/mhsb.hpp"

namespace craneassist::mhsb {

using dynamics::JointVector;

// The plant's assumed parameters (paper 001 gives none of them for the three-link arm; Table 3 the
// servo-pump's displacement). SI units.
struct MhsbPlantSettings {
  double mechanical_step_s = 0.25e-3;     // ODE step; a divisor of the control period
  int hydraulic_substeps = 10;            // pressure steps per ODE step (25 us)
  double bulk_modulus_pa = 1.0e9;         // effective: oil 1.4-1.6 GPa, softened by hoses
  double chamber_dead_volume_m3 = 20e-6;  // each chamber at its end of stroke, hose included
  double supply_node_volume_m3 = 20e-6;   // the boosted line between servo-pump(s) and valve
  double main_line_volume_m3 = 500e-6;    // the main pump's line
  // The main pump's pressure compensator: full flow at P0 - band, none at P0.
  double compensator_band_pa = 0.05e6;
  // Below this drop a servo-valve edge is laminar (Q linear in dp), so dQ/dp stays finite at
  // dp = 0; the check valve turns laminar below a quarter of its rated drop.
  double laminar_drop_pa = 0.01e6;
  // The valve's leakage (hydraulics.mhsb.servo_valve.leakage) flows whenever the supply is more
  // than this above tank; below it, in proportion.
  double leakage_full_drop_pa = 0.2e6;
  // Check valve from the main line to a boosted supply node: opens at cracking, passes rated flow
  // at cracking + rated drop.
  double check_cracking_pa = 0.02e6;
  double check_rated_flow_m3_s = 2.0 / 60000.0;
  double check_rated_drop_pa = 0.2e6;
  // Relief valves (main line and every boosted node) open at model.pump.max_pressure_pa and pass
  // relief_rated_flow_m3_s at relief_override_pa above it.
  double relief_override_pa = 0.5e6;
  double relief_rated_flow_m3_s = 3.0 / 60000.0;
  // Servo-pump: displacement (paper 001 Table 3: 0.18 cm^3/rev), first-order speed response to
  // its command, speed limit. 0: the speed at which one servo-pump delivers the config's
  // servo_pump_max_flow plus the valve's leakage (so the cylinder gets servo_pump_max_flow, the
  // planner's DB limit; docs/mhsb-simulator.md).
  double servo_pump_displacement_m3_rad = 0.18e-6 / (2.0 * 3.141592653589793);
  double servo_pump_time_constant_s = 0.02;
  double servo_pump_max_speed_rad_s = 0.0;
  double cylinder_viscous_friction_n_s_m = 2000.0;  // piston and rod seals
};

// The cascade controller's gains (assumed; docs/mhsb-simulator.md). Position loop in cylinder
// space: desired force = gravity and inertia feedforward + kp e + ki int(e) + kd (v_ref - v), e the
// cylinder length error.
struct MhsbControllerSettings {
  double period_s = 0.004;                    // paper 001 section 4.1: 250 Hz
  double position_kp_n_m = 4e5;               // N per m of cylinder error
  double position_ki_n_m_s = 1e5;             // N per m s
  double position_kd_n_s_m = 5e3;             // N per m/s (damping; see the docs)
  double position_integral_limit_n = 2000.0;  // |ki int(e)| at most
  // Force loop: spool = flow feedforward + kp (f_ref - f) + ki int(f_ref - f), kp and ki scaled
  // by force_gain_rated_flow_m3_s / the valve's rated flow, so that the loop's flow per newton of
  // error is the same for any valve size (the gains were tuned on a 2 L/min valve).
  double force_kp_1_n = 1e-4;
  double force_ki_1_n_s = 2e-3;
  double force_gain_rated_flow_m3_s = 2.0 / 60000.0;
  double force_integral_limit = 0.5;  // spool fraction
  double flow_feedforward = 1.0;      // 0: none; 1: the opening that passes v_ref at the drop
  // Servo-pump loop: speed = flow feedforward + kp (P_ref - p_s) + ki int(P_ref - p_s), per
  // actuator, shared by its servo-pumps. P_ref = the supply pressure that moves the gravity load at
  // v_ref through the valve opened to pressure_target_opening, plus pressure_target_margin_pa.
  double pump_kp_rad_s_pa = 2e-4;
  double pump_ki_rad_s2_pa = 2e-3;
  double pressure_target_opening = 0.8;
  double pressure_target_margin_pa = 0.1e6;
  bool pressure_target_from_force_ref = true;
};

struct MhsbSettings {
  MhsbPlantSettings plant;
  MhsbControllerSettings controller;
};

// What the planner gives each control period.
struct MhsbReference {
  JointVector q, qdot, qddot;
  mhsb::ModePattern modes;
};

enum class MhsbStepStatus : std::uint8_t {
  kOk,
  // The reference has the wrong size, a non-finite value or more boost modules than fitted: the
  // last valid reference is held (its position, at rest) with its modes.
  kInvalidReference,
  // An ODE step (rigid body or the gravity probe) failed for want of memory: the last feedforward
  // is kept.
  kDynamicsFailed,
};
const char* to_string(MhsbStepStatus status);

inline constexpr int kMaxServoPumps = 8;

// Everything step() measures, per joint unless said otherwise.
struct MhsbState {
  double t_s = 0.0;
  JointVector q, qdot;
  JointVector q_error;         // reference - measured (rad or m)
  JointVector cylinder_m;      // piston position from the retracted end
  JointVector p_a_pa, p_b_pa;  // chambers
  JointVector p_supply_pa;     // the valve's supply (the main line in N)
  JointVector p_target_pa;     // the servo-pump loop's P_ref (0 in N)
  JointVector force_n;         // A_A p_A - A_B p_B
  JointVector force_ref_n;     // the position loop's desired force
  JointVector spool_command;   // -1..1
  JointVector spool;           // the spool's position (after the lag)
  mhsb::ModePattern modes;
  std::array<double, kMaxServoPumps> pump_speed_rad_s{};  // per module
  std::array<int, kMaxServoPumps> pump_joint{};           // the joint a module feeds, -1: none
  double p_main_pa = 0.0;
  double main_flow_m3_s = 0.0;  // the main pump's delivered flow
  double main_power_w = 0.0;    // p_main * main flow
  double servo_pump_power_w = 0.0;
  double main_energy_j = 0.0;
  double servo_pump_energy_j = 0.0;
  double relief_energy_j = 0.0;  // dissipated in the reliefs
  double energy_j() const { return main_energy_j + servo_pump_energy_j; }
};

class MhsbSimulator {
 public:
  // model needs hydraulics.mhsb and a constant-pressure main pump; q_initial its dof. Throws
  // std::invalid_argument for a model or settings it cannot simulate (naming the field) and
  // std::runtime_error for ODE resources. The arm starts at rest at q_initial in all-N, its
  // chamber pressures holding the gravity load.
  MhsbSimulator(const dynamics::CraneModel& model, const MhsbSettings& settings,
                const JointVector& q_initial);
  ~MhsbSimulator();
  MhsbSimulator(const MhsbSimulator&) = delete;
  MhsbSimulator& operator=(const MhsbSimulator&) = delete;

  // One control period: the controller reads the state and the reference, then the plant advances
  // by settings.controller.period_s. No allocation, no exception.
  MhsbStepStatus step(const MhsbReference& reference) noexcept;

  const MhsbState& state() const;
  const dynamics::CraneModel& model() const;
  const MhsbSettings& settings() const;
  int dof() const;
  // Servo-pumps fitted (model.mhsb->modules) and their speed limit.
  int servo_pumps() const;
  double servo_pump_max_speed_rad_s() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The reference as a function of time (seconds from the start of the run).
using MhsbReferenceFunction = std::function<void(double t_s, MhsbReference& out)>;

struct MhsbRunSummary {
  double duration_s = 0.0;
  JointVector max_abs_error;  // per joint, rad or m
  double max_abs_error_any = 0.0;
  JointVector max_p_supply_pa;
  double energy_j = 0.0;
  double main_energy_j = 0.0;
  double servo_pump_energy_j = 0.0;
  int invalid_references = 0;
  int dynamics_failures = 0;
};

// Runs the reference for duration_s (whole control periods) from the simulator's present state;
// writes one CSV row per period to csv when given (columns in docs/mhsb-simulator.md).
MhsbRunSummary run_mhsb_reference(MhsbSimulator& sim, const MhsbReferenceFunction& reference,
                                  double duration_s, std::ostream* csv = nullptr);
// The CSV header line of run_mhsb_reference for a dof-joint arm with `pumps` servo-pumps.
void write_mhsb_csv_header(std::ostream& out, int dof, int pumps);
void write_mhsb_csv_row(std::ostream& out, const MhsbState& state, const MhsbReference& reference,
                        int pumps);

}  // namespace craneassist::mhsb
