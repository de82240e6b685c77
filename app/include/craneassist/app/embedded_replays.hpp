#pragma once

namespace craneassist::app::embedded {

// examples/replays/demo.csv, the default replay of `craneassist replay`.
extern const char* const kDemoReplayCsv;

}  // namespace craneassist::app::embedded
