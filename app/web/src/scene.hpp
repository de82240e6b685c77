// What the page draws and plots, as JSON: the crane description once (/crane.json) and one
// message per streamed cycle. The crane is sent as points, not as DH parameters, so the page
// needs no kinematics: the joint frame origins and each cylinder's two ends, in the crane frame
// (x forward, y up, z lateral; three.js is y-up too). Runs on the server's I/O thread.
#pragma once

#include <cstdint>
#include <string>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/dynamics/kinematics.hpp"

namespace craneassist::web {

// The crane's name, joints, cylinders and the limits the gauges are drawn against.
std::string crane_json(const config::CraneConfig& crane, double frame_rate_hz);

class SceneBuilder {
 public:
  explicit SceneBuilder(const dynamics::CraneModel& model);
  // One cycle as a "frame" message; out is cleared first (its capacity is kept).
  void frame_json(const control::LogRow& row, std::uint64_t seq, std::string& out);

 private:
  const dynamics::CraneModel& model_;
  dynamics::KinematicsData data_;
};

}  // namespace craneassist::web
