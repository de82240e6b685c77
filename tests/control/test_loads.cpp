// Loads nobody announces (docs/loads.md): the simulator's load body, load-holding valves,
// friction and pressure sensors; the crane scale; the rated capacity limiter; end to end on the
// simulated K70M. Figures for the docs are printed as "[ figures  ]" lines.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "config_edit.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/static_gravity.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

using namespace craneassist;

namespace {

const std::string kSource = CRANEASSIST_SOURCE_DIR;
const std::string kK70m = kSource + "/config/cranes/k70m.yaml";
constexpr int kLift = 1, kTilt = 2;

// What a run did, cycle by cycle.
struct Sample {
  double t;
  Eigen::Vector3d cmd, tip, tip_v;
  scaling::ActiveLimit limit;
  control::LoadOutput load;
  double truth_kg;
  double lift_cylinder_v;
  double power_w;
};

class Probe final : public control::CycleObserver {
 public:
  explicit Probe(const dynamics::CraneModel& model) : model_(model) {}
  void on_cycle(const control::CycleRecord& c) noexcept override {
    if (c.controller == nullptr) return;
    const auto& r = c.row;
    Sample s{c.time.t_s,
             Eigen::Vector3d(r.cmd[0], r.cmd[1], r.cmd[2]),
             Eigen::Vector3d(r.tip[0], r.tip[1], r.tip[2]),
             Eigen::Vector3d(r.tip_v[0], r.tip_v[1], r.tip_v[2]),
             c.controller->limit,
             c.controller->load,
             c.state.payload_truth_kg,
             c.state.valid ? c.state.qdot[kLift] *
                                 dynamics::cylinder_arm(model_.cylinders[kLift], c.state.q[kLift])
                           : 0.0,
             c.state.pump.power_w};
    samples.push_back(s);
  }
  std::vector<Sample> samples;

 private:
  const dynamics::CraneModel& model_;
};

struct RunResult {
  control::RunSummary summary;
  std::vector<Sample> samples;
};

RunResult run(const config::CraneConfig& cfg, const input::Replay& replay, bool known = false,
              double settle_s = 1.0) {
  sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
  Probe probe(cfg.model);
  probe.samples.reserve(10000);
  control::RunOptions options;
  options.controller.payload_known = known;
  options.settle_s = settle_s;
  options.observers.push_back(&probe);
  RunResult r;
  r.summary = control::run_replay(cfg, replay, machine, options, nullptr);
  r.samples = std::move(probe.samples);
  return r;
}

config::CraneConfig k70m(double payload_kg) {
  auto cfg = config::default_crane_config();
  config::set_payload_mass(cfg.model, payload_kg);
  return cfg;
}

input::Replay replay_text(const std::string& text) {
  return input::Replay::parse(text, "test.csv");
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

double reach(const Eigen::Vector3d& tip) {
  return std::hypot(tip.x(), tip.z());
}

// The chamber pressures after the simulator has stood for settle_s with neutral valves.
valves::MachineState standing(sim_backend::SimBackend& sim, int dof, double settle_s) {
  valves::ValveCommand neutral;
  neutral.spool = dynamics::JointVector::Zero(dof);
  sim.write(neutral);
  sim.advance(settle_s);
  valves::MachineState s;
  sim.read(s);
  return s;
}

}  // namespace

TEST(LoadChart, InterpolatesAndHoldsTheMomentBeyondTheLastReach) {
  const auto cfg = config::default_crane_config();
  const auto& chart = cfg.load_chart;
  ASSERT_FALSE(chart.empty());
  EXPECT_DOUBLE_EQ(chart.rated_kg_at(chart.reach_m.back()), chart.rated_kg.back());
  EXPECT_DOUBLE_EQ(chart.rated_kg_at(1.0), chart.rated_kg.front());
  EXPECT_NEAR(chart.rated_kg_at(10.0) * 10.0, chart.rated_kg.back() * chart.reach_m.back(), 1e-9);
  const double mid = chart.rated_kg_at(0.5 * (chart.reach_m[2] + chart.reach_m[3]));
  EXPECT_NEAR(mid, 0.5 * (chart.rated_kg[2] + chart.rated_kg[3]), 1e-9);
  EXPECT_EQ(chart.rated_kg_at(std::nan("")), 0.0);
}

TEST(LoadConfig, BadFrictionValvesSensorsAndChartNameTheField) {
  using test::crane_config_error_after_edit;
  auto e = crane_config_error_after_edit(kK70m, "coulomb_extend: 1.5 kN", "coulomb_extend: -1 kN");
  EXPECT_NE(std::string(e.what()).find("friction.coulomb_extend"), std::string::npos) << e.what();
  e = crane_config_error_after_edit(kK70m, "viscous: 5 kN*s/m", "viscous: 5 kN");
  EXPECT_NE(std::string(e.what()).find("friction.viscous"), std::string::npos) << e.what();
  e = crane_config_error_after_edit(kK70m, "relief: 23 MPa", "relief: 20 MPa");
  EXPECT_NE(std::string(e.what()).find("load_holding.relief"), std::string::npos) << e.what();
  e = crane_config_error_after_edit(kK70m, "noise: 0.03 MPa", "noise: 3 m");
  EXPECT_NE(std::string(e.what()).find("pressure_sensors.noise"), std::string::npos) << e.what();
  e = crane_config_error_after_edit(kK70m, "rated_load: 1260 885", "rated_load: 1260");
  EXPECT_NE(std::string(e.what()).find("load_chart.rated_load"), std::string::npos) << e.what();
  e = crane_config_error_after_edit(kK70m, "reach: 4 5 6", "reach: 4 6 5");
  EXPECT_NE(std::string(e.what()).find("load_chart.reach"), std::string::npos) << e.what();
}

TEST(SimLoads, ThePayloadChangesWhileTheCraneStandsAndThePressuresSayBy) {
  auto cfg = k70m(0.0);
  cfg.simulation.pressure_noise_pa = 0.0;
  cfg.simulation.pressure_resolution_pa = 0.0;
  sim_backend::SimBackend sim(cfg.model, offline::sim_settings(cfg));
  const int n = cfg.model.dof();
  const auto empty = standing(sim, n, 0.5);
  EXPECT_EQ(empty.payload_truth_kg, 0.0);
  ASSERT_TRUE(empty.chamber_pressures);
  sim.set_payload_mass(650.0);
  const auto loaded = standing(sim, n, 1.0);
  EXPECT_EQ(loaded.payload_truth_kg, 650.0);
  // The lift's effort grows by the payload's weight times its horizontal arm about the lift
  // joint.
  const auto& cyl = cfg.model.cylinders[kLift];
  const double arm = dynamics::cylinder_arm(cyl, loaded.q[kLift]);
  const auto force = [&](const valves::MachineState& s) {
    return s.pressure_a_pa[kLift] * cyl.area_a_m2 - s.pressure_b_pa[kLift] * cyl.area_b_m2;
  };
  dynamics::KinematicsData kin;
  dynamics::forward_kinematics(cfg.model, kin, loaded.q);
  const Eigen::Vector3d tip = kin.frames[static_cast<std::size_t>(n)].translation();
  const Eigen::Vector3d joint = kin.frames[kLift].translation();
  const Eigen::Vector3d axis = kin.frames[kLift].linear().col(2);
  const double expected = 650.0 * 9.81 * axis.dot((tip - joint).cross(Eigen::Vector3d::UnitZ()));
  EXPECT_NEAR((force(loaded) - force(empty)) * arm, std::abs(expected), 0.01 * std::abs(expected));
  // Nonsense is ignored.
  sim.set_payload_mass(-1.0);
  sim.set_payload_mass(std::nan(""));
  EXPECT_EQ(sim.payload_mass(), 650.0);
}

TEST(SimLoads, ALoadBeyondThePortReliefSinksAtTheValveFlowNeverFaster) {
  const auto cfg = k70m(2500.0);
  sim_backend::SimBackend sim(cfg.model, offline::sim_settings(cfg));
  const int n = cfg.model.dof();
  const auto& cyl = cfg.model.cylinders[kLift];
  const double creep = cfg.model.load_holding.relief_flow_m3_s / cyl.area_a_m2;
  valves::ValveCommand neutral;
  neutral.spool = dynamics::JointVector::Zero(n);
  double fastest = 0.0, sum = 0.0;
  int samples = 0;
  for (int k = 0; k < 300; ++k) {
    sim.write(neutral);
    sim.advance(0.01);
    valves::MachineState s;
    sim.read(s);
    const double v = s.qdot[kLift] * dynamics::cylinder_arm(cyl, s.q[kLift]);
    fastest = std::max(fastest, -v);
    if (k >= 100) {
      sum += -v;
      ++samples;
    }
  }
  EXPECT_TRUE(sim.relief_passing(kLift));
  EXPECT_LE(fastest, 1.2 * creep) << "sank faster than the valve's relief flow";
  EXPECT_NEAR(sum / samples, creep, 0.2 * creep) << "creeps at the relief flow";
}

TEST(SimLoads, ALoadThePumpCannotLiftIsHeldNotDropped) {
  // The pump's relief just below what the lift needs for 900 kg, the load-holding valves above.
  auto cfg = k70m(900.0);
  cfg.simulation.pressure_noise_pa = 0.0;
  {
    sim_backend::SimBackend probe(cfg.model, offline::sim_settings(cfg));
    const auto s = standing(probe, cfg.model.dof(), 0.3);
    cfg.model.pump.max_pressure_pa = s.pressure_a_pa[kLift] - 1e6;
    cfg.model.load_holding.relief_pa = s.pressure_a_pa[kLift] + 3e6;
  }
  sim_backend::SimBackend sim(cfg.model, offline::sim_settings(cfg));
  const int n = cfg.model.dof();
  valves::MachineState s;
  sim.read(s);
  const double q0 = s.q[kLift];
  valves::ValveCommand up;
  up.spool = dynamics::JointVector::Zero(n);
  up.spool[kLift] = 1.0;
  double lowest = q0;
  for (int k = 0; k < 200; ++k) {
    sim.write(up);
    sim.advance(0.01);
    sim.read(s);
    lowest = std::min(lowest, s.q[kLift]);
  }
  EXPECT_FALSE(sim.relief_passing(kLift));
  EXPECT_GT(lowest, q0 - 1e-3) << "the boom fell against the stick";
  EXPECT_LT(s.q[kLift], q0 + 1e-3) << "lifted a load beyond the pump's relief";
}

TEST(SimLoads, FrictionShowsInTheChamberPressuresWhileMoving) {
  auto cfg = k70m(0.0);
  cfg.simulation.pressure_noise_pa = 0.0;
  cfg.model.grapple = {};  // rigid: a swinging grapple would add its inertia to the force
  const auto& cyl = cfg.model.cylinders[kTilt];
  const auto force_moving = [&](double spool) {
    sim_backend::SimBackend sim(cfg.model, offline::sim_settings(cfg));
    valves::ValveCommand c;
    c.spool = dynamics::JointVector::Zero(cfg.model.dof());
    c.spool[kTilt] = spool;
    valves::MachineState s;
    for (int k = 0; k < 60; ++k) {
      sim.write(c);
      sim.advance(0.01);
    }
    sim.read(s);
    return s.pressure_a_pa[kTilt] * cyl.area_a_m2 - s.pressure_b_pa[kTilt] * cyl.area_b_m2;
  };
  // Slowly out, slowly in about the same pose: the gravity load is nearly the same, the
  // friction changes sign.
  const double out = force_moving(0.6), in = force_moving(-0.6);
  const auto& f = cyl.friction;
  EXPECT_NEAR(out - in, f.coulomb_extend_n + f.coulomb_retract_n,
              0.5 * (f.coulomb_extend_n + f.coulomb_retract_n));
}

// The crane scale over the loading cycles, at rest and moving, loads 0 to 1000 kg.
TEST(CraneScale, WeighsUnannouncedLoadsWithinOnePercentAtRestAndThreeMoving) {
  const auto cycle = input::Replay::load_file(kSource + "/examples/replays/work_cycle.csv");
  const double rated = 650.0;
  for (const double load : {0.0, 300.0, 650.0, 1000.0}) {
    // The cycle's load column grabs 450 kg; here the grabbed log weighs `load`.
    std::vector<input::ReplayRow> rows = cycle.rows();
    for (auto& r : rows) {
      if (r.load_kg > 0.0) r.load_kg = load;
    }
    std::ostringstream text;
    input::write_replay(text, rows);
    const auto replay = input::Replay::parse(text.str(), "work_cycle");
    const RunResult r = run(k70m(0.0), replay);
    const auto& l = r.summary.load;
    std::printf(
        "[ figures  ] crane scale, work cycle with %.0f kg: at rest max %.1f kg (%ld cycles), "
        "moving max %.1f kg (%ld cycles); final %.1f kg\n",
        load, l.max_error_rest_kg, l.rest_samples, l.max_error_moving_kg, l.moving_samples,
        l.estimate_kg);
    EXPECT_GT(l.rest_samples, 50);
    EXPECT_GT(l.moving_samples, 50);
    EXPECT_LE(l.max_error_rest_kg, 0.01 * rated) << load << " kg";
    EXPECT_LE(l.max_error_moving_kg, 0.03 * rated) << load << " kg";
    // Until the scale has weighed the load the dynamics never assume less than the rated load.
    for (const auto& s : r.samples) {
      if (!s.load.converged) {
        ASSERT_GE(s.load.model_kg, s.load.rated_kg - 1e-9);
      }
    }
  }
}

TEST(CraneScale, ALogSlippingOutMidLiftIsSeen) {
  const auto replay = input::Replay::load_file(kSource + "/examples/replays/work_cycle_slip.csv");
  const RunResult r = run(k70m(0.0), replay);
  EXPECT_EQ(r.summary.load.truth_changes, 2);
  EXPECT_LE(r.summary.load.max_error_moving_kg, 0.03 * 650.0);
  EXPECT_NEAR(r.summary.load.estimate_kg, 0.0, 6.5);
  EXPECT_GE(r.summary.load.max_error_rest_kg, 0.0);
}

// 1200 kg at the start pose (about 110 % of the rated moment there).
TEST(RatedCapacityLimiter, OverloadedReachingOutIsRefusedPullingInStaysFree) {
  const auto cfg = k70m(1200.0);
  const RunResult out = run(cfg, replay_text("t,v_x,v_y,v_z\n0,0,0,0\n1,0.4,0,0\n5,0,0,0\n"));
  double trip_moment = -1.0, peak_moment = 0.0, against = 0.0;
  for (const auto& s : out.samples) {
    const double moment = 1200.0 * reach(s.tip);
    if (s.load.overload && trip_moment < 0.0) trip_moment = moment;
    if (trip_moment >= 0.0) peak_moment = std::max(peak_moment, moment);
    if (s.cmd.norm() > 0.0) against = std::max(against, -s.tip_v.dot(s.cmd.normalized()));
  }
  const double rated_moment =
      cfg.load_chart.rated_kg_at(reach(out.samples.front().tip)) * reach(out.samples.front().tip);
  ASSERT_GE(trip_moment, 0.0) << "the limiter never tripped";
  std::printf(
      "[ figures  ] 1200 kg at the start pose: load moment rose %.1f %% of rated after the trip, "
      "against the stick at most %.3f m/s, refused in %ld cycles\n",
      100.0 * (peak_moment - trip_moment) / rated_moment, against, out.summary.load.refused_cycles);
  EXPECT_LE(peak_moment - trip_moment, 0.05 * rated_moment);
  EXPECT_LE(against, 0.05);
  EXPECT_GT(out.summary.limit_cycles[static_cast<std::size_t>(scaling::ActiveLimit::kOverload)],
            50);

  const RunResult in = run(cfg, replay_text("t,v_x,v_y,v_z\n0,0,0,0\n1,-0.4,0,0\n4,0,0,0\n"));
  EXPECT_GT(in.summary.tip_path_m, 0.8) << "pulling in must stay free";
  double in_against = 0.0;
  for (const auto& s : in.samples) {
    if (s.cmd.norm() > 0.0) in_against = std::max(in_against, -s.tip_v.dot(s.cmd.normalized()));
  }
  EXPECT_LE(in_against, 0.05);
}

TEST(RatedCapacityLimiter, AboveThePortReliefTheBoomSinksAtTheValveFlowAndTheSummarySaysSo) {
  const auto cfg = k70m(2500.0);
  const RunResult r = run(cfg, replay_text("t,v_x,v_y,v_z\n0,0,0,0\n1,0.3,0,0\n3,0,0,0\n"));
  const auto& cyl = cfg.model.cylinders[kLift];
  const double creep = cfg.model.load_holding.relief_flow_m3_s / cyl.area_a_m2;
  double fastest = 0.0;
  for (const auto& s : r.samples) fastest = std::max(fastest, -s.lift_cylinder_v);
  EXPECT_GT(r.summary.load.relief_cycles, 0);
  EXPECT_GT(r.summary.load.overload_cycles, 0);
  EXPECT_LE(fastest, 1.2 * creep + 0.005) << "the lift sank faster than the valve's flow";
}

// The heavy lift with 650 kg at 20 kW, the controller told nothing.
TEST(LoadsEndToEnd, HeavyLiftUnannouncedStaysWithinPowerOnEveryResolution) {
  const auto replay = input::Replay::load_file(kSource + "/examples/replays/heavy_lift.csv");
  for (const char* resolution : {"pinv-joint", "pinv-actuator", "min-flow", "min-ls-power"}) {
    auto cfg = k70m(650.0);
    config::set_prime_mover_power(cfg.model, 20e3);
    config::set_resolution(cfg, resolution);
    const RunResult r = run(cfg, replay, false, 1.5);
    std::vector<double> errors;
    double peak = 0.0;
    for (const auto& s : r.samples) {
      peak = std::max(peak, s.power_w);
      if (s.cmd.norm() > 0.0 && s.tip_v.norm() > 0.05) errors.push_back(angle_deg(s.cmd, s.tip_v));
    }
    ASSERT_FALSE(errors.empty());
    std::sort(errors.begin(), errors.end());
    const double p95 =
        errors[static_cast<std::size_t>(0.95 * static_cast<double>(errors.size() - 1))];
    std::printf(
        "[ figures  ] heavy lift 650 kg unannounced, 20 kW, %s: peak power %.3f P_max, "
        "direction error p95 %.2f deg, max %.2f deg, final estimate %.1f kg\n",
        resolution, peak / 20e3, p95, errors.back(), r.summary.load.estimate_kg);
    EXPECT_LE(peak, 1.02 * 20e3) << resolution;
    EXPECT_LE(p95, 2.0) << resolution;
    // Weighed within 3 % of the rated load to the end, and the stop never opens a port relief.
    EXPECT_NEAR(r.summary.load.estimate_kg, 650.0, 0.03 * 650.0) << resolution;
    EXPECT_EQ(r.summary.load.relief_cycles, 0) << resolution;
  }
}

// Told, on the simulator the controller follows every load change of the replay too.
TEST(LoadsEndToEnd, KnownPayloadFollowsTheReplaysLoadColumn) {
  const auto cycle = input::Replay::load_file(kSource + "/examples/replays/work_cycle.csv");
  const RunResult r = run(k70m(0.0), cycle, true);
  int loaded = 0;
  for (const auto& s : r.samples) {
    ASSERT_EQ(s.load.model_kg, s.truth_kg) << s.t;
    loaded += s.truth_kg == 450.0;
  }
  EXPECT_GT(loaded, 500);
}

TEST(LoadsEndToEnd, KnownPayloadKeepsTodaysBehaviour) {
  const auto replay = input::Replay::load_file(kSource + "/examples/replays/heavy_lift.csv");
  const RunResult r = run(k70m(650.0), replay, true);
  for (const auto& s : r.samples) {
    ASSERT_EQ(s.load.model_kg, 650.0);
    ASSERT_TRUE(s.load.converged);
  }
}

// The K70M's chart against what its cylinders hold: at every reach on the chart, the rated load
// held in any pose at that reach needs at most 90 % of the pump's relief on lift and tilt.
TEST(LoadChart, K70mChartIsWithinWhatTheCylindersHoldAtNinetyPercentOfRelief) {
  auto cfg = config::default_crane_config();
  auto& model = cfg.model;
  const auto& chart = cfg.load_chart;
  const double relief = model.pump.max_pressure_pa;
  dynamics::KinematicsData kin;
  dynamics::JointVector q = cfg.simulation.q_initial, effort;
  constexpr int kSteps = 40;
  std::vector<double> worst(chart.reach_m.size(), 0.0);  // highest pressure share per kg
  for (int a = 0; a <= kSteps; ++a) {
    for (int b = 0; b <= kSteps; ++b) {
      for (int c = 0; c <= 8; ++c) {
        const auto& j = model.joints;
        // Off the end stops (the last 5 % of a range, where the stop carries the load).
        const auto inner = [&](int i, double share) {
          return j[i].q_min + (j[i].q_max - j[i].q_min) * (0.05 + 0.9 * share);
        };
        q[1] = inner(1, static_cast<double>(a) / kSteps);
        q[2] = inner(2, static_cast<double>(b) / kSteps);
        q[3] = j[3].q_min + (j[3].q_max - j[3].q_min) * c / 8.0;
        const Eigen::Vector3d tip = dynamics::tip_position(model, kin, q);
        const double r = reach(tip);
        // The working envelope: the outer boom within 10 deg of horizontal (frame 3's z axis is
        // along it; the base frame's z is up).
        const double elevation = std::asin(kin.frames[3].linear().col(2).z());
        if (std::abs(elevation) > 10.0 * M_PI / 180.0) continue;
        for (std::size_t k = 0; k < chart.reach_m.size(); ++k) {
          if (std::abs(r - chart.reach_m[k]) > 0.1) continue;
          config::set_payload_mass(model, chart.rated_kg[k]);
          dynamics::static_gravity_effort(model, kin, q, effort);
          for (int i : {kLift, kTilt}) {
            const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
            const double f = effort[i] / dynamics::cylinder_arm(cyl, q[i]);
            const double p = f >= 0.0 ? f / cyl.area_a_m2 : -f / cyl.area_b_m2;
            worst[k] = std::max(worst[k], p / relief);
          }
        }
      }
    }
  }
  for (std::size_t k = 0; k < chart.reach_m.size(); ++k) {
    std::printf(
        "[ figures  ] chart %.1f m, %.0f kg: worst holding pressure %.1f %% of relief (90 %% "
        "allows %.0f kg)\n",
        chart.reach_m[k], chart.rated_kg[k], 100.0 * worst[k], chart.rated_kg[k] * 0.9 / worst[k]);
    EXPECT_LE(worst[k], 0.9) << chart.reach_m[k] << " m";
    EXPECT_GT(worst[k], 0.0) << "no pose in the envelope at " << chart.reach_m[k] << " m";
  }
}
