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
#include "craneassist/dynamics/mobile_base.hpp"

namespace craneassist::web {

// The crane's name, joints, cylinders and the limits the gauges are drawn against.
std::string crane_json(const config::CraneConfig& crane, double frame_rate_hz);

class SceneBuilder {
 public:
  // base: the wheeled base the crane stands on (nullptr: a fixed base; kept by reference).
  explicit SceneBuilder(const dynamics::CraneModel& model,
                        const dynamics::MobileBaseModel* base = nullptr);
  // One cycle as a "frame" message; out is cleared first (its capacity is kept).
  void frame_json(const control::LogRow& row, std::uint64_t seq, std::string& out);

 private:
  // The frame's "base" member (sim --drive): the pose, motion and flows, the crane's root (its
  // frame in the view's) and the chassis and wheels as placed boxes.
  void base_json(const control::LogRow& row, std::string& out) const;

  const dynamics::CraneModel& model_;
  const dynamics::MobileBaseModel* base_;
  dynamics::KinematicsData data_;
};

}  // namespace craneassist::web
