// The measured valve characteristic (ValveTable, model.hpp) and its inverse, the dead-zone
// inverse DZI of paper 000 appendix A: piecewise-linear interpolation between the table points,
// exact at them and continuous. Pure functions over the table; none allocates or throws.
#pragma once

#include <string>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

// Empty when the table is usable; otherwise why not (for the config's error message): at least
// two points, equal lengths, commands finite, in [-1, 1] and strictly increasing, velocities
// finite and non-decreasing, equal neighbours only at zero velocity (the dead band), and both
// directions present (first velocity negative, last positive).
std::string check_valve_table(const ValveTable& table);

// Steady cylinder velocity at a spool command (held at the end values beyond the table).
double valve_table_velocity(const ValveTable& table, double command);

// The inverse (DZI): the spool command giving the cylinder velocity, interpolated between the
// table points on the side of the velocity's sign, saturating at the end points beyond the
// table's speeds. A velocity below 1e-4 of the table's top speed on its side (or NaN) gives 0, so
// the section stays neutral instead of sitting at the dead-band edge (the straight-line rule).
double valve_table_command(const ValveTable& table, double velocity_m_s);

// The dead-band edge on one side (side > 0: extension, else retraction): the outermost command
// that still gives no motion that way (signed; e.g. 0.53 and -0.53).
double valve_table_dead_band_edge(const ValveTable& table, double side);

// Section i's spool time constant and transport delay: its table's where measured, else the
// valves' (hydraulics.valves.time_constant, delay); the longest delay plus time constant over
// the sections.
double section_time_constant_s(const CraneModel& model, int i);
double section_delay_s(const CraneModel& model, int i);
double longest_valve_lag_s(const CraneModel& model);

// The straight-line characteristic of the model without a table: no flow over |u| <= dead_zone,
// then linear up to v_max at |u| = 1, symmetric.
ValveTable straight_line_valve_table(double dead_zone, double v_max_m_s);

}  // namespace craneassist::dynamics
