#include "craneassist/scaling/base_drive.hpp"

#include <algorithm>
#include <cmath>

namespace craneassist::scaling {

const char* to_string(BaseLimit limit) {
  switch (limit) {
    case BaseLimit::kFlow:
      return "flow";
    case BaseLimit::kMotorSpeed:
      return "motor_speed";
    case BaseLimit::kTrackingError:
      return "tracking_error";
    case BaseLimit::kEnd:
      return "end";
  }
  return "?";
}

void flow_bounded_drive(const dynamics::MobileBaseModel& model, double speed_fraction,
                        double curvature_fraction, double flow_budget_m3_s,
                        BaseDriveOutput& out) noexcept {
  out = BaseDriveOutput{};
  if (!std::isfinite(speed_fraction) || !std::isfinite(curvature_fraction) ||
      !std::isfinite(flow_budget_m3_s)) {
    return;
  }
  out.curvature_1_m =
      std::clamp(curvature_fraction, -1.0, 1.0) * dynamics::max_curvature_1_m(model);
  out.v_max_m_s =
      std::max(0.0, flow_budget_m3_s) / dynamics::flow_per_speed_m2(model, out.curvature_1_m);
  if (model.motor_speed_max_rad_s > 0.0) {
    const double v_motor =
        model.motor_speed_max_rad_s / dynamics::motor_speed_per_speed_1_m(model, out.curvature_1_m);
    if (v_motor < out.v_max_m_s) {
      out.v_max_m_s = v_motor;
      out.limit = BaseLimit::kMotorSpeed;
    }
  }
  out.v_m_s = std::clamp(speed_fraction, -1.0, 1.0) * out.v_max_m_s;
  out.omega_rad_s = out.curvature_1_m * out.v_m_s;
}

}  // namespace craneassist::scaling
