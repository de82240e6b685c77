// The one control loop (app/control_loop.hpp) and the machine lifecycle: the loop runs its task
// cycle by cycle on machine time, hands every cycle to the observers in order, ends a run on a
// stop request only once the task reports the machine at rest, safe-stops the machine when that
// takes too long, and treats a machine fault the same in a replay as in a live run.
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/control_loop.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/offline/sim_setup.hpp"

using namespace craneassist;

namespace {

// A machine that counts the calls of the loop; read() reports a fault from cycle fault_at on.
class CountingMachine final : public valves::MachineInterface {
 public:
  explicit CountingMachine(long fault_at = -1) : fault_at_(fault_at) {}
  valves::BackendStatus read(valves::MachineState& state) override {
    ++reads;
    state.valid = !(fault_at_ >= 0 && advances >= fault_at_);
    return state.valid ? valves::BackendStatus::kOk : valves::BackendStatus::kFault;
  }
  valves::BackendStatus write(const valves::ValveCommand&) override {
    ++writes;
    return valves::BackendStatus::kOk;
  }
  void advance(double) override { ++advances; }
  const char* name() const override { return "counting"; }
  bool activate(double, std::string*) override { return true; }
  void safe_stop() noexcept override { ++safe_stops; }
  long reads = 0, writes = 0, advances = 0, safe_stops = 0;

 private:
  long fault_at_;
};

// The simulator whose measurement is lost for good (a latched fault) after `fault_at` cycles.
class FaultingSim final : public valves::MachineInterface {
 public:
  FaultingSim(const config::CraneConfig& cfg, long fault_at)
      : sim_(cfg.model, offline::sim_settings(cfg)), fault_at_(fault_at) {}
  valves::BackendStatus read(valves::MachineState& state) override {
    sim_.read(state);
    if (advances_ < fault_at_) return valves::BackendStatus::kOk;
    state.valid = false;
    return valves::BackendStatus::kFault;
  }
  valves::BackendStatus write(const valves::ValveCommand& c) override { return sim_.write(c); }
  void advance(double dt_s) override {
    ++advances_;
    sim_.advance(dt_s);
  }
  const char* name() const override { return "faulting"; }
  bool activate(double t, std::string* why) override { return sim_.activate(t, why); }
  void safe_stop() noexcept override { sim_.safe_stop(); }

 private:
  sim_backend::SimBackend sim_;
  long fault_at_;
  long advances_ = 0;
};

// Reports kStopping for `stop_cycles` cycles after a stop request, then kStopped.
class StoppingTask final : public control::CycleTask {
 public:
  explicit StoppingTask(long stop_cycles) : stop_cycles_(stop_cycles) {}
  void start(const valves::MachineState&, double) override { ++starts; }
  control::CycleStatus step(const control::CycleTime& time, const valves::MachineState&,
                            const char* stop_cause, valves::ValveCommand&,
                            control::LogRow& row) noexcept override {
    row.t = time.t_s;
    k_ = time.k;
    if (stop_cause == nullptr) {
      return idle_from >= 0 && time.k >= idle_from ? control::CycleStatus::kStopped
                                                   : control::CycleStatus::kRunning;
    }
    cause = stop_cause;
    if (stop_seen_at < 0) stop_seen_at = time.k;
    return time.k - stop_seen_at >= stop_cycles_ ? control::CycleStatus::kStopped
                                                 : control::CycleStatus::kStopping;
  }
  bool finished() const noexcept override { return finished_from >= 0 && k_ >= finished_from; }
  int starts = 0;
  long idle_from = -1;      // from this cycle on at rest without a stop request (a stale input)
  long finished_from = -1;  // from this cycle on the task's work is done (finished())
  long stop_seen_at = -1;
  std::string cause;

 private:
  long stop_cycles_;
  long k_ = -1;
};

class Recorder final : public control::CycleObserver {
 public:
  void on_cycle(const control::CycleRecord& c) noexcept override {
    ks.push_back(c.time.k);
    ts.push_back(c.row.t);
  }
  void on_finish(const control::CycleTime& last, const valves::MachineState&) override {
    ++finishes;
    last_k = last.k;
  }
  std::vector<long> ks;
  std::vector<double> ts;
  int finishes = 0;
  long last_k = -1;
};

// Sets the stop flag at cycle `at`.
class StopAt final : public control::CycleObserver {
 public:
  StopAt(std::atomic<bool>& flag, long at) : flag_(flag), at_(at) {}
  void on_cycle(const control::CycleRecord& c) noexcept override {
    if (c.time.k == at_) flag_.store(true);
  }

 private:
  std::atomic<bool>& flag_;
  long at_;
};

// The loop's options for a run of at most max_cycles cycles, the rest their defaults.
control::LoopOptions run_of(long max_cycles) {
  control::LoopOptions options;
  options.max_cycles = max_cycles;
  return options;
}

// With a task that never comes to rest, the loop gives the stop 0.5 s: then it safe-stops the
// machine, once, and the run has `cycles` cycles.
void expect_safe_stop_after_half_a_second(control::LoopOptions options, long cycles) {
  CountingMachine machine;
  StoppingTask never(100000);
  options.stop_settle_max_s = 0.5;
  const auto s = control::run_control_loop(never, machine, options);
  EXPECT_TRUE(s.safe_stopped);
  EXPECT_EQ(machine.safe_stops, 1);
  EXPECT_EQ(s.cycles, cycles);
}

}  // namespace

TEST(ControlLoop, RunsEveryCycleOnMachineTimeAndTellsEveryObserverInOrder) {
  CountingMachine machine;
  StoppingTask task(0);
  Recorder recorder;
  control::LoopOptions options;
  options.period_s = 0.01;
  options.t0_s = 2.0;
  options.max_cycles = 50;
  options.observers = {&recorder};
  const auto s = control::run_control_loop(task, machine, options);
  EXPECT_EQ(s.cycles, 51) << "50, then the end of the run's stop (at rest at once)";
  EXPECT_DOUBLE_EQ(s.duration_s, 0.51);
  EXPECT_FALSE(s.stop_requested);
  EXPECT_TRUE(s.end_stop);
  EXPECT_EQ(s.stop_cycles, 1);
  EXPECT_EQ(task.cause, "end of run");
  EXPECT_EQ(task.starts, 1);
  EXPECT_EQ(machine.writes, 51);
  EXPECT_EQ(machine.advances, 51);
  EXPECT_EQ(machine.reads, 53) << "one before the start, one per cycle, one at the end";
  ASSERT_EQ(recorder.ks.size(), 51u);
  for (std::size_t k = 0; k < recorder.ks.size(); ++k) {
    EXPECT_EQ(recorder.ks[k], static_cast<long>(k));
    EXPECT_DOUBLE_EQ(recorder.ts[k], 2.0 + 0.01 * static_cast<double>(k));
  }
  EXPECT_EQ(recorder.finishes, 1);
  EXPECT_EQ(recorder.last_k, 50);
  EXPECT_EQ(machine.safe_stops, 0);
}

// The end of a run is a stop like any other: the task brings the machine to rest (the
// controller: jerk-limited, then neutral valves) before the run ends; too slow, safe_stop().
TEST(ControlLoop, TheEndOfARunStopsTheMachineBeforeItEnds) {
  CountingMachine machine;
  StoppingTask task(30);  // 0.3 s to come to rest
  const auto s = control::run_control_loop(task, machine, run_of(100));
  EXPECT_TRUE(s.end_stop);
  EXPECT_FALSE(s.stop_requested);
  EXPECT_EQ(task.cause, "end of run");
  EXPECT_EQ(task.stop_seen_at, 100);
  EXPECT_EQ(s.cycles, 131) << "cycles 100..130 stopping, 130 reports kStopped";
  EXPECT_EQ(s.stop_cycles, 31);
  EXPECT_FALSE(s.safe_stopped);
  expect_safe_stop_after_half_a_second(run_of(100), 151);
}

// A run whose machine is already stopped (e.g. by a stale input) just ends; a study segment
// (stop_at_end false) ends where it is.
TEST(ControlLoop, ARunAlreadyStoppedOrASegmentEndsAtItsLength) {
  CountingMachine machine;
  StoppingTask task(30);
  task.idle_from = 5;
  const auto stopped = control::run_control_loop(task, machine, run_of(20));
  EXPECT_EQ(stopped.cycles, 20);
  EXPECT_FALSE(stopped.end_stop);
  EXPECT_EQ(task.stop_seen_at, -1);

  StoppingTask segment(30);
  control::LoopOptions segment_options;
  segment_options.max_cycles = 20;
  segment_options.stop_at_end = false;
  const auto s = control::run_control_loop(segment, machine, segment_options);
  EXPECT_EQ(s.cycles, 20);
  EXPECT_FALSE(s.end_stop);
  EXPECT_EQ(segment.stop_seen_at, -1);
}

// A task that finishes its work (a calibration sweep on a machine) ends the run there, before
// max_cycles: at once when it is at rest, else through the end-of-run stop.
TEST(ControlLoop, ATaskThatHasFinishedEndsTheRun) {
  CountingMachine machine;
  StoppingTask at_rest(30);
  at_rest.idle_from = 10;
  at_rest.finished_from = 10;
  const auto s = control::run_control_loop(at_rest, machine, run_of(1000));
  EXPECT_EQ(s.cycles, 11) << "cycle 10 reports kStopped and finished; the run ends after it";
  EXPECT_FALSE(s.end_stop);
  EXPECT_EQ(at_rest.stop_seen_at, -1);

  StoppingTask moving(30);
  moving.finished_from = 10;
  const auto m = control::run_control_loop(moving, machine, run_of(1000));
  EXPECT_TRUE(m.end_stop);
  EXPECT_EQ(moving.cause, "end of run");
  EXPECT_EQ(moving.stop_seen_at, 11);
  EXPECT_EQ(m.cycles, 42) << "cycles 11..41 stopping, 41 reports kStopped";
}

// A run length computed from outside numbers never converts out of range.
TEST(ControlLoop, ARunLengthOutOfRangeIsAnErrorNotUndefinedBehaviour) {
  EXPECT_EQ(control::run_cycles(1500.0, "x"), 1500);
  EXPECT_EQ(control::run_cycles(0.0, "x"), 0);
  EXPECT_THROW(control::run_cycles(1e30, "the replay"), std::invalid_argument);
  EXPECT_THROW(control::run_cycles(std::nan(""), "the replay"), std::invalid_argument);
  EXPECT_THROW(control::run_cycles(-1.0, "the replay"), std::invalid_argument);
  EXPECT_THROW(control::run_cycles(std::numeric_limits<double>::infinity(), "x"),
               std::invalid_argument);
  const auto cfg = config::default_crane_config();
  const auto replay = input::Replay::parse("t,v_x,v_y,v_z\n0,0,0,0\n1,0,0,0\n", "short.csv");
  sim_backend::SimBackend sim(cfg.model, offline::sim_settings(cfg));
  control::RunOptions options;
  options.settle_s = std::nan("");
  EXPECT_THROW(control::run_replay(cfg, replay, sim, options, nullptr), std::invalid_argument);
  options.settle_s = 1e300;
  EXPECT_THROW(control::run_replay(cfg, replay, sim, options, nullptr), std::invalid_argument);
}

TEST(ControlLoop, AStopRequestEndsTheRunOnlyOnceTheTaskIsAtRest) {
  CountingMachine machine;
  StoppingTask task(30);  // 0.3 s to come to rest
  std::atomic<bool> stop{false};
  StopAt stopper(stop, 9);
  control::LoopOptions options;
  options.max_cycles = 1000;
  options.stop = &stop;
  options.stop_cause = "operator quit";
  options.observers = {&stopper};
  const auto s = control::run_control_loop(task, machine, options);
  EXPECT_TRUE(s.stop_requested);
  EXPECT_EQ(task.cause, "operator quit");
  EXPECT_EQ(task.stop_seen_at, 10) << "the flag set in cycle 9 is read at the start of cycle 10";
  EXPECT_EQ(s.cycles, 41) << "cycles 10..40 stopping, 40 reports kStopped";
  EXPECT_FALSE(s.safe_stopped);
  EXPECT_EQ(machine.safe_stops, 0);
}

TEST(ControlLoop, AStopThatTakesTooLongSafeStopsTheMachine) {
  std::atomic<bool> stop{true};
  control::LoopOptions options = run_of(100000);
  options.stop = &stop;
  expect_safe_stop_after_half_a_second(options, 51);
}

TEST(ControlLoop, AMachineFaultIsAStopRequestWithItsReason) {
  CountingMachine machine(20);
  StoppingTask task(5);
  const auto s = control::run_control_loop(task, machine, run_of(1000));
  EXPECT_TRUE(s.machine_fault);
  EXPECT_TRUE(s.stop_requested);
  EXPECT_EQ(task.cause, "machine fault");
  EXPECT_EQ(s.cycles, 26);
}

// A replay on a machine that faults stops as a live run does: the controller's stop, then the
// end of the run (the replay used to run on to its end, ignoring the fault).
TEST(ControlLoop, AReplayStopsOnAMachineFaultAsALiveRunDoes) {
  const auto cfg = config::default_crane_config();
  const auto replay = input::Replay::parse("t,v_x,v_y,v_z\n0,0.4,0,0\n10,0.4,0,0\n", "fault.csv");
  FaultingSim machine(cfg, 150);
  control::RunOptions options;
  const auto s = control::run_replay(cfg, replay, machine, options, nullptr);
  EXPECT_TRUE(s.machine_fault);
  EXPECT_GT(s.cycles, 150);
  EXPECT_LT(s.cycles, 400) << "the 11 s replay ended soon after the fault";
  EXPECT_GT(s.neutral_valve_cycles, 0);
}

TEST(MachineLifecycle, ASafeStoppedSimulatorHoldsItsValvesNeutralUntilActivated) {
  const auto cfg = config::default_crane_config();
  sim_backend::SimBackend sim(cfg.model, offline::sim_settings(cfg));
  valves::ValveCommand open;
  open.spool = dynamics::JointVector::Constant(cfg.model.dof(), 0.0);
  open.spool[0] = 0.8;  // slew
  valves::MachineState state;
  const auto run = [&](int cycles) {
    for (int k = 0; k < cycles; ++k) {
      sim.write(open);
      sim.advance(0.01);
    }
    sim.read(state);
    return std::abs(state.qdot[0]);
  };
  EXPECT_GT(run(100), 0.05) << "active from the start: the slew moves";
  sim.safe_stop();
  EXPECT_LT(run(150), 1e-3) << "safe-stopped: written commands are ignored";
  std::string why;
  ASSERT_TRUE(sim.activate(0.0, &why));
  EXPECT_GT(run(100), 0.05) << "activated again";
}

TEST(CycleTiming, HistogramQuantilesAndExtremes) {
  control::DurationHistogram h;
  for (int i = 1; i <= 100; ++i) h.add(i * 1e-6 * 10.0);  // 10 us .. 1 ms
  h.add(0.5);                                             // beyond the last bin
  EXPECT_EQ(h.count(), 101);
  EXPECT_DOUBLE_EQ(h.min_s(), 10e-6);
  EXPECT_DOUBLE_EQ(h.max_s(), 0.5);
  // The upper edge of the 10 us bin that holds the quantile.
  EXPECT_NEAR(h.quantile_s(0.5), 0.52e-3, 1e-9);
  EXPECT_NEAR(h.quantile_s(0.99), 1.01e-3, 1e-9);
  EXPECT_DOUBLE_EQ(h.quantile_s(1.0), 0.5);
  h.add(std::nan(""));  // counted as 0, never a crash
  EXPECT_DOUBLE_EQ(h.min_s(), 0.0);
}

TEST(CycleTiming, APacedLoopMeasuresItsStartLatencyAndComputeTime) {
  CountingMachine machine;
  StoppingTask task(0);
  control::LoopOptions options;
  options.period_s = 0.002;
  options.max_cycles = 50;
  options.realtime = true;
  const auto s = control::run_control_loop(task, machine, options);
  EXPECT_EQ(s.timing.start_latency.count(), 51) << "50 and the end's stop";
  EXPECT_EQ(s.timing.compute.count(), 51);
  EXPECT_GE(s.timing.start_latency.min_s(), 0.0);
  EXPECT_DOUBLE_EQ(s.max_late_s(), s.timing.start_latency.max_s());
  EXPECT_GE(s.wall_time_s, 49 * 0.002) << "paced: 50 cycles take at least 49 periods";
  EXPECT_NE(control::describe(s.timing).find("overruns in 51 cycles"), std::string::npos);
}

// The system may refuse SCHED_FIFO or the memory lock (a container, no CAP_SYS_NICE): the loop
// runs anyway and says why; whatever was granted is undone at the end.
TEST(CycleTiming, RealTimeSetUpIsGrantedOrRefusedWithAReason) {
  CountingMachine machine;
  StoppingTask task(0);
  control::LoopOptions options;
  options.max_cycles = 5;
  options.realtime_setup.lock_memory = true;
  options.realtime_setup.priority = 80;
  options.realtime_setup.cpu = 0;
  const auto s = control::run_control_loop(task, machine, options);
  EXPECT_EQ(s.cycles, 6) << "5 and the end of the run's stop";
  const auto& r = s.realtime_result;
  if (!r.memory_locked) {
    EXPECT_NE(r.refused.find("memory lock refused"), std::string::npos);
  }
  if (r.priority == 0) {
    EXPECT_NE(r.refused.find("SCHED_FIFO priority 80 refused"), std::string::npos);
  }
  if (r.cpu < 0) {
    EXPECT_NE(r.refused.find("core 0"), std::string::npos);
  }
  EXPECT_EQ(r.refused.empty(), r.memory_locked && r.priority == 80 && r.cpu == 0);
  int policy = -1;
  sched_param param{};
  pthread_getschedparam(pthread_self(), &policy, &param);
  EXPECT_EQ(policy, SCHED_OTHER) << "the priority is given back after the run";
}

namespace {

// Keeps every log row of the run.
class RowProbe final : public control::CycleObserver {
 public:
  void on_cycle(const control::CycleRecord& c) noexcept override { rows.push_back(c.row); }
  std::vector<control::LogRow> rows;
};

}  // namespace

// A replay that ends with the crane moving (no settle time): the run does not just stop, the
// crane decelerates jerk-limited to rest, then every valve is neutral (issue: the valves used to
// go from flow to blocked in one frame with the load moving).
TEST(ControlLoop, AReplayEndingInMotionDeceleratesJerkLimitedThenNeutral) {
  const auto cfg = config::default_crane_config();
  const auto replay =
      input::Replay::parse("t,v_x,v_y,v_z\n0,0.6,0,0.2\n3,0.6,0,0.2\n", "ends_moving.csv");
  sim_backend::SimBackend sim(cfg.model, offline::sim_settings(cfg));
  RowProbe probe;
  control::RunOptions options;
  options.settle_s = 0.0;
  options.observers = {&probe};
  const auto s = control::run_replay(cfg, replay, sim, options, nullptr);
  EXPECT_TRUE(s.end_stop);
  EXPECT_GT(s.stop_cycles, 20) << "a real deceleration, not one frame";
  ASSERT_FALSE(probe.rows.empty());
  const std::size_t end = probe.rows.size() - static_cast<std::size_t>(s.stop_cycles);
  const control::LogRow& before = probe.rows[end - 1];
  EXPECT_STREQ(before.status, "running");
  EXPECT_GT(std::hypot(before.tip_v[0], before.tip_v[2]), 0.3) << "moving when the replay ends";
  for (std::size_t i = end; i < probe.rows.size(); ++i) {
    const control::LogRow& r = probe.rows[i];
    EXPECT_STREQ(r.stop_reason, "end of run");
    EXPECT_LE(std::abs(r.sdddot), cfg.scaling.jerk_max_m_s3 * 1.001) << "t " << r.t;
  }
  const control::LogRow& last = probe.rows.back();
  EXPECT_STREQ(last.status, "stopped");
  for (int j = 0; j < cfg.model.dof(); ++j) EXPECT_EQ(last.spool[j], 0.0) << "joint " << j;
  EXPECT_LT(std::hypot(last.ref_v[0], last.ref_v[1], last.ref_v[2]), 1e-9);
  EXPECT_FALSE(s.machine_fault);
}
