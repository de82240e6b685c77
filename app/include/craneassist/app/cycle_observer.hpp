// Something that watches the live loop cycle by cycle (DDS telemetry, a test probe). The loop
// calls on_cycle() on its own thread once per period after the valves are written; it must
// return at once: no lock, no allocation, no I/O (copy the row into a preallocated ring).
#pragma once

#include "craneassist/app/csv_log.hpp"

namespace craneassist::app {

class CycleObserver {
 public:
  virtual ~CycleObserver() = default;
  virtual void on_cycle(const LogRow& row) noexcept = 0;
};

}  // namespace craneassist::app
