// The crane as a robot description (URDF) for RViz, Foxglove and other ROS tools
// (`craneassist urdf`, docs/ros.md).
//
// One link per joint, in the order of the DH chain: base_link is DH frame 0; the joint named as
// in the config moves link "<name>_link" about (or along) its z axis; the fixed part of each DH
// transform (theta/d offset, a, alpha) is the origin of the next joint, and of the fixed joint
// to "tip_link" at the boom tip. So the URDF's forward kinematics equal the model's at every q.
// Inertials come from the model's bodies (several on one frame are combined about their common
// centre of mass); visuals are boxes along each link and a cylinder for the pillar.
#pragma once

#include <string>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

// The URDF text (XML). Joint limits: the config's ranges; velocity: the cylinder's speed limit
// over its arm at mid-range; effort: the cylinder's piston area at the pump's pressure ceiling
// times that arm (approximate: the arm varies along the range).
std::string to_urdf(const CraneModel& model, const std::string& robot_name = "craneassist_crane");

}  // namespace craneassist::dynamics
