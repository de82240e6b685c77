// A replay file as a live CommandSource (`craneassist sim --input replay FILE`, tests): the
// command at the loop's clock since the first cycle, stamped with that clock. The scripted
// operator holds the deadman, releasing it for the first cycle only, so the input monitor arms
// as it would for a person pressing the button after start-up (the command passes once the
// deadman has been held for the monitor's deadman_hold). A stop row (docs/replay-format.md) is
// played as the deadman released with a zero command: the monitor stops the crane (valves
// neutral once at rest) and the next row re-arms it, as a person releasing and pressing again
// (the motion resumes after the monitor's stop_latch and deadman_hold).
#pragma once

#include "craneassist/input/command_source.hpp"
#include "craneassist/input/replay.hpp"

namespace craneassist::input {

class ReplaySource : public CommandSource {
 public:
  // Keeps a reference to the replay: it must outlive the source.
  explicit ReplaySource(const Replay& replay) noexcept : cursor_(replay) {}

  void begin_cycle(double now_s, const Eigen::Vector3d& tip_m) noexcept override;
  SourceState poll(OperatorCommand& out) noexcept override;
  const char* name() const noexcept override { return "replay"; }

 private:
  ReplayCursor cursor_;
  bool started_ = false;
  int cycles_ = 0;
  double start_s_ = 0.0;
  double now_s_ = 0.0;
};

}  // namespace craneassist::input
