// Which limit holds the motion back this cycle (MoveIt Servo's status idea): logged every cycle
// and shown to the operator.
#pragma once

namespace craneassist::scaling {

enum class ActiveLimit {
  kNone,
  kFlow,                  // pump maximum flow
  kCylinderSpeed,         // a cylinder's maximum speed (valve saturation)
  kPower,                 // prime-mover power (load-sensing pump power limit)
  kTrackingError,         // the measured tip lags the reference
  kJointLimit,            // a joint or cylinder end is near
  kStaleInput,            // no valid operator input
  kCylinderAcceleration,  // a cylinder's maximum acceleration (path curvature at speed)
  kSingularity,           // a near-singular pose: the direction needs very fast joints
  kPressure,              // a load pressure at the pump's ceiling (relief; p_s with a CP pump)
  kDynamicsFailed,        // the ODE dynamics step failed (out of memory): stopping without it
  kOverload,              // the rated capacity limiter: the motion would raise the load moment
  kStopRequest,           // the run asks for a stop: its end, the operator's quit, a fault
};
inline constexpr int kActiveLimitCount = static_cast<int>(ActiveLimit::kStopRequest) + 1;

const char* to_string(ActiveLimit limit);

}  // namespace craneassist::scaling
