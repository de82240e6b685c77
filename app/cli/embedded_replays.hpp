#pragma once

namespace craneassist::cli::embedded {

// examples/replays/demo.csv, the default replay of `craneassist replay`.
extern const char* const kDemoReplayCsv;
// config/can/k70m_can.yaml, the default CAN mapping of `replay --backend can` and `emulate`.
extern const char* const kK70mCanMappingYaml;
// tools/plot_polytope.py, which `craneassist research polytope --plot` runs with python3.
extern const char* const kPlotPolytopePy;

}  // namespace craneassist::cli::embedded
