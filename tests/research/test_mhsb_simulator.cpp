// The MHSB arm simulator (mhsb/mhsb_simulator.hpp, docs/mhsb-simulator.md): the paper 001
// three-link arm on the MHSB circuit under the cascade controller. Holding, the mode limits (N
// cannot lift what needs more than P0, DB can, SB faster), the check valve, tracking of a smooth
// move, the measured energy against the quasi-static model, and no allocation in step().
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>
#include <string>

#include "config_edit.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/mhsb/mhsb.hpp"
#include "craneassist/mhsb/mhsb_simulator.hpp"
#include "ode_allocation_counter.hpp"

using namespace craneassist;
using dynamics::JointVector;
using mhsb::MhsbMode;
using mhsb::MhsbReference;
using mhsb::MhsbSimulator;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The shipped arm with J2 and J3 on both elbows: these tests hold postures with J2 and J3
// negative (the shipped config keeps one elbow for the posture table, docs/mhsb.md).
const dynamics::CraneModel& arm_model() {
  static const dynamics::CraneModel model =
      config::parse_crane_config(
          test::edited_text(std::string(CRANEASSIST_SOURCE_DIR) + "/config/cranes/mhsb_3link.yaml",
                            {{"min: 0 deg, assumed", "min: -150 deg, assumed"},
                             {"stroke: 105 mm", "stroke: 210 mm"},
                             {"min: 0 deg, assumed  # one elbow, as J2", "min: -120 deg, assumed"},
                             {"stroke: 71 mm", "stroke: 134 mm"}}),
          "mhsb_3link.yaml, both elbows")
          .model;
  return model;
}

JointVector deg(double a, double b, double c) {
  JointVector q(3);
  q << a * kDeg, b * kDeg, c * kDeg;
  return q;
}

mhsb::ModePattern pattern(const char* text) {
  return *mhsb::parse_mode_pattern(text, 3);
}

// Quintic (rest to rest) from q0 to q1 over [t0, t0 + duration], held outside it.
struct Quintic {
  JointVector q0, q1;
  double t0 = 0.0, duration = 1.0;
  mhsb::ModePattern modes;

  void operator()(double t, MhsbReference& r) const {
    const double s = std::clamp((t - t0) / duration, 0.0, 1.0);
    const double p = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    const double dp = 30.0 * s * s * (1.0 - s) * (1.0 - s) / duration;
    const double ddp = 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s) / (duration * duration);
    r.q = q0 + p * (q1 - q0);
    r.qdot = dp * (q1 - q0);
    r.qddot = ddp * (q1 - q0);
    r.modes = modes;
  }
  // Highest cylinder speed along it (peak of the quintic: 1.875 / duration per unit step).
  double peak_cylinder_speed(const dynamics::CraneModel& m) const {
    double v = 0.0;
    for (int j = 0; j < 3; ++j) {
      const auto& c = m.cylinders[static_cast<std::size_t>(j)];
      v = std::max(
          v, std::abs(dynamics::cylinder_length(c, q1[j]) - dynamics::cylinder_length(c, q0[j])) *
                 1.875 / duration);
    }
    return v;
  }
};

// The quasi-static energy of a reference (mhsb_actuator_power_w, series model, gravity forces),
// integrated at the control period.
double quasi_static_energy_j(const dynamics::CraneModel& m, const Quintic& ref, double duration,
                             double period) {
  dynamics::RigidBodyTerms terms(m);
  MhsbReference r;
  JointVector g, dc;
  double e = 0.0;
  for (double t = 0.0; t < duration - 1e-9; t += period) {
    ref(t + 0.5 * period, r);
    terms.gravity(r.q, g);
    dynamics::cylinder_arms(m, r.q, dc);
    for (int j = 0; j < 3; ++j) {
      const double f = g[j] / dc[j];
      const double v = dc[j] * r.qdot[j];
      e += mhsb::mhsb_actuator_power_w(m, j, r.modes.mode[static_cast<std::size_t>(j)], f, v,
                                       mhsb::MhsbEnergyModel::kSeries) *
           period;
    }
  }
  return e;
}

mhsb::MhsbRunSummary run(MhsbSimulator& sim, const Quintic& ref, double duration,
                         const char* csv_name = nullptr) {
  if (csv_name == nullptr) return mhsb::run_mhsb_reference(sim, ref, duration);
  std::ostringstream csv;
  auto sum = mhsb::run_mhsb_reference(sim, ref, duration, &csv);
  if (const char* dir = std::getenv("MHSB_SIM_CSV_DIR")) {
    std::ofstream(std::string(dir) + "/" + csv_name) << csv.str();
  }
  return sum;
}

// The arm stretched out forward, link 1 10 deg down: J1's gravity load needs about 7 MPa.
const JointVector kStretched = deg(-10, 0, 0);

TEST(MhsbSimulator, StretchedPoseNeedsMoreThanP0AtJ1) {
  // The premise of the boost tests below.
  const auto& m = arm_model();
  dynamics::RigidBodyTerms terms(m);
  JointVector g, dc;
  terms.gravity(kStretched, g);
  dynamics::cylinder_arms(m, kStretched, dc);
  EXPECT_TRUE(mhsb::needs_boost(m, 0, g[0] / dc[0], 1e-3));
  EXPECT_GT(g[0] / dc[0] / m.cylinders[0].area_a_m2, 1.5 * m.pump.supply_pressure_pa);
}

TEST(MhsbSimulator, HoldsAPoseAgainstGravity) {
  const auto& m = arm_model();
  const JointVector q0 = deg(80, -120, -60);  // every load below P0
  MhsbSimulator sim(m, {}, q0);
  const Quintic hold{q0, q0, 0.0, 1.0, pattern("N-N-N")};
  const auto sum = run(sim, hold, 3.0, "hold.csv");
  EXPECT_EQ(sum.invalid_references, 0);
  EXPECT_EQ(sum.dynamics_failures, 0);
  std::cout << "hold: max joint error " << sum.max_abs_error_any / kDeg << " deg\n";
  EXPECT_LT(sum.max_abs_error_any, 0.2 * kDeg);
  EXPECT_LT((sim.state().q - q0).cwiseAbs().maxCoeff(), 0.05 * kDeg);
  EXPECT_LT(sim.state().qdot.cwiseAbs().maxCoeff(), 1e-3);
}

TEST(MhsbSimulator, HoldsAPoseThatNeedsABoostInDb) {
  const auto& m = arm_model();
  MhsbSimulator sim(m, {}, kStretched);
  const Quintic hold{kStretched, kStretched, 0.0, 1.0, pattern("DB-N-N")};
  const auto sum = run(sim, hold, 3.0);
  std::cout << "DB hold: max joint error " << sum.max_abs_error_any / kDeg << " deg, supply "
            << sim.state().p_supply_pa[0] / 1e6 << " MPa\n";
  EXPECT_LT(sum.max_abs_error_any, 0.2 * kDeg);
  EXPECT_LT(sim.state().qdot.cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_GT(sim.state().p_supply_pa[0], m.pump.supply_pressure_pa + 2e6);
}

// J1 lifts the stretched arm by 15 deg: its cylinder at 12 mm/s (more than one servo-pump's flow).
Quintic lift(const char* modes, double duration) {
  return {kStretched, deg(5, 0, 0), 0.2, duration, pattern(modes)};
}

TEST(MhsbSimulator, NCannotLiftWhatNeedsMoreThanP0ButDbCan) {
  const auto& m = arm_model();
  const double p0 = m.pump.supply_pressure_pa;
  const Quintic n_lift = lift("N-N-N", 4.0);
  const Quintic db_lift = lift("DB-N-N", 4.0);
  ASSERT_LT(db_lift.peak_cylinder_speed(m), 8e-3);  // within one servo-pump's flow

  MhsbSimulator n_sim(m, {}, kStretched);
  double n_max_q1 = -1.0;
  MhsbReference r;
  double n_max_pump_speed = 0.0;
  for (int k = 0; k < 1250; ++k) {
    n_lift(k * 0.004, r);
    n_sim.step(r);
    n_max_q1 = std::max(n_max_q1, n_sim.state().q[0]);
    for (double w : n_sim.state().pump_speed_rad_s) {
      n_max_pump_speed = std::max(n_max_pump_speed, std::abs(w));
    }
  }
  // The main line may rise above P0 here: the load presses oil back through the open valve
  // against the main pump's outlet check. N never boosts: the servo-pumps stand.
  std::cout << "N: highest J1 " << n_max_q1 / kDeg << " deg (target 5 deg), supply "
            << n_sim.state().p_supply_pa[0] / 1e6 << " MPa\n";
  EXPECT_LT(n_max_q1, kStretched[0] + 1.0 * kDeg);
  EXPECT_EQ(n_max_pump_speed, 0.0);

  MhsbSimulator db_sim(m, {}, kStretched);
  const auto sum = run(db_sim, db_lift, 5.0, "db_lift.csv");
  std::cout << "DB: J1 " << db_sim.state().q[0] / kDeg << " deg, max error "
            << sum.max_abs_error[0] / kDeg << " deg, max supply " << sum.max_p_supply_pa[0] / 1e6
            << " MPa\n";
  EXPECT_NEAR(db_sim.state().q[0], 5.0 * kDeg, 0.2 * kDeg);
  EXPECT_GT(sum.max_p_supply_pa[0], p0 + 2e6);
  EXPECT_LT(sum.max_abs_error[0], 1.0 * kDeg);
}

TEST(MhsbSimulator, SbMovesFasterThanDbUnderTheLoad) {
  const auto& m = arm_model();
  // A ramp at 12 mm/s of cylinder speed: more than one servo-pump delivers (8.2 mm/s).
  const double v_cyl = 12e-3;
  const double rate = v_cyl / m.cylinders[0].arm_m;
  const auto ramp = [&](const char* modes) {
    return [&, modes](double t, MhsbReference& r) {
      const double s = std::clamp(t - 0.2, 0.0, 1.5);
      r.q = kStretched;
      r.q[0] += rate * s;
      r.qdot.setZero(3);
      r.qdot[0] = t > 0.2 && t < 1.7 ? rate : 0.0;
      r.qddot.setZero(3);
      r.modes = pattern(modes);
    };
  };
  // Mean cylinder speed from 0.6 s to 1.6 s (the ramp runs from 0.2 s to 1.7 s).
  const auto mean_speed = [&](const char* modes) {
    MhsbSimulator sim(m, {}, kStretched);
    std::ostringstream csv;
    mhsb::run_mhsb_reference(sim, ramp(modes), 0.6, &csv);
    const double c0 = sim.state().cylinder_m[0];
    MhsbReference r;
    for (int k = 150; k < 400; ++k) {
      ramp(modes)(k * 0.004, r);
      sim.step(r);
    }
    if (const char* dir = std::getenv("MHSB_SIM_CSV_DIR")) {
      std::ofstream(std::string(dir) + "/ramp_" + modes + ".csv") << csv.str();
    }
    return (sim.state().cylinder_m[0] - c0) / 1.0;
  };
  const double db = mean_speed("DB-N-N");
  const double sb = mean_speed("SB-N-N");
  std::cout << "cylinder 1 speed under the load: DB " << db * 1e3 << " mm/s, SB " << sb * 1e3
            << " mm/s (reference 12 mm/s)\n";
  // DB: one servo-pump's flow less the leakage, 0.2415 L/min over the piston area (8.2 mm/s).
  const double db_cap = m.mhsb->servo_pump_max_flow_m3_s / m.cylinders[0].area_a_m2;
  EXPECT_NEAR(db, db_cap, 0.1 * db_cap);
  EXPECT_GT(sb, 1.3 * db);
  // Within 15 %: SB catches up the lag of the ramp's start inside the window.
  EXPECT_NEAR(sb, v_cyl, 0.15 * v_cyl);
}

TEST(MhsbSimulator, CheckValveFeedsTheDbNodeWhenTheServoPumpStands) {
  // J3 in DB with a light load: the pressure target is below P0, so its servo-pump stands and the
  // check valve feeds the valve from the main line.
  const auto& m = arm_model();
  const double p0 = m.pump.supply_pressure_pa;
  const Quintic move{deg(80, -120, -60), deg(80, -120, -30), 0.2, 3.0, pattern("N-N-DB")};
  MhsbSimulator sim(m, {}, move.q0);
  MhsbReference r;
  double min_ps = 1e12, max_ps = 0.0, max_speed = 0.0;
  for (int k = 0; k < 900; ++k) {
    move(k * 0.004, r);
    ASSERT_EQ(sim.step(r), mhsb::MhsbStepStatus::kOk);
    const auto& s = sim.state();
    min_ps = std::min(min_ps, s.p_supply_pa[2]);
    max_ps = std::max(max_ps, s.p_supply_pa[2]);
    for (int p = 0; p < sim.servo_pumps(); ++p) {
      if (s.pump_joint[static_cast<std::size_t>(p)] == 2) {
        max_speed = std::max(max_speed, s.pump_speed_rad_s[static_cast<std::size_t>(p)]);
      }
    }
  }
  std::cout << "DB node with the servo-pump standing: " << min_ps / 1e6 << " .. " << max_ps / 1e6
            << " MPa, servo-pump speed at most " << max_speed << " rad/s\n";
  EXPECT_LT(max_speed, 0.01 * sim.servo_pump_max_speed_rad_s());
  EXPECT_GT(min_ps, p0 - 0.3e6);
  EXPECT_LT(max_ps, p0 + 0.05e6);
  EXPECT_NEAR(sim.state().q[2], move.q1[2], 0.2 * kDeg);
}

// All three joints, N only, cylinders at most 12 mm/s.
Quintic n_move() {
  return {deg(80, -120, -60), deg(72, -104, -36), 0.2, 3.0, pattern("N-N-N")};
}

TEST(MhsbSimulator, TracksASmoothQuasiStaticMove) {
  const auto& m = arm_model();
  const Quintic move = n_move();
  ASSERT_LE(move.peak_cylinder_speed(m), 12e-3);
  MhsbSimulator sim(m, {}, move.q0);
  const auto sum = run(sim, move, 4.0, "n_move.csv");
  std::cout << "quintic N move: max joint errors " << sum.max_abs_error.transpose() / kDeg
            << " deg\n";
  EXPECT_LT(sum.max_abs_error_any, 0.5 * kDeg);  // paper 001 section 4.2: 2.43 deg
  EXPECT_LT((sim.state().q - move.q1).cwiseAbs().maxCoeff(), 0.1 * kDeg);
}

void expect_energy_near_model(const Quintic& move, double duration, const char* what) {
  const auto& m = arm_model();
  MhsbSimulator sim(m, {}, move.q0);
  const auto sum = run(sim, move, duration);
  const double model_j = quasi_static_energy_j(m, move, duration, 0.004);
  std::cout << what << ": measured " << sum.energy_j << " J (main pump " << sum.main_energy_j
            << " J, servo-pumps " << sum.servo_pump_energy_j << " J), quasi-static " << model_j
            << " J, " << 100.0 * (sum.energy_j / model_j - 1.0) << " %\n";
  EXPECT_NEAR(sum.energy_j, model_j, 0.1 * model_j);
}

TEST(MhsbSimulator, EnergyOfAnNMoveMatchesTheQuasiStaticModel) {
  expect_energy_near_model(n_move(), 4.0, "N move");
}

TEST(MhsbSimulator, EnergyOfABoostedMoveMatchesTheQuasiStaticModel) {
  const Quintic move = lift("DB-N-N", 4.0);
  expect_energy_near_model(move, 4.5, "DB lift");
}

TEST(MhsbSimulator, InvalidReferenceHoldsTheLastOne) {
  const auto& m = arm_model();
  const JointVector q0 = deg(80, -120, -60);
  MhsbSimulator sim(m, {}, q0);
  MhsbReference r;
  Quintic{q0, q0, 0.0, 1.0, pattern("N-N-N")}(0.0, r);
  EXPECT_EQ(sim.step(r), mhsb::MhsbStepStatus::kOk);
  MhsbReference bad = r;
  bad.q[1] = std::nan("");
  EXPECT_EQ(sim.step(bad), mhsb::MhsbStepStatus::kInvalidReference);
  bad = r;
  bad.modes = pattern("SB-SB-SB");  // six modules, four fitted
  EXPECT_EQ(sim.step(bad), mhsb::MhsbStepStatus::kInvalidReference);
  EXPECT_EQ(sim.state().modes, pattern("N-N-N"));
  EXPECT_THROW(MhsbSimulator(m, {}, deg(0, 0, 0).head(2)), std::invalid_argument);
  mhsb::MhsbSettings s;
  s.plant.mechanical_step_s = 0.3e-3;  // does not divide 4 ms
  EXPECT_THROW(MhsbSimulator(m, s, q0), std::invalid_argument);
}

TEST(MhsbSimulator, CsvHasOneRowPerPeriodAndTheDocumentedColumns) {
  const auto& m = arm_model();
  const Quintic move = n_move();
  MhsbSimulator sim(m, {}, move.q0);
  std::ostringstream csv;
  mhsb::run_mhsb_reference(sim, move, 0.1, &csv);
  std::istringstream in(csv.str());
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("t_s,j1_q_ref,j1_q,j1_q_error,j1_mode,", 0), 0u);
  EXPECT_NE(header.find(",sp4_joint,sp4_speed_rad_s,p_main_pa,"), std::string::npos);
  int rows = 0;
  const auto columns = std::count(header.begin(), header.end(), ',');
  while (std::getline(in, line)) {
    ++rows;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), columns);
  }
  EXPECT_EQ(rows, 25);
}

TEST(MhsbSimulator, StepAllocatesNothing) {
  const auto& m = arm_model();
  MhsbSimulator sim(m, {}, kStretched);
  MhsbReference r;
  const Quintic a = lift("DB-N-N", 2.0);
  const Quintic b = lift("SB-DB-N", 2.0);
  a(0.0, r);
  sim.step(r);  // warm
  test::expect_no_heap_or_ode_allocations(m, [&] {
    for (int k = 0; k < 200; ++k) {
      (k < 100 ? a : b)(k * 0.004, r);
      sim.step(r);
    }
  });
}

}  // namespace
