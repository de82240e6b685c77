// Mobile base configs (config::parse_base_config, config/machines/*.yaml, docs/mobile.md): any
// bytes are rejected with a ConfigError naming the source, or give a base whose model the
// kinematics, the flow bound and the operator's drive can use: the tightest turn, the wheels of
// a motion, and a drive command whose motor flows stay within the drive pump.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "craneassist/config/base_config.hpp"
#include "craneassist/config/config_error.hpp"
#include "craneassist/dynamics/mobile_base.hpp"
#include "craneassist/scaling/base_drive.hpp"
#include "fuzz_check.hpp"

using craneassist::config::ConfigError;
namespace dynamics = craneassist::dynamics;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  craneassist::config::BaseConfig cfg;
  try {
    cfg = craneassist::config::parse_base_config(text, "fuzz.yaml");
  } catch (const ConfigError& e) {
    FUZZ_CHECK(e.file() == "fuzz.yaml", "the error names the file");
    FUZZ_CHECK(e.line() >= 0, "a line number");
    return 0;
  }
  FUZZ_CHECK(cfg.source_name == "fuzz.yaml", "the config names its source");
  const dynamics::MobileBaseModel& m = cfg.model;
  const double kappa_max = dynamics::max_curvature_1_m(m);
  FUZZ_CHECK(std::isfinite(kappa_max) && kappa_max > 0.0, "a finite tightest turn");
  FUZZ_CHECK(std::isfinite(dynamics::min_outer_turning_radius_m(m)), "a finite turning radius");
  for (double fraction : {0.0, 0.5, 1.0}) {
    const double f = dynamics::flow_per_speed_m2(m, fraction * kappa_max);
    FUZZ_CHECK(std::isfinite(f) && f > 0.0, "a finite flow per unit speed");
  }
  // The operator's drive at full stick, straight and at the tightest turn, both ways.
  for (double curvature : {0.0, 1.0, -1.0}) {
    for (double speed : {1.0, -1.0}) {
      craneassist::scaling::BaseDriveOutput out;
      craneassist::scaling::flow_bounded_drive(m, speed, curvature, m.pump_max_flow_m3_s, out);
      FUZZ_CHECK(std::isfinite(out.v_m_s) && std::isfinite(out.omega_rad_s), "a finite command");
      dynamics::WheelState wheels;
      dynamics::wheel_inverse_kinematics(m, out.omega_rad_s, out.v_m_s, wheels);
      FUZZ_CHECK(std::isfinite(wheels.flow_sum_m3_s), "finite motor flows");
      FUZZ_CHECK(wheels.flow_sum_m3_s <= m.pump_max_flow_m3_s * (1.0 + 1e-6),
                 "the motors within the drive pump");
    }
  }
  return 0;
}
