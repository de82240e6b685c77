// When a telemetry topic is due (internal to the dds module): each topic is written at most at
// its rate, by machine time, and once more at the end for the final state.
#pragma once

#include <cstdint>

#include "craneassist/dds/telemetry_frame.hpp"

namespace craneassist::dds {

class TopicPacer {
 public:
  explicit TopicPacer(double rate_hz = 50.0) : period_s_(1.0 / rate_hz) {}

  // Whether to write the frame: its period has passed since the last write (or machine time
  // went back, or nothing was written yet); with `force`, any frame not yet written. Marks the
  // frame written when it returns true.
  bool due(const TelemetryFrame& f, bool force) {
    const bool by_rate = !written_once_ || f.t_s < last_t_ || f.t_s - last_t_ >= period_s_ - 1e-9;
    if (!(by_rate || (force && last_cycle_ != f.cycle))) return false;
    last_t_ = f.t_s;
    last_cycle_ = f.cycle;
    written_once_ = true;
    return true;
  }

 private:
  double period_s_;
  double last_t_ = 0.0;
  std::uint64_t last_cycle_ = 0;
  bool written_once_ = false;
};

}  // namespace craneassist::dds
