// The flow manipulability polytope of a crane at one pose, for `craneassist research polytope`
// (docs/polytope.md): its volume (or a planar arm's area), its vertices, and the admissible tip
// speed along given directions, over every joint motion (the LP) and along the joint motion the
// controller's redundancy resolution chooses (what its flow and cylinder-speed scaling allows).
// The limits are the full scaling's: control.flow_reserve kept back from the pump's flow and
// from each cylinder's speed.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/flow_polytope.hpp"
#include "craneassist/mhsb/mhsb.hpp"

namespace craneassist::studies {

struct PolytopeSpeed {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // unit, crane frame (in a planar arm's
                                                         // plane)
  double best_m_s = 0.0;                                 // over every admissible joint motion (LP)
  double resolved_m_s = 0.0;   // along the controller's resolution of the direction
  double intended_m_s = 0.0;   // the speed the resolution was shaped for
  std::string resolved_limit;  // what bounds resolved_m_s: "pump flow", "lift cylinder speed",
                               // "slew at its end", or "" (the tip cannot move along it)
  dynamics::JointVector best_qdot, resolved_qdot;  // the joint rates at those speeds
};

struct PolytopeReport {
  int task_dim = 3;  // 2: a planar arm, in its plane
  // A planar arm's plane: rows map crane-frame vectors to plane coordinates; axis names.
  std::optional<Eigen::Matrix<double, 2, 3>> plane;
  std::array<std::string, 3> axis_names{"x", "y", "z"};
  int dimension = 0;          // of the polytope (task_dim unless singular)
  double volume_m3_s3 = 0.0;  // task_dim 3
  double area_m2_s2 = 0.0;    // task_dim 2, or a flat 3-D polytope's area in its plane
  int joint_vertices = 0;     // vertices of the joint-velocity set
  // The polytope's vertices in task coordinates (planar: plane coordinates, third 0) and the
  // joint rates that reach each.
  std::vector<Eigen::Vector3d> vertices;
  std::vector<dynamics::JointVector> vertex_qdot;
  std::vector<PolytopeSpeed> speeds;  // one per direction asked
  std::vector<std::string> joints_at_end;
  double max_flow_m3_s = 0.0;  // the pump flow the set allows (less the reserve)
  double flow_reserve = 0.0;
  std::string resolution;  // the controller's resolution, e.g. "min-ls-power"
  // An MHSB arm (hydraulics.mhsb; docs/mhsb.md): the mode pattern of the polytope above, each
  // cylinder's gravity load at the pose (N, positive pushing the rod in), and the polytope's
  // measure (area, or volume for a 3-D task) in every pattern the modules allow, in
  // mode_patterns() order.
  std::optional<mhsb::ModePattern> modes;
  dynamics::JointVector cylinder_force_n;
  std::vector<std::pair<mhsb::ModePattern, double>> pattern_measures;
};

// The polytope of cfg's crane at q. directions: crane-frame vectors (any length but not zero; a
// planar arm uses their part in its plane). intended_speed_m_s: the speed the controller's
// resolution is shaped for (it chooses joint motions that serve that speed); nullopt: the LP's
// speed along each direction (the operator asks for all the machine can give there). modes: an
// MHSB arm's mode pattern (nullopt: all N); ignored without hydraulics.mhsb.
PolytopeReport polytope_report(const config::CraneConfig& cfg, const dynamics::JointVector& q,
                               const std::vector<Eigen::Vector3d>& directions,
                               std::optional<double> intended_speed_m_s,
                               std::optional<mhsb::ModePattern> modes = std::nullopt);

}  // namespace craneassist::studies
