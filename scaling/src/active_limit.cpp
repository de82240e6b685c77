#include "craneassist/scaling/active_limit.hpp"

namespace craneassist::scaling {

const char* to_string(ActiveLimit limit) {
  switch (limit) {
    case ActiveLimit::kNone:
      return "none";
    case ActiveLimit::kFlow:
      return "flow";
    case ActiveLimit::kCylinderSpeed:
      return "cylinder_speed";
    case ActiveLimit::kPower:
      return "power";
    case ActiveLimit::kTrackingError:
      return "tracking_error";
    case ActiveLimit::kJointLimit:
      return "joint_limit";
    case ActiveLimit::kCylinderAcceleration:
      return "cylinder_acceleration";
    case ActiveLimit::kStaleInput:
      return "stale_input";
    case ActiveLimit::kSingularity:
      return "singularity";
    case ActiveLimit::kPressure:
      return "pressure";
    case ActiveLimit::kOverload:
      return "overload";
    case ActiveLimit::kDynamicsFailed:
      return "dynamics_failed";
    case ActiveLimit::kStopRequest:
      return "stop_request";
  }
  return "?";
}

}  // namespace craneassist::scaling
