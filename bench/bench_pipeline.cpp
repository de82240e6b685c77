// Speed of the control cycle and of the simulator (docs/benchmarks.md has the figures).
//   build/bench/bench_pipeline --benchmark_repetitions=5 --benchmark_report_aggregates_only
#include <benchmark/benchmark.h>

#include "craneassist/app/controller.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/scaling/path_scaler.hpp"
#include "craneassist/scaling/tip_path.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

using namespace craneassist;

namespace {

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

// One controller update (redundancy resolution, prescaling, valve mapping) of a moving crane.
void BM_ControllerUpdate(benchmark::State& state) {
  const auto cfg = config::default_crane_config();
  app::Controller controller(cfg, {});
  valves::MachineState s;
  s.q = cfg.simulation.q_initial;
  s.qdot = dynamics::JointVector::Zero(4);
  s.load_pressure_pa = dynamics::JointVector::Zero(4);
  s.valid = true;
  controller.reset(s);
  app::ControllerOutput out;
  const Eigen::Vector3d v(0.3, 0.2, 0.4);
  for (auto _ : state) {
    controller.update(s, v, out);
    benchmark::DoNotOptimize(out.valves.spool.data());
    s.q = out.q_ref;
  }
}
BENCHMARK(BM_ControllerUpdate)->Unit(benchmark::kMicrosecond);

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
    terms.path_terms(q, f1, f2, sdot, out);
    benchmark::DoNotOptimize(out.b.data());
  }
}
BENCHMARK(BM_PathTerms)->Unit(benchmark::kMicrosecond);

// The whole per-cycle scaling step of the tip path (issue target: median under 50 us):
// path-velocity decomposition and redundancy resolution (f', f''), speed limits, m(s) and b(s)
// from the ODE model, acceleration bounds and the jerk-bounded filter. The heavy-lift case:
// 650 kg, moving, power limit active.
void BM_ScalingStep(benchmark::State& state) {
  auto cfg = config::default_crane_config();
  config::set_payload_mass(cfg.model, 650.0);
  const auto& sc = cfg.scaling;
  const double period = 1.0 / cfg.control.rate_hz;
  dynamics::RigidBodyTerms terms(cfg.model);
  scaling::TipPath tip_path(cfg.model, {period, sc.direction_change_acceleration_m_s2,
                                        sc.jerk_max_m_s3, sc.deceleration_max_m_s2});
  scaling::PathScaler scaler(
      cfg.model,
      {period, sc.jerk_max_m_s3, sc.acceleration_max_m_s2, cfg.control.flow_reserve,
       scaling::PowerBound::kLoadSensing, sc.power_reserve},
      terms);
  scaling::TipPathOutput path;
  scaling::PathScalerOutput out;
  dynamics::JointVector q = cfg.simulation.q_initial;
  const dynamics::JointVector q0 = q;
  const Eigen::Vector3d v(0.0, 1.5, 1.5);
  int k = 0;
  for (auto _ : state) {
    tip_path.update(q, v, scaler.state().sdot, path);
    scaling::PathScalerInput in;
    in.sdot_request = path.sdot_request;
    in.sdot_joint_limit = path.sdot_joint_limit;
    scaler.update(q, path.geometry, in, out);
    q += path.geometry.f1 * out.state.sdot * period;
    if (++k % 300 == 0) {  // stay inside the workspace: start over every 3 s of motion
      q = q0;
      scaler.reset();
    }
    benchmark::DoNotOptimize(out.state.sdot);
  }
}
BENCHMARK(BM_ScalingStep)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
