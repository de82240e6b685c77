// One control period (4 ms) of the MHSB arm simulator (docs/mhsb-simulator.md): the cascade
// controller and 16 rigid-body steps of 0.25 ms with 10 pressure substeps each, the three-link arm
// of paper 001 lifting its 10 kg load in DB (J1) while holding J2 and J3 in N.
#include <benchmark/benchmark.h>

#include <numbers>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/mhsb/mhsb_simulator.hpp"

namespace {

using namespace craneassist;

void BM_MhsbControlPeriod(benchmark::State& state) {
  const auto model = config::mhsb_3link_config().model;
  constexpr double kDeg = std::numbers::pi / 180.0;
  dynamics::JointVector q0(3);
  q0 << -10 * kDeg, 0.0, 0.0;
  mhsb::MhsbSimulator sim(model, {}, q0);
  mhsb::MhsbReference ref;
  ref.q = q0;
  ref.qdot.setZero(3);
  ref.qdot[0] = 0.1;  // 4.5 mm/s of cylinder speed
  ref.qddot.setZero(3);
  ref.modes = *mhsb::parse_mode_pattern("DB-N-N", 3);
  const double period = sim.settings().controller.period_s;
  long periods = 0;
  for (auto _ : state) {
    // Up and down within 10 deg, so the run stays in its range however long it lasts.
    if (periods % 400 == 0) ref.qdot[0] = -ref.qdot[0];
    ref.q[0] += ref.qdot[0] * period;
    benchmark::DoNotOptimize(sim.step(ref));
    ++periods;
  }
  state.counters["real_time_factor"] =
      benchmark::Counter(static_cast<double>(periods) * period, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MhsbControlPeriod)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
