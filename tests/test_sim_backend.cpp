// The simulated crane: LS pump sharing without flow sharing, valve sections, and the ODE crane
// under valve control.
#include <gtest/gtest.h>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/sim_backend/pump_model.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"
#include "craneassist/sim_backend/valve_section.hpp"

using namespace craneassist;
using dynamics::JointVector;

namespace {

dynamics::Pump test_pump() {
  dynamics::Pump p;
  p.max_flow_m3_s = 5e-3;
  p.max_pressure_pa = 21e6;
  p.ls_margin_pa = 2e6;
  p.prime_mover_power_w = 40e3;
  p.standby_pressure_pa = 2e6;
  return p;
}

JointVector vec(std::initializer_list<double> values) {
  JointVector v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double x : values) v[i++] = x;
  return v;
}

}  // namespace

TEST(LsPump, UnsaturatedServesEverySectionAtHighestLoadPlusMargin) {
  const sim_backend::PumpModel pump(test_pump());
  sim_backend::PumpResult r;
  pump.solve(vec({1e-3, 1e-3, 0.0}), vec({5e6, 8e6, 15e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kNone);
  EXPECT_DOUBLE_EQ(r.supply_pressure_pa, 10e6) << "closed section's load does not count";
  EXPECT_DOUBLE_EQ(r.flow_m3_s, 2e-3);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[0], 1.0);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[1], 1.0);
  EXPECT_DOUBLE_EQ(r.power_w, 10e6 * 2e-3);
}

TEST(LsPump, PowerSaturationStarvesTheMostLoadedSectionFirst) {
  const sim_backend::PumpModel pump(test_pump());
  sim_backend::PumpResult r;
  // Demand 3.5e-3 m^3/s at 17 MPa would need 60 kW; 40 kW are available.
  pump.solve(vec({1e-3, 1e-3, 1.5e-3}), vec({3e6, 6e6, 15e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kPower);
  EXPECT_LE(r.power_w, 40e3 * (1 + 1e-9));
  EXPECT_NEAR(r.power_w, 40e3, 40.0);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[0], 1.0);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[1], 1.0);
  EXPECT_GT(r.delivered_fraction[2], 0.0);
  EXPECT_LT(r.delivered_fraction[2], 1.0);
  EXPECT_GT(r.supply_pressure_pa, 15e6);
  EXPECT_LT(r.supply_pressure_pa, 17e6);
  // With more demand from the light sections the heavy one gets nothing at all: the supply
  // pressure falls below its load and its load-holding check valve keeps it still.
  pump.solve(vec({1.5e-3, 1.5e-3, 1.5e-3}), vec({3e6, 6e6, 15e6}), r);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[2], 0.0);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[0], 1.0);
  EXPECT_LT(r.supply_pressure_pa, 15e6);
  EXPECT_NEAR(r.power_w, 40e3, 40.0);
}

TEST(LsPump, FlowSaturationAtLowPressureIsFlowLimited) {
  const sim_backend::PumpModel pump(test_pump());
  sim_backend::PumpResult r;
  pump.solve(vec({3e-3, 3e-3}), vec({1e6, 2e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kMaxFlow);
  EXPECT_NEAR(r.flow_m3_s, 5e-3, 1e-9);
  EXPECT_GT(r.delivered_fraction[0], r.delivered_fraction[1]);
}

TEST(LsPump, OverrunningLoadDoesNotSetThePressure) {
  const sim_backend::PumpModel pump(test_pump());
  sim_backend::PumpResult r;
  pump.solve(vec({1e-3, 1e-3}), vec({-8e6, 1e6}), r);
  EXPECT_DOUBLE_EQ(r.supply_pressure_pa, 3e6);
}

TEST(LsPump, LoadAboveReliefStalls) {
  const sim_backend::PumpModel pump(test_pump());
  sim_backend::PumpResult r;
  pump.solve(vec({1e-3, 1e-3}), vec({25e6, 1e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kRelief);
  EXPECT_DOUBLE_EQ(r.supply_pressure_pa, 21e6);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[0], 0.0);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[1], 1.0);
}

TEST(ValveSection, DelayLagAndDeadZone) {
  dynamics::ValveSections p;
  p.dead_zone = 0.5;
  p.time_constant_s = 0.0;
  p.delay_s = 0.1;
  sim_backend::ValveSection valve(p, 0.2, 1e-3);
  for (int k = 0; k < 100; ++k) EXPECT_EQ(valve.step(1.0), 0.0) << "step " << k;
  EXPECT_DOUBLE_EQ(valve.step(1.0), 0.2);
  sim_backend::ValveSection half(p, 0.2, 1e-3);
  double v = 0;
  for (int k = 0; k < 200; ++k) v = half.step(-0.75);
  EXPECT_DOUBLE_EQ(v, -0.1);
  sim_backend::ValveSection inside(p, 0.2, 1e-3);
  for (int k = 0; k < 200; ++k) v = inside.step(0.45);
  EXPECT_DOUBLE_EQ(v, 0.0);
  p.time_constant_s = 0.05;
  p.delay_s = 0.0;
  sim_backend::ValveSection lag(p, 0.2, 1e-3);
  for (int k = 0; k < 50; ++k) lag.step(1.0);
  EXPECT_NEAR(lag.spool_position(), 1.0 - std::exp(-1.0), 0.01);
}

class SimCrane : public ::testing::Test {
 protected:
  void SetUp() override { cfg_ = config::default_crane_config(); }
  sim_backend::SimBackend make() {
    return sim_backend::SimBackend(cfg_.model, {cfg_.simulation.step_s, cfg_.simulation.q_initial});
  }
  config::CraneConfig cfg_;
};

TEST_F(SimCrane, HoldsStillWithNeutralValves) {
  auto sim = make();
  valves::MachineState s;
  valves::ValveCommand cmd;
  cmd.spool.setZero(4);
  sim.write(cmd);
  sim.advance(2.0);
  ASSERT_EQ(sim.read(s), valves::BackendStatus::kOk);
  EXPECT_LT((s.q - cfg_.simulation.q_initial).norm(), 1e-4);
  EXPECT_NEAR(s.t_s, 2.0, 1e-9);
  EXPECT_DOUBLE_EQ(s.pump.flow_m3_s, 0.0);
  // The lift cylinder holds the boom: positive load pressure of several MPa.
  EXPECT_GT(s.load_pressure_pa[1], 2e6);
  EXPECT_LT(s.load_pressure_pa[1], 20e6);
}

TEST_F(SimCrane, OpenSectionMovesAtTheValveVelocity) {
  auto sim = make();
  valves::MachineState s;
  valves::ValveCommand cmd;
  cmd.spool.setZero(4);
  cmd.spool[0] = 1.0;  // full slew: 0.1 m/s cylinder speed, low load
  sim.write(cmd);
  sim.advance(1.0);
  sim.read(s);
  const double arm = dynamics::cylinder_arm(cfg_.model.cylinders[0], s.q[0]);
  EXPECT_NEAR(s.qdot[0] * arm, 0.10, 1e-3);
  EXPECT_NEAR(s.pump.flow_m3_s, 0.10 * cfg_.model.cylinders[0].area_a_m2, 1e-5);
  EXPECT_GT(s.pump.energy_j, 0.0);
}

TEST_F(SimCrane, EndStopHoldsTheJoint) {
  auto sim = make();
  valves::MachineState s;
  valves::ValveCommand cmd;
  cmd.spool.setZero(4);
  cmd.spool[3] = -1.0;  // retract the extension into its stop at q4 = 0
  sim.write(cmd);
  sim.advance(5.0);
  sim.read(s);
  EXPECT_NEAR(s.q[3], 0.0, 5e-3);
  EXPECT_NEAR(s.qdot[3], 0.0, 1e-3);
}

TEST_F(SimCrane, PowerNeverExceedsThePrimeMoverWhenSaturated) {
  config::set_payload_mass(cfg_.model, 650.0);
  auto sim = make();
  valves::MachineState s;
  valves::ValveCommand cmd;
  cmd.spool = JointVector::Constant(4, 1.0);  // everything open at once
  sim.write(cmd);
  double peak = 0.0;
  int power_limited = 0;
  for (int k = 0; k < 200; ++k) {
    sim.advance(0.01);
    sim.read(s);
    peak = std::max(peak, s.pump.power_w);
    power_limited += s.pump.limit == valves::PumpLimit::kPower;
  }
  EXPECT_GT(power_limited, 10);
  EXPECT_LE(peak, cfg_.model.pump.prime_mover_power_w * 1.001);
}
