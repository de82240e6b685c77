// The MHSB circuit quasi-statically (mhsb/mhsb.hpp, docs/mhsb.md) and the paper 001 arm's
// config (config/cranes/mhsb_3link.yaml).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "config_edit.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/mhsb/mhsb.hpp"

namespace {

using craneassist::config::ConfigError;
using namespace craneassist::dynamics;
using namespace craneassist::mhsb;

const std::string kPath = std::string(CRANEASSIST_SOURCE_DIR) + "/config/cranes/mhsb_3link.yaml";

ConfigError error_after_edit(const std::string& from, const std::string& to) {
  return craneassist::test::crane_config_error_after_edit(kPath, from, to);
}

TEST(MhsbConfig, TheShippedArmIsThePapersTable1) {
  const auto cfg = craneassist::config::mhsb_3link_config();
  const CraneModel& m = cfg.model;
  ASSERT_EQ(m.dof(), 3);
  EXPECT_DOUBLE_EQ(m.joints[0].a_m, 0.45);
  EXPECT_DOUBLE_EQ(m.joints[1].a_m, 0.40);
  EXPECT_DOUBLE_EQ(m.joints[2].a_m, 0.179);
  EXPECT_NEAR(m.cylinders[0].area_a_m2, M_PI / 4 * 0.025 * 0.025, 1e-12);
  ASSERT_TRUE(m.mhsb.has_value());
  EXPECT_EQ(m.mhsb->modules, 4);
  EXPECT_DOUBLE_EQ(m.pump.supply_pressure_pa, 4e6);
  EXPECT_DOUBLE_EQ(m.mhsb->servo_pump_efficiency, 0.56);
  EXPECT_NEAR(m.mhsb->velocity_limit_m_s, 0.012, 1e-12);
  // The file on disk is the embedded one.
  const auto file = craneassist::config::load_crane_config(kPath);
  ASSERT_TRUE(file.model.mhsb.has_value());
  EXPECT_DOUBLE_EQ(file.model.mhsb->servo_pump_max_flow_m3_s, m.mhsb->servo_pump_max_flow_m3_s);
  // The shipped K70M has no MHSB circuit.
  EXPECT_FALSE(craneassist::config::default_crane_config().model.mhsb.has_value());
}

TEST(MhsbConfig, ErrorsNameTheField) {
  auto e = error_after_edit("mode: constant-pressure", "mode: load-sensing");
  EXPECT_EQ(e.field(), "hydraulics.mhsb");
  EXPECT_NE(e.reason().find("constant-pressure"), std::string::npos) << e.reason();
  e = error_after_edit("modules: 4,", "modules: 2.5,");
  EXPECT_EQ(e.field(), "hydraulics.mhsb.modules");
  EXPECT_GT(e.line(), 0);
  e = error_after_edit("servo_pump_efficiency: 0.56", "servo_pump_efficiency: 1.5");
  EXPECT_EQ(e.field(), "hydraulics.mhsb.servo_pump_efficiency");
  e = error_after_edit("leakage: 0.015 L/min", "leakage: 0.015 MPa");
  EXPECT_EQ(e.field(), "hydraulics.mhsb.servo_valve.leakage");
  e = error_after_edit("    velocity_limit:", "    velocity_limt:");
  EXPECT_EQ(e.field(), "hydraulics.mhsb.velocity_limt");
}

TEST(MhsbModes, TwentyThreePatternsForThreeJointsAndFourModules) {
  const auto patterns = mode_patterns(3, 4);
  EXPECT_EQ(patterns.size(), 23u);  // paper 001 section 3
  EXPECT_EQ(to_string(patterns.front()), "N-N-N");
  for (const auto& p : patterns) {
    EXPECT_LE(p.modules(), 4);
    const auto back = parse_mode_pattern(to_string(p), 3);
    ASSERT_TRUE(back.has_value()) << to_string(p);
    EXPECT_EQ(*back, p);
  }
  EXPECT_EQ(mode_patterns(3, 6).size(), 27u);
  EXPECT_EQ(mode_patterns(3, 0).size(), 1u);
  EXPECT_FALSE(parse_mode_pattern("N-DB", 3).has_value());
  EXPECT_FALSE(parse_mode_pattern("N-DB-SB-N", 3).has_value());
  EXPECT_FALSE(parse_mode_pattern("N-XB-SB", 3).has_value());
  EXPECT_EQ(parse_mode_pattern("SB-N-DB", 3)->switches_from(*parse_mode_pattern("SB-DB-N", 3)), 2);
}

TEST(MhsbValve, RequiredPressureAndSpeedsAreInverses) {
  const auto cfg = craneassist::config::mhsb_3link_config();
  const Cylinder& c = cfg.model.cylinders[0];
  const ServoValve& valve = cfg.model.mhsb->valve;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> force(-3000.0, 3000.0), speed(-0.05, 0.05);
  for (int k = 0; k < 200; ++k) {
    const double f = force(rng), v = speed(rng), pt = 2e5;
    const double ps = required_supply_pressure_pa(c, valve, pt, f, v);
    const auto s = servo_valve_speeds(c, valve, ps, pt, f);
    EXPECT_NEAR(v >= 0 ? s.extend_m_s : -s.retract_m_s, v, 1e-9) << f << " " << v;
  }
  // No supply: nothing moves against a load pushing the rod in, but it falls under it.
  const auto s = servo_valve_speeds(c, valve, 0.0, 0.0, 1000.0);
  EXPECT_EQ(s.extend_m_s, 0.0);
  EXPECT_GT(s.retract_m_s, 0.0);
}

TEST(MhsbValve, DecoupledBoostSpeedsAreThePapersTable2) {
  const auto cfg = craneassist::config::mhsb_3link_config();
  const Mhsb& m = *cfg.model.mhsb;
  const Cylinder& c = cfg.model.cylinders[0];
  const double cap = mode_flow_cap_m3_s(m, MhsbMode::kDecoupledBoost);
  EXPECT_NEAR(cap / c.area_a_m2 * 1e3, 8.2, 0.05);   // mm/s extending
  EXPECT_NEAR(cap / c.area_b_m2 * 1e3, 10.7, 0.05);  // retracting
  EXPECT_NEAR(mode_flow_cap_m3_s(m, MhsbMode::kSharedBoost), 2 * cap, 1e-15);
  EXPECT_TRUE(std::isinf(mode_flow_cap_m3_s(m, MhsbMode::kNormal)));
  EXPECT_DOUBLE_EQ(mode_supply_pressure_pa(cfg.model, MhsbMode::kNormal), 4e6);
  EXPECT_DOUBLE_EQ(mode_supply_pressure_pa(cfg.model, MhsbMode::kDecoupledBoost), 14e6);
}

TEST(MhsbModes, SelectionRules) {
  const auto cfg = craneassist::config::mhsb_3link_config();
  const CraneModel& model = cfg.model;
  const double v = model.mhsb->velocity_limit_m_s;
  const double a1 = model.cylinders[0].area_a_m2;
  const double heavy = 1.5 * a1 * 4e6;  // a positive load above what P0 can push
  for (const double f : {heavy, -heavy}) {
    // Negative loads (the load moves with the rod): N only, however large.
    const double with = f > 0 ? -v : v;
    EXPECT_FALSE(needs_boost(model, 0, f, with));
    EXPECT_TRUE(mode_allowed(model, 0, MhsbMode::kNormal, f, with));
    EXPECT_FALSE(mode_allowed(model, 0, MhsbMode::kDecoupledBoost, f, with));
    EXPECT_FALSE(mode_allowed(model, 0, MhsbMode::kSharedBoost, f, with));
  }
  // A light positive load: N.
  EXPECT_TRUE(mode_allowed(model, 0, MhsbMode::kNormal, 0.3 * a1 * 4e6, v));
  EXPECT_FALSE(mode_allowed(model, 0, MhsbMode::kSharedBoost, 0.3 * a1 * 4e6, v));
  // A heavy positive load: DB or SB, not N.
  EXPECT_TRUE(needs_boost(model, 0, heavy, v));
  EXPECT_FALSE(mode_allowed(model, 0, MhsbMode::kNormal, heavy, v));
  EXPECT_TRUE(mode_allowed(model, 0, MhsbMode::kDecoupledBoost, heavy, v));
  EXPECT_TRUE(mode_allowed(model, 0, MhsbMode::kSharedBoost, heavy, v));
  // Retracting against a load pulling the rod out is positive too.
  EXPECT_TRUE(needs_boost(model, 0, -heavy, -v));
}

TEST(MhsbPower, NormalModeThrottlesFromP0AndBoostCountsTheServoPump) {
  const auto cfg = craneassist::config::mhsb_3link_config();
  const CraneModel& model = cfg.model;
  const Mhsb& m = *model.mhsb;
  const Cylinder& c = model.cylinders[0];
  const double v = 0.01, p0 = 4e6, leak = m.valve.leakage_m3_s;
  for (const double f : {-500.0, 0.0, 500.0}) {
    EXPECT_NEAR(mhsb_actuator_power_w(model, 0, MhsbMode::kNormal, f, v, MhsbEnergyModel::kSeries),
                p0 * (c.area_a_m2 * v + leak), 1e-9);
  }
  const double f = 1.5 * c.area_a_m2 * p0;
  const double ps = required_supply_pressure_pa(c, m.valve, 0.0, f, v);
  ASSERT_GT(ps, p0);
  const double q = c.area_a_m2 * v, eta = m.servo_pump_efficiency;
  EXPECT_NEAR(
      mhsb_actuator_power_w(model, 0, MhsbMode::kDecoupledBoost, f, v, MhsbEnergyModel::kSeries),
      (p0 + (ps - p0) / eta) * (q + leak), 1e-9);
  EXPECT_NEAR(
      mhsb_actuator_power_w(model, 0, MhsbMode::kSharedBoost, f, v, MhsbEnergyModel::kPaper),
      ps * q / eta + ps * leak, 1e-9);
  // Retracting uses the annulus.
  EXPECT_NEAR(mhsb_actuator_power_w(model, 0, MhsbMode::kNormal, 0.0, -v, MhsbEnergyModel::kSeries),
              p0 * (c.area_b_m2 * v + leak), 1e-9);
}

TEST(MhsbPolytope, ModeBoxesCutTheJointVelocities) {
  const auto cfg = craneassist::config::mhsb_3link_config();
  const CraneModel& model = cfg.model;
  JointVector q(3), arms(3), force(3);
  q << 0.2, -0.5, 0.3;
  cylinder_arms(model, q, arms);
  const double a1 = model.cylinders[0].area_a_m2;
  // Joint 1 held by a load above what P0 pushes: in N it cannot extend, in DB it extends at the
  // servo-pump's flow; joint 2 unloaded.
  force << 1.2 * a1 * 4e6, 0.0, 0.0;
  FlowPolytopeSettings settings;
  JointVelocitySet n, db;
  mhsb_joint_velocity_set(model, q, arms, force, *parse_mode_pattern("N-N-N", 3), settings, n);
  mhsb_joint_velocity_set(model, q, arms, force, *parse_mode_pattern("DB-N-N", 3), settings, db);
  ASSERT_GT(arms[0], 0.0);  // positive joint rate extends
  EXPECT_EQ(n.qdot_max[0], 0.0);
  EXPECT_LT(n.qdot_min[0], 0.0);  // it may lower the load
  const double cap = model.mhsb->servo_pump_max_flow_m3_s;
  EXPECT_NEAR(db.qdot_max[0] * arms[0], cap / a1, 1e-12);
  EXPECT_NEAR(db.qdot_min[0] * arms[0], -cap / model.cylinders[0].area_b_m2, 1e-12);
  // Unloaded joint 2 in N: the valve at P0, more than V_L.
  const auto s = servo_valve_speeds(model.cylinders[1], model.mhsb->valve, 4e6, 0.0, 0.0);
  EXPECT_NEAR(n.qdot_max[1] * std::abs(arms[1]),
              std::min(s.extend_m_s, model.cylinders[1].v_max_m_s), 1e-12);
  EXPECT_GT(s.extend_m_s, 0.04);
  EXPECT_DOUBLE_EQ(n.max_flow_m3_s, model.pump.max_flow_m3_s);
}

// Every vertex of a pattern's joint-velocity set is a motion the circuit can make: each cylinder's
// speed needs at most its mode's supply pressure against its load, and a boosted cylinder's flow
// is at most its servo-pumps'.
TEST(MhsbPolytope, EveryVertexIsWithinTheValveAndPumpLaws) {
  const auto cfg = craneassist::config::mhsb_3link_config();
  const CraneModel& model = cfg.model;
  const Mhsb& m = *model.mhsb;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0), load(-4000.0, 4000.0);
  const auto patterns = mode_patterns(3, m.modules);
  Eigen::MatrixXd vertices(3, max_joint_vertices(3));
  int checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    JointVector q(3), arms(3), force(3);
    for (int i = 0; i < 3; ++i) {
      const auto& j = model.joints[static_cast<std::size_t>(i)];
      q[i] = j.q_min + unit(rng) * (j.q_max - j.q_min);
      force[i] = load(rng);
    }
    cylinder_arms(model, q, arms);
    const ModePattern& pattern = patterns[static_cast<std::size_t>(trial) % patterns.size()];
    JointVelocitySet set;
    mhsb_joint_velocity_set(model, q, arms, force, pattern, FlowPolytopeSettings{}, set);
    const int count = joint_velocity_vertices(set, vertices);
    for (int k = 0; k < count; ++k) {
      double flow = 0.0;
      for (int i = 0; i < 3; ++i) {
        const double v = arms[i] * vertices(i, k);
        const Cylinder& c = model.cylinders[static_cast<std::size_t>(i)];
        flow += flow_area_m2(c, v) * std::abs(v);
        if (std::abs(v) < 1e-12) continue;
        const MhsbMode mode = pattern.mode[static_cast<std::size_t>(i)];
        EXPECT_LE(required_supply_pressure_pa(c, m.valve, m.tank_pressure_pa, force[i], v),
                  mode_supply_pressure_pa(model, mode) * (1 + 1e-9) + 1e-3)
            << to_string(pattern) << " joint " << i;
        EXPECT_LE(flow_area_m2(c, v) * std::abs(v), mode_flow_cap_m3_s(m, mode) * (1 + 1e-9));
        EXPECT_LE(std::abs(v), c.v_max_m_s * (1 + 1e-9));
        ++checked;
      }
      EXPECT_LE(flow, model.pump.max_flow_m3_s * (1 + 1e-9));
    }
  }
  EXPECT_GT(checked, 500);
}

}  // namespace
