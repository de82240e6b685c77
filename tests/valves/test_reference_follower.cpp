// The reference follower (valves/reference_follower.hpp): the valve command of a joint reference
// through the dead-zone inverse (a measured valve table included), the slew-rate limit on every
// command, neutral reached at that rate, and the position error measured against the reference of
// one valve delay ago.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "craneassist/valves/reference_follower.hpp"
#include "curved_valve_table.hpp"

namespace {

using namespace craneassist;
using dynamics::ValveTable;

using test::curved_table;

}  // namespace

// The follower goes through the table too: once the spool lag is crossed, it commands the
// table's inverse of the cylinder velocity reference.
TEST(ReferenceFollower, CommandsTheTableInverse) {
  auto cfg = config::default_crane_config();
  cfg.model.valves.tables.assign(4, curved_table());
  valves::ReferenceFollower follower(cfg.model, 0.0, 0.01);
  const dynamics::JointVector q = cfg.simulation.q_initial;
  follower.reset(q);
  dynamics::JointVector qdot = dynamics::JointVector::Zero(4);
  qdot[3] = 0.07;  // extension, m/s (arm 1)
  qdot[1] = -0.1;  // lift down, rad/s
  dynamics::JointVector arms;
  dynamics::cylinder_arms(cfg.model, q, arms);
  valves::ValveCommand out;
  follower.update(q, qdot, nullptr, out);
  // From neutral: led through the dead band, at most the slew-rate limit per cycle.
  EXPECT_EQ(out.spool[3], follower.max_step());
  for (int k = 0; k < 30; ++k) follower.update(q, qdot, nullptr, out);
  EXPECT_NEAR(out.spool[3], dynamics::valve_table_command(curved_table(), arms[3] * 0.07), 1e-9);
  EXPECT_NEAR(out.spool[1], dynamics::valve_table_command(curved_table(), arms[1] * -0.1), 1e-9);
  EXPECT_EQ(out.spool[0], 0.0);
}

TEST(ReferenceFollower, EveryCommandWithinTheSlewRateAndNeutralAtThatRate) {
  const auto cfg = config::default_crane_config();
  const double period = 0.01;
  valves::ReferenceFollower follower(cfg.model, cfg.control.position_gain_1_s, period);
  const double step = follower.max_step();
  ASSERT_GT(step, 0.0);
  ASSERT_LT(step, 2.0);  // the K70M's valves have a stroke time
  dynamics::JointVector q = cfg.simulation.q_initial;
  follower.reset(q);
  dynamics::JointVector qdot(4);
  qdot << 0.2, -0.15, 0.2, 0.1;  // every section, both directions
  valves::ValveCommand out, last;
  last.spool = dynamics::JointVector::Zero(4);
  for (int k = 0; k < 100; ++k) {
    follower.update(q, qdot, &q, out);
    for (int i = 0; i < 4; ++i) EXPECT_LE(std::abs(out.spool[i] - last.spool[i]), step + 1e-12);
    last = out;
    q += qdot * period;
  }
  const double open = last.spool.cwiseAbs().maxCoeff();
  EXPECT_GT(last.spool.cwiseAbs().minCoeff(), 0.05);  // every section open
  int cycles = 0;
  while (!follower.neutral(out)) {
    for (int i = 0; i < 4; ++i) EXPECT_LE(std::abs(out.spool[i] - last.spool[i]), step + 1e-12);
    last = out;
    ASSERT_LT(++cycles, 1000);
  }
  EXPECT_TRUE(out.spool.isZero(0.0));
  EXPECT_GE(cycles + 1, static_cast<int>(open / step));  // no faster than the slew rate allows
}

TEST(ReferenceFollower, MeasuresAgainstTheReferenceOfOneValveDelayAgo) {
  const auto cfg = config::default_crane_config();
  const double period = 0.01;
  valves::ReferenceFollower follower(cfg.model, cfg.control.position_gain_1_s, period);
  const auto lag =
      std::lround((cfg.model.valves.delay_s + cfg.model.valves.time_constant_s) / period);
  ASSERT_GT(lag, 1);
  const dynamics::JointVector q0 = cfg.simulation.q_initial;
  follower.reset(q0);
  std::vector<dynamics::JointVector> refs;
  valves::ValveCommand out;
  for (long k = 0; k < 3 * lag; ++k) {
    dynamics::JointVector q = q0;
    q[0] += 0.001 * static_cast<double>(k + 1);
    refs.push_back(q);
    follower.update(q, dynamics::JointVector::Zero(4), nullptr, out);
    const dynamics::JointVector& expected = k >= lag ? refs[static_cast<std::size_t>(k - lag)] : q0;
    EXPECT_EQ(follower.delayed_reference_q(), expected) << k;
  }
  // A machine standing at the delayed reference gets no correction: at rest, neutral commands.
  valves::ReferenceFollower still(cfg.model, cfg.control.position_gain_1_s, period);
  still.reset(q0);
  for (int k = 0; k < 50; ++k) still.update(q0, dynamics::JointVector::Zero(4), &q0, out);
  EXPECT_TRUE(out.spool.isZero(1e-12));
}
