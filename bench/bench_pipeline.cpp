// Speed of the control cycle and of the simulator (docs/benchmarks.md has the figures).
//   build/bench/bench_pipeline --benchmark_repetitions=5 --benchmark_report_aggregates_only
#include <benchmark/benchmark.h>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/controller.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/flow_polytope.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/scaling/tip_path.hpp"
#include "craneassist/scaling/tip_scaler.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

using namespace craneassist;

namespace {

// The crane standing still at the configuration's start pose, as the controller reads it.
valves::MachineState still_at_start(const config::CraneConfig& cfg) {
  valves::MachineState s;
  s.q = cfg.simulation.q_initial;
  s.qdot = dynamics::JointVector::Zero(4);
  s.load_pressure_pa = dynamics::JointVector::Zero(4);
  // Both chambers measured, as on the simulator and the K70M's bus: the crane scale runs every
  // cycle (docs/loads.md).
  s.chamber_pressures = true;
  s.pressure_a_pa = dynamics::JointVector::Constant(4, 5e6);
  s.pressure_b_pa = dynamics::JointVector::Constant(4, 0.3e6);
  s.valid = true;
  return s;
}

// One control period (10 ms) of the simulated reference crane moving with every section open:
// the cost of the simulator per control cycle. real_time_factor = simulated / computer time.
void BM_SimulatorControlPeriod(benchmark::State& state) {
  const auto cfg = config::default_crane_config();
  sim_backend::SimBackend sim(cfg.model, {cfg.simulation.step_s, cfg.simulation.q_initial});
  valves::ValveCommand cmd;
  cmd.spool = dynamics::JointVector::Constant(4, 0.7);
  cmd.spool[3] = 0.0;
  const double period = 1.0 / cfg.control.rate_hz;
  int k = 0;
  for (auto _ : state) {
    cmd.spool[1] = (k++ / 100) % 2 == 0 ? 0.7 : -0.7;  // reverse the lift every second
    sim.write(cmd);
    sim.advance(period);
  }
  state.counters["real_time_factor"] = benchmark::Counter(
      period * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulatorControlPeriod)->Unit(benchmark::kMicrosecond);

// The K70M with its sway damping on (argument 1, the default) or off (0, --no-sway-damping).
config::CraneConfig k70m_sway(const benchmark::State& state) {
  auto cfg = config::default_crane_config();
  cfg.scaling.sway_damping = state.range(0) != 0;
  return cfg;
}

// One controller update (redundancy resolution, path scaling, valve mapping) of a crane moving
// out, up and sideways from its start pose, on a machine that follows the reference; started over
// every 3 s of motion so that it measures motion, not a crane come to rest at a workspace end.
// BM_ControllerUpdateWithPolytope: the same with the flow manipulability polytope on, as in a
// run with a log, telemetry or the web view (control::PolytopeProbe).
void controller_update(benchmark::State& state, bool polytope) {
  const auto cfg = k70m_sway(state);
  control::Controller controller(cfg, {.polytope = polytope});
  const valves::MachineState start = still_at_start(cfg);
  valves::MachineState s = start;
  controller.reset(s);
  control::ControllerOutput out;
  const Eigen::Vector3d v(0.3, 0.2, 0.4);
  int k = 0;
  for (auto _ : state) {
    controller.update(s, v, out);
    benchmark::DoNotOptimize(out.valves.spool.data());
    s.q = out.q_ref;
    if (++k % 300 == 0) {
      state.PauseTiming();
      s = start;
      controller.reset(s);
      state.ResumeTiming();
    }
  }
}
void BM_ControllerUpdate(benchmark::State& state) {
  controller_update(state, false);
}
BENCHMARK(BM_ControllerUpdate)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);
void BM_ControllerUpdateWithPolytope(benchmark::State& state) {
  controller_update(state, true);
}
BENCHMARK(BM_ControllerUpdateWithPolytope)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

// The same stick held with the crane at the end of its workspace (every cycle resolves,
// damps the ends and holds the reference at rest): the busiest case of the end handling.
void BM_ControllerUpdateAtWorkspaceEnd(benchmark::State& state) {
  const auto cfg = k70m_sway(state);
  control::Controller controller(cfg, {});
  valves::MachineState s = still_at_start(cfg);
  controller.reset(s);
  control::ControllerOutput out;
  const Eigen::Vector3d v(0.3, 0.2, 0.4);
  for (int k = 0; k < 3000; ++k) {  // 30 s: far enough to meet the end
    controller.update(s, v, out);
    s.q = out.q_ref;
  }
  for (auto _ : state) {
    controller.update(s, v, out);
    benchmark::DoNotOptimize(out.valves.spool.data());
    s.q = out.q_ref;
  }
}
BENCHMARK(BM_ControllerUpdateAtWorkspaceEnd)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

// H(q), C(q,qdot) qdot and g(q) from the ODE model of the reference crane.
void BM_RigidBodyTerms(benchmark::State& state) {
  const auto cfg = config::default_crane_config();
  dynamics::RigidBodyTerms terms(cfg.model);
  dynamics::DynamicsTerms out;
  dynamics::JointVector q = cfg.simulation.q_initial;
  dynamics::JointVector qdot(4);
  qdot << 0.1, 0.2, -0.2, 0.3;
  for (auto _ : state) {
    terms.compute(q, qdot, out);
    benchmark::DoNotOptimize(out.mass.data());
  }
}
BENCHMARK(BM_RigidBodyTerms)->Unit(benchmark::kMicrosecond);

// The per-cycle path dynamics m = H f', b = H f'' sdot^2 + C(q, f' sdot) f' sdot + g of the
// reference crane (2 ODE steps), moving.
void BM_PathTerms(benchmark::State& state) {
  const auto cfg = config::default_crane_config();
  dynamics::RigidBodyTerms terms(cfg.model);
  dynamics::PathTerms out;
  const dynamics::JointVector q = cfg.simulation.q_initial;
  dynamics::JointVector f1(4), f2(4);
  f1 << 0.1, 0.2, -0.2, 0.3;
  f2 << 0.02, -0.05, 0.04, 0.01;
  const double sdot = 0.5;
  for (auto _ : state) {
    if (!terms.path_terms(q, f1, f2, sdot, out)) {
      state.SkipWithError("path_terms: the ODE step failed");
      break;
    }
    benchmark::DoNotOptimize(out.b.data());
  }
}
BENCHMARK(BM_PathTerms)->Unit(benchmark::kMicrosecond);

// The whole per-cycle scaling step of the tip motion (issue target: median under 50 us): the
// redundancy resolution of the direction with the joints kept off their ends (f' and f'', three
// solves), speed limits, m(s) and b(s) from the ODE model, acceleration bounds and the
// jerk-limited move of the reference velocity. The heavy-lift case: 650 kg, moving, power limit
// active.
void BM_ScalingStep(benchmark::State& state) {
  auto cfg = config::default_crane_config();
  config::set_payload_mass(cfg.model, 650.0);
  const auto& sc = cfg.scaling;
  const double period = 1.0 / cfg.control.rate_hz;
  dynamics::RigidBodyTerms terms(cfg.model);
  scaling::TipPathConfig path_config;
  path_config.period_s = period;
  path_config.jerk_max = sc.jerk_max_m_s3;
  path_config.deceleration_max = sc.deceleration_max_m_s2;
  path_config.flow_reserve = cfg.control.flow_reserve;
  path_config.resolution = cfg.redundancy.resolution;
  scaling::TipPath tip_path(cfg.model, path_config);
  scaling::TipScalerConfig scaler_config;
  scaler_config.period_s = period;
  scaler_config.jerk_max = sc.jerk_max_m_s3;
  scaler_config.acceleration_max = sc.acceleration_max_m_s2;
  scaler_config.deceleration_max = sc.deceleration_max_m_s2;
  scaler_config.flow_reserve = cfg.control.flow_reserve;
  scaler_config.power_reserve = sc.power_reserve;
  scaling::TipScaler scaler(cfg.model, scaler_config, terms);
  scaling::TipPathOutput path;
  scaling::TipScalerOutput out;
  dynamics::JointVector q = cfg.simulation.q_initial;
  const dynamics::JointVector q0 = q;
  const Eigen::Vector3d v(0.0, 1.5, 1.5);
  int k = 0;
  for (auto _ : state) {
    scaling::TipPathInput path_in;
    path_in.direction = scaler.direction(v);
    path_in.sdot = scaler.speed();
    path_in.intended_speed = scaler.intended_speed(v);
    tip_path.update(q, path_in, path);
    scaling::TipScalerInput in;
    in.command = v;
    in.direction = path_in.direction;
    in.sdot_joint_limit = path.sdot_joint_limit;
    scaler.update(q, path.geometry, in, out);
    q += path.geometry.f1 * out.ds;
    if (++k % 300 == 0) {  // stay inside the workspace: start over every 3 s of motion
      q = q0;
      scaler.reset();
      tip_path.reset();
    }
    benchmark::DoNotOptimize(&out.sdot);
  }
}
BENCHMARK(BM_ScalingStep)->Unit(benchmark::kMicrosecond);

// The flow manipulability polytope of the reference crane at its start pose
// (dynamics/flow_polytope.hpp), in the three parts the controller runs each cycle. Argument: the
// pump's maximum flow in L/min (325: the K70M's, at which the flow barely limits and the
// polytope is the image of the speed box; 120: a pump that cuts it in every orthant).
struct PolytopeRig {
  config::CraneConfig cfg = config::default_crane_config();
  dynamics::FlowPolytope poly{4, 3};
  dynamics::JointVelocitySet set;
  dynamics::TaskJacobian jacobian;
  explicit PolytopeRig(double pump_lpm) {
    cfg.model.pump.max_flow_m3_s = pump_lpm * 1e-3 / 60.0;
    const dynamics::JointVector q = cfg.simulation.q_initial;
    dynamics::JointVector arms;
    dynamics::cylinder_arms(cfg.model, q, arms);
    dynamics::KinematicsData kin;
    dynamics::tip_jacobian(cfg.model, kin, q, jacobian);
    const double r = cfg.control.flow_reserve;
    dynamics::joint_velocity_set(cfg.model, q, arms,
                                 {.flow_reserve = r, .cylinder_speed_reserve = r}, set);
    poly.update(set, jacobian);
    poly.build_hull();
  }
};

// The joint-velocity set's vertices and their tip images.
void BM_PolytopeVertices(benchmark::State& state) {
  PolytopeRig rig(static_cast<double>(state.range(0)));
  for (auto _ : state) {
    rig.poly.update(rig.set, rig.jacobian);
    benchmark::DoNotOptimize(rig.poly.task_points().data());
  }
  state.counters["points"] = rig.poly.point_count();
}
BENCHMARK(BM_PolytopeVertices)->Arg(325)->Arg(120)->Unit(benchmark::kMicrosecond);

// Their convex hull and its volume.
void BM_PolytopeHull(benchmark::State& state) {
  PolytopeRig rig(static_cast<double>(state.range(0)));
  for (auto _ : state) {
    rig.poly.build_hull();
    const double volume = rig.poly.volume();
    benchmark::DoNotOptimize(&volume);
  }
  state.counters["hull_vertices"] = static_cast<double>(rig.poly.hull_vertices().size());
}
BENCHMARK(BM_PolytopeHull)->Arg(325)->Arg(120)->Unit(benchmark::kMicrosecond);

// The LP: the largest tip speed along a direction over every joint velocity.
void BM_PolytopeMaxSpeed(benchmark::State& state) {
  PolytopeRig rig(static_cast<double>(state.range(0)));
  const Eigen::Vector3d u = Eigen::Vector3d(0.3, 0.2, 0.4).normalized();
  for (auto _ : state) {
    const double s = rig.poly.max_speed(u);
    benchmark::DoNotOptimize(&s);
  }
}
BENCHMARK(BM_PolytopeMaxSpeed)->Arg(325)->Arg(120)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
