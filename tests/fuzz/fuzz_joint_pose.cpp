// Joint poses as the command line (--initial) and suite manifests write them
// (config::parse_joint_pose, "lift=0 deg, tilt=-125 deg, extension=0.2 m"): any bytes are
// rejected with std::invalid_argument, or give a pose of finite values inside the reference
// crane's joint ranges.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string_view>

#include "craneassist/config/crane_config.hpp"
#include "fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const craneassist::config::CraneConfig cfg = craneassist::config::default_crane_config();
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto q = craneassist::config::parse_joint_pose(cfg.model, text, cfg.simulation.q_initial);
    FUZZ_CHECK(q.size() == cfg.model.dof(), "one value per joint");
    for (int i = 0; i < cfg.model.dof(); ++i) {
      const auto& j = cfg.model.joints[static_cast<std::size_t>(i)];
      FUZZ_CHECK(std::isfinite(q[i]), "a finite joint value");
      FUZZ_CHECK(q[i] >= j.q_min && q[i] <= j.q_max, "inside the joint's range");
    }
  } catch (const std::invalid_argument& e) {
    FUZZ_CHECK(*e.what() != '\0', "the error says what is wrong");
  }
  return 0;
}
