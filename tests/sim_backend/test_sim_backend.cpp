// The simulated crane: the LS and constant-pressure pump without flow sharing, valve sections,
// and the ODE crane under valve control.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

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

// The same pump in constant-pressure mode at p_s = 15 MPa: it delivers up to
// min(5e-3, 40e3 / 15e6) = 2.67e-3 m^3/s at p_s.
dynamics::Pump cp_pump(double supply_pressure_pa = 15e6) {
  dynamics::Pump p = test_pump();
  p.mode = dynamics::PumpMode::kConstantPressure;
  p.supply_pressure_pa = supply_pressure_pa;
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

TEST(LsPump, FlowLimitCapsTheDeliveryAndIsRestored) {
  // A pump shared with another consumer (a wheeled base's hub motors): what it may deliver is cut
  // per step; sections starve by load as at the pump's own limit, and the cut is undone.
  sim_backend::PumpModel pump(test_pump());
  sim_backend::PumpResult r;
  pump.set_flow_limit(1e-3);
  EXPECT_DOUBLE_EQ(pump.flow_limit(), 1e-3);
  pump.solve(vec({1e-3, 1e-3}), vec({1e6, 2e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kMaxFlow);
  EXPECT_NEAR(r.flow_m3_s, 1e-3, 1e-9);
  EXPECT_GT(r.delivered_fraction[0], r.delivered_fraction[1]);
  // Over-running sections take flow at zero pressure, but not more than the pump gives.
  pump.set_flow_limit(0.2e-3);
  pump.solve(vec({1e-3, 1e-3}), vec({-8e6, -6e6}), r);
  EXPECT_LE(r.flow_m3_s, 0.2e-3 * (1 + 1e-12));
  EXPECT_GT(r.flow_m3_s, 0.0);
  pump.set_flow_limit(0.0);
  pump.solve(vec({1e-3, 1e-3}), vec({-8e6, 1e6}), r);
  EXPECT_EQ(r.flow_m3_s, 0.0);
  pump.set_flow_limit(std::nan(""));  // not finite: nothing
  EXPECT_EQ(pump.flow_limit(), 0.0);
  pump.set_flow_limit(1.0);  // above the pump's own: its own
  EXPECT_DOUBLE_EQ(pump.flow_limit(), 5e-3);
  pump.solve(vec({1e-3, 1e-3}), vec({1e6, 2e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kNone);
  EXPECT_DOUBLE_EQ(r.flow_m3_s, 2e-3);
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

TEST(LsPump, IgnoresTheConstantPressureSetpoint) {
  dynamics::Pump p = test_pump();
  p.supply_pressure_pa = 15e6;  // only used in constant-pressure mode
  const sim_backend::PumpModel pump(p);
  sim_backend::PumpResult r;
  pump.solve(vec({1e-3, 1e-3, 0.0}), vec({5e6, 8e6, 15e6}), r);
  EXPECT_DOUBLE_EQ(r.supply_pressure_pa, 10e6);
  EXPECT_DOUBLE_EQ(r.power_w, 10e6 * 2e-3);
  pump.solve(vec({0.0, 0.0}), vec({5e6, 8e6}), r);
  EXPECT_DOUBLE_EQ(r.supply_pressure_pa, 2e6) << "idle LS pump at standby";
}

TEST(CpPump, HoldsTheSetpointWhateverTheLoads) {
  const sim_backend::PumpModel pump(cp_pump());
  sim_backend::PumpResult light, heavy, idle;
  pump.solve(vec({1e-3, 0.5e-3, 0.0}), vec({1e6, 3e6, 14e6}), light);
  pump.solve(vec({1e-3, 0.5e-3, 0.0}), vec({8e6, 12e6, 1e6}), heavy);
  for (const auto* r : {&light, &heavy}) {
    EXPECT_EQ(r->limit, valves::PumpLimit::kNone);
    EXPECT_DOUBLE_EQ(r->supply_pressure_pa, 15e6);
    EXPECT_DOUBLE_EQ(r->flow_m3_s, 1.5e-3);
    EXPECT_DOUBLE_EQ(r->delivered_fraction[0], 1.0);
    EXPECT_DOUBLE_EQ(r->delivered_fraction[1], 1.0);
    EXPECT_DOUBLE_EQ(r->power_w, 15e6 * 1.5e-3) << "p_s Q, not (max load + margin) Q";
  }
  // Nothing open: the pump holds p_s at zero displacement and (ideal) takes no power.
  pump.solve(vec({0.0, 0.0, 0.0}), vec({8e6, 12e6, 1e6}), idle);
  EXPECT_DOUBLE_EQ(idle.supply_pressure_pa, 15e6);
  EXPECT_DOUBLE_EQ(idle.flow_m3_s, 0.0);
  EXPECT_DOUBLE_EQ(idle.power_w, 0.0);
  EXPECT_EQ(idle.limit, valves::PumpLimit::kNone);
}

TEST(CpPump, SectionNearOrAboveTheSetpointStarves) {
  const sim_backend::PumpModel pump(cp_pump());
  sim_backend::PumpResult r;
  // dp_c = 2 MPa: 14 MPa is 1 MPa below p_s (sqrt(1/2) of its flow), 16 MPa is above it.
  pump.solve(vec({0.5e-3, 0.5e-3, 0.5e-3}), vec({2e6, 14e6, 16e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kRelief) << "the pressure ceiling held a section back";
  EXPECT_DOUBLE_EQ(r.supply_pressure_pa, 15e6);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[0], 1.0);
  EXPECT_NEAR(r.delivered_fraction[1], std::sqrt(0.5), 1e-12);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[2], 0.0);
  EXPECT_NEAR(r.flow_m3_s, 0.5e-3 * (1.0 + std::sqrt(0.5)), 1e-15);
  EXPECT_NEAR(r.power_w, 15e6 * r.flow_m3_s, 1e-9);
  // The same loads on a load-sensing pump get their full flow at 18 MPa.
  const sim_backend::PumpModel ls(test_pump());
  ls.solve(vec({0.5e-3, 0.5e-3, 0.5e-3}), vec({2e6, 14e6, 16e6}), r);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[2], 1.0);
}

TEST(CpPump, PowerLimitLowersThePressureAndStarvesTheMostLoadedSection) {
  const sim_backend::PumpModel pump(cp_pump());
  EXPECT_DOUBLE_EQ(pump.deliverable_flow(15e6), 40e3 / 15e6);
  sim_backend::PumpResult r;
  // 3e-3 m^3/s at 15 MPa would need 45 kW; 40 kW are available. The power limiter cuts the
  // displacement and the supply pressure falls to 40 kW / 3e-3 = 13.3 MPa, still above both
  // loads + dp_c: every section keeps its flow.
  pump.solve(vec({1.5e-3, 1.5e-3}), vec({3e6, 9e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kPower);
  EXPECT_NEAR(r.supply_pressure_pa, 40e3 / 3e-3, 1e-3);
  EXPECT_DOUBLE_EQ(r.flow_m3_s, 3e-3);
  // With a 12 MPa load the pressure cannot fall that far without starving that section: it
  // settles between 12 and 14 MPa, the light section fully served, the heavy one not.
  pump.solve(vec({1.5e-3, 1.5e-3}), vec({3e6, 12e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kPower);
  EXPECT_GT(r.supply_pressure_pa, 12e6);
  EXPECT_LT(r.supply_pressure_pa, 14e6);
  EXPECT_LE(r.power_w, 40e3 * (1 + 1e-9));
  EXPECT_NEAR(r.power_w, 40e3, 40.0);
  EXPECT_NEAR(r.power_w, r.supply_pressure_pa * r.flow_m3_s, 1e-9);
  EXPECT_DOUBLE_EQ(r.delivered_fraction[0], 1.0);
  EXPECT_GT(r.delivered_fraction[1], 0.0);
  EXPECT_LT(r.delivered_fraction[1], 1.0);
}

TEST(CpPump, FlowLimitAtALowSetpoint) {
  // At 5 MPa the 40 kW would allow 8e-3 m^3/s; the displacement stops at 5e-3.
  const sim_backend::PumpModel pump(cp_pump(5e6));
  sim_backend::PumpResult r;
  pump.solve(vec({2e-3, 2e-3}), vec({0.5e6, 1e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kNone);
  EXPECT_DOUBLE_EQ(r.supply_pressure_pa, 5e6);
  pump.solve(vec({3e-3, 3e-3}), vec({0.5e6, 1e6}), r);
  EXPECT_EQ(r.limit, valves::PumpLimit::kMaxFlow);
  EXPECT_NEAR(r.flow_m3_s, 5e-3, 1e-9);
  EXPECT_LT(r.supply_pressure_pa, 5e6);
  EXPECT_GT(r.delivered_fraction[0], r.delivered_fraction[1]);
}

TEST(CpPump, SetpointAboveReliefIsCappedByTheRelief) {
  const sim_backend::PumpModel pump(cp_pump(30e6));
  sim_backend::PumpResult r;
  pump.solve(vec({1e-3, 0.0}), vec({5e6, 0.0}), r);
  EXPECT_DOUBLE_EQ(r.supply_pressure_pa, 21e6);
  EXPECT_DOUBLE_EQ(r.power_w, 21e6 * 1e-3);
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

// The machine's section where it differs from the model (docs/valves.md#the-machine-it-meets):
// its own lag, delay and dead band, its gain and shape beyond the band, its hysteresis.
TEST(ValveSection, AMachineSectionDiffersWhereItsDeviationSays) {
  dynamics::ValveSections model;
  model.dead_zone = 0.5;
  model.time_constant_s = 0.05;
  model.delay_s = 0.1;
  dynamics::ValveDeviation d;
  d.time_constant_s = 0.0;
  d.delay_s = 0.02;
  d.dead_zone = 0.25;
  d.gain = 1.2;
  d.shape = 2.0;
  sim_backend::ValveSection valve(model, d, 0.2, 1e-3);
  for (int k = 0; k < 20; ++k) EXPECT_EQ(valve.step(1.0), 0.0) << "its own delay, step " << k;
  EXPECT_DOUBLE_EQ(valve.step(1.0), 1.2 * 0.2) << "full opening: gain x max_speed";
  sim_backend::ValveSection half(model, d, 0.2, 1e-3);
  double v = 0.0;
  for (int k = 0; k < 50; ++k) v = half.step(-0.625);  // half way from its band to full
  EXPECT_DOUBLE_EQ(v, -1.2 * 0.2 * 0.25) << "opening 0.5 squared";
  sim_backend::ValveSection narrow(model, d, 0.2, 1e-3);
  for (int k = 0; k < 50; ++k) v = narrow.step(0.45);
  EXPECT_GT(v, 0.0) << "inside the model's band, outside the machine's";
  EXPECT_DOUBLE_EQ(v, valve.velocity_at(0.45));

  // Hysteresis 0.1: the effective spool trails the command by half of it, each way.
  dynamics::ValveDeviation h;
  h.time_constant_s = 0.0;
  h.delay_s = 0.0;
  h.hysteresis = 0.1;
  sim_backend::ValveSection play(model, h, 0.2, 1e-3);
  play.step(0.8);
  EXPECT_NEAR(play.spool_position(), 0.75, 1e-12) << "rising: half the play below";
  play.step(0.78);
  EXPECT_NEAR(play.spool_position(), 0.75, 1e-12) << "a small reversal moves nothing";
  play.step(0.6);
  EXPECT_NEAR(play.spool_position(), 0.65, 1e-12) << "falling: half the play above";
  // Left out, every field is the model's: the same velocities step by step.
  sim_backend::ValveSection same(model, dynamics::ValveDeviation{}, 0.2, 1e-3);
  sim_backend::ValveSection plain(model, 0.2, 1e-3);
  for (int k = 0; k < 300; ++k) {
    const double u = std::sin(0.02 * k);
    ASSERT_DOUBLE_EQ(same.step(u), plain.step(u)) << k;
  }
}

// The machine's joint sensors and feedback: late by their delays, rounded to their resolution;
// exact and at once when left out.
TEST(SimJointSensing, ReadingsAreLateAndCoarseAsConfigured) {
  auto cfg = config::default_crane_config();
  sim_backend::SimSettings exact{cfg.simulation.step_s, cfg.simulation.q_initial};
  sim_backend::SimSettings coarse = exact;
  coarse.joints.angle_resolution_rad = 0.01;
  coarse.joints.length_resolution_m = 0.005;
  coarse.joints.delay_s = 0.02;
  coarse.joints.feedback_delay_s = 0.03;
  sim_backend::SimBackend truth(cfg.model, exact), machine(cfg.model, coarse);
  valves::ValveCommand cmd;
  cmd.spool = JointVector::Constant(4, 0.9);
  truth.write(cmd);
  machine.write(cmd);
  valves::MachineState now, seen;
  std::vector<JointVector> history;
  for (int k = 0; k < 60; ++k) {
    truth.advance(0.01);
    machine.advance(0.01);
    truth.read(now);
    machine.read(seen);
    history.push_back(now.q);
    if (k < 5) continue;
    const JointVector& late = history[static_cast<std::size_t>(k - 5)];  // 50 ms ago
    for (int i = 0; i < 4; ++i) {
      const double res = i == 3 ? 0.005 : 0.01;
      EXPECT_NEAR(seen.q[i], late[i], 0.5 * res + 1e-12) << "joint " << i << " cycle " << k;
      EXPECT_NEAR(std::remainder(seen.q[i], res), 0.0, 1e-9) << "rounded, joint " << i;
    }
  }
  EXPECT_GT((now.q - history.front()).norm(), 0.05) << "the crane moved";
}

class SimCrane : public ::testing::Test {
 protected:
  void SetUp() override { cfg_ = config::default_crane_config(); }
  sim_backend::SimBackend make() {
    return sim_backend::SimBackend(cfg_.model, {cfg_.simulation.step_s, cfg_.simulation.q_initial});
  }
  // Every section fully open at once with a 650 kg payload, 2 s in 10 ms steps: the pump's
  // power is limited in more than 10 of them and never exceeds the prime mover's. check(s)
  // holds at every step.
  template <class Check>
  void expect_power_bounded_with_every_section_open(Check check) {
    config::set_payload_mass(cfg_.model, 650.0);
    auto sim = make();
    valves::MachineState s;
    valves::ValveCommand cmd;
    cmd.spool = JointVector::Constant(4, 1.0);
    sim.write(cmd);
    double peak = 0.0;
    int power_limited = 0;
    for (int k = 0; k < 200; ++k) {
      sim.advance(0.01);
      sim.read(s);
      peak = std::max(peak, s.pump.power_w);
      power_limited += s.pump.limit == valves::PumpLimit::kPower;
      check(s);
    }
    EXPECT_GT(power_limited, 10);
    EXPECT_LE(peak, cfg_.model.pump.prime_mover_power_w * 1.001);
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
  expect_power_bounded_with_every_section_open([](const valves::MachineState&) {});
}

// The same slew-and-lift move on the LS and the CP crane: the CP pump holds 20 MPa throughout and
// its energy is p_s times the delivered volume; once the slew has accelerated (its start is
// pressure limited, at 20 MPa on the CP crane, at relief on the LS one) the compensated sections
// move alike on both.
TEST_F(SimCrane, ConstantPressureEnergyIsSupplyPressureTimesVolume) {
  ASSERT_EQ(cfg_.model.pump.mode, dynamics::PumpMode::kLoadSensing);
  ASSERT_DOUBLE_EQ(cfg_.model.pump.supply_pressure_pa, 20e6);
  auto ls = make();
  cfg_.model.pump.mode = dynamics::PumpMode::kConstantPressure;
  auto cp = make();
  valves::ValveCommand cmd;
  cmd.spool = vec({0.9, 0.7, 0.0, 0.0});  // about 1.4e-3 m^3/s: 29 kW at 20 MPa, unsaturated
  ls.write(cmd);
  cp.write(cmd);
  valves::MachineState s_ls, s_cp;
  double volume_m3 = 0.0;
  int pressure_limited = 0;
  for (int k = 0; k < 1500; ++k) {  // 1.5 s, one simulation step at a time
    ls.advance(cfg_.simulation.step_s);
    cp.advance(cfg_.simulation.step_s);
    ls.read(s_ls);
    cp.read(s_cp);
    ASSERT_NE(s_cp.pump.limit, valves::PumpLimit::kPower) << "step " << k;
    ASSERT_DOUBLE_EQ(s_cp.pump.pressure_pa, 20e6) << "step " << k;
    ASSERT_DOUBLE_EQ(s_cp.pump.power_w, 20e6 * s_cp.pump.flow_m3_s) << "step " << k;
    volume_m3 += s_cp.pump.flow_m3_s * cfg_.simulation.step_s;
    pressure_limited += s_cp.pump.limit == valves::PumpLimit::kRelief;
  }
  EXPECT_GT(volume_m3, 1e-3) << "the sections opened (after the 0.15 s valve delay)";
  EXPECT_NEAR(s_cp.pump.energy_j, 20e6 * volume_m3, 1e-9 * s_cp.pump.energy_j);
  EXPECT_GT(pressure_limited, 10) << "the slew's start is limited by p_s - dp_c";
  EXPECT_EQ(s_cp.pump.limit, valves::PumpLimit::kNone);
  // Load independent, compensated sections: the same speeds and the same flow on both pumps.
  EXPECT_LT((s_cp.qdot - s_ls.qdot).norm(), 1e-6);
  EXPECT_NEAR(s_cp.pump.flow_m3_s, s_ls.pump.flow_m3_s, 1e-9);
  EXPECT_GT(s_cp.pump.flow_m3_s, 1.2e-3);
  // The LS pump runs at the lift's load + 3 MPa, far below 20 MPa: less energy for the volume.
  EXPECT_LT(s_ls.pump.pressure_pa, 15e6);
  EXPECT_LT(s_ls.pump.energy_j, 0.8 * s_cp.pump.energy_j);
}

TEST_F(SimCrane, ConstantPressurePowerNeverExceedsThePrimeMover) {
  cfg_.model.pump.mode = dynamics::PumpMode::kConstantPressure;
  expect_power_bounded_with_every_section_open(
      [](const valves::MachineState& s) { EXPECT_LE(s.pump.pressure_pa, 20e6); });
}

TEST_F(SimCrane, ConstantPressureNeedsASupplyPressure) {
  cfg_.model.pump.mode = dynamics::PumpMode::kConstantPressure;
  cfg_.model.pump.supply_pressure_pa = 0.0;
  EXPECT_THROW(make(), std::invalid_argument);
}

// A cylinder standing on its end stop is driven off it: the stop's reaction is not a load on the
// oil (before, it read as a load pressure far beyond relief and starved the section for good).
TEST(SimBackend, DrivesACylinderOffItsEndStop) {
  const auto cfg = craneassist::config::default_crane_config();
  craneassist::dynamics::JointVector q0(4);
  q0 << 0.0, 0.44, -1.93, 0.0;  // extension fully retracted, on its stop
  craneassist::sim_backend::SimBackend sim(cfg.model, {cfg.simulation.step_s, q0});
  craneassist::valves::MachineState state;
  sim.read(state);
  EXPECT_LT(state.load_pressure_pa[3], cfg.model.pump.max_pressure_pa);
  craneassist::valves::ValveCommand extend{craneassist::dynamics::JointVector::Zero(4)};
  extend.spool[3] = 1.0;
  for (int k = 0; k < 100; ++k) {
    sim.write(extend);
    sim.advance(0.01);
  }
  sim.read(state);
  EXPECT_GT(state.q[3], 0.2);  // 1 s at up to 0.8 m/s of extension (0.4 m/s of cylinder)
}
