// The crane as a robot description (URDF) for RViz, Foxglove and other ROS tools
// (`craneassist urdf`, docs/ros.md).
//
// One link per joint, in the order of the DH chain: base_link is DH frame 0; the joint named as
// in the config moves link "<name>_link" about (or along) its z axis; the fixed part of each DH
// transform (theta/d offset, a, alpha) is the origin of the next joint, and of the fixed joint
// to "tip_link" at the boom tip. So the URDF's forward kinematics equal the model's at every q.
// Inertials come from the model's bodies (several on one frame are combined about their common
// centre of mass); visuals are boxes along each link and a cylinder for the pillar.
//
// A model whose grapple hangs (model.grapple, docs/sway.md) gets the two-axis link at the tip as
// two revolute joints: "hanger_across" turns "hanger_link" about the axis across the boom plane
// (fixed to the boom, as in the simulator), "hanger_along" turns "grapple_link" about the axis
// across the first, fixed to the grapple. grapple_link carries the grapple, rotator and payload
// (their inertial, and a visual of the hanger and the grapple); tip_link keeps the tip point.
// hanger_joint_angles() gives the joints' angles for a swing, so that a JointState with them
// draws the grapple where the simulator (or a machine's swing sensor) has it.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

// The URDF names of the hanger's joints, in the order of hanger_joint_angles().
inline constexpr std::array<const char*, 2> kHangerJointNames = {"hanger_across", "hanger_along"};

// The hanger's axes in the tip frame (the last DH frame): `across` (the first joint's axis, the
// lift joint's axis, fixed to the boom), `hang` (where the grapple hangs at zero angles: down,
// at the model's mid-range pose, square to `across`) and `along` = across x hang (the second
// joint's axis at zero angles). Constant in every pose for a crane whose boom joints after the
// slew all turn about the lift's axis (a boom in one plane: every crane config here); for
// another crane they are those of the mid-range pose. Meaningful only when the grapple hangs.
struct HangerAxes {
  Eigen::Vector3d across = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d hang = Eigen::Vector3d::UnitX();
  Eigen::Vector3d along = Eigen::Vector3d::UnitY();
};
HangerAxes hanger_axes(const CraneModel& model);

// The angles of hanger_across and hanger_along (rad) that hang the grapple at the swing
// radial_rad, tangential_rad (MachineState::swing_*: towards the reach and across it) from the
// tip frame `tip` (the last DH frame in the base frame, forward_kinematics): the URDF's
// grapple_link then hangs where dynamics::grapple_position() puts the grapple. A non-finite
// swing (nothing measures it) hangs it straight down. No allocation.
std::array<double, 2> hanger_joint_angles(const CraneModel& model, const HangerAxes& axes,
                                          const Eigen::Isometry3d& tip, double radial_rad,
                                          double tangential_rad) noexcept;

// The URDF's joints as a transform tree (what robot_state_publisher would put on /tf, so that a
// viewer without it, Foxglove's 3-D panel, moves the URDF): each joint's parent and child link,
// in to_urdf()'s order (the crane's joints, "tip", then the hanger's two when the grapple hangs).
struct UrdfFrame {
  std::string parent, child;
};
std::vector<UrdfFrame> urdf_frames(const CraneModel& model);

// The parent-to-child transform of each of urdf_frames() at the joint positions q[0..dof) and
// the hanger angles (hanger_joint_angles(); axes: hanger_axes(model)), into
// out[0..urdf_frames().size()). No allocation.
void urdf_transforms(const CraneModel& model, const HangerAxes& axes, const double* q,
                     const std::array<double, 2>& hanger, Eigen::Isometry3d* out) noexcept;

// The URDF text (XML). Joint limits: the config's ranges; velocity: the cylinder's speed limit
// over its arm at mid-range; effort: the cylinder's piston area at the pump's pressure ceiling
// times that arm (approximate: the arm varies along the range).
std::string to_urdf(const CraneModel& model, const std::string& robot_name = "craneassist_crane");

}  // namespace craneassist::dynamics
