// Point-to-point planning with posture and mode, S2-S4 of paper 001 (sections 2.2-2.3;
// docs/mhsb.md#the-planner): A* over the workspace grid of the optimal posture table
// (posture_table.hpp), a sixth-degree polynomial time trajectory through the path, and the modes
// retimed from that trajectory's required forces.
//
// S2. A state is (node, mode pattern); its posture is the table's. From (n, p) the arm may go to
// any of the 8 neighbours n' in any pattern p' whose modes the transition allows: with the
// postures q = T(n, p), q' = T(n', p'), each cylinder travels dc_j = c_j(q') - c_j(q) at a constant
// speed (paper assumption 2), every joint no faster than the velocity limit V_L and, in DB/SB, the
// servo-pumps' flow over its area (8.2/10.7 mm/s extending/retracting in DB for the paper's arm),
// the main pump's flow on the sum:
//     t_node = max( max_j |dc_j| / vcap_j(mode_j, sign dc_j),  sum_j A_j |dc_j| / Q_MP ).
// v_j = dc_j / t_node. Joint j needs a boost when its cylinder force F_j (the load held at q or at
// q', static_gravity.hpp) is a positive load at v_j needing more than P0 from its open valve
// (mhsb::needs_boost; a joint at rest: when it cannot hold F_j from P0); then its mode must be
// DB or SB, else N (mhsb::mode_allowed), and a boost mode must reach the pressure. A pattern
// p' that breaks the rule for a joint is not a successor. Costs of the transition:
//     E = t_node * sum_j (P_j(F at q) + P_j(F at q')) / 2     (J)
// with P_j = mhsb::mhsb_actuator_power_w (series or the paper's eq. 9; valve leakage included)
// on the MHSB circuit, or on a crane without it the load-sensing pump's (highest load pressure of a
// cylinder doing positive work + margin) times the flow (a constant-pressure pump: p_s times it);
//     t = t_node (s),   G = joints whose mode differs between p and p'.
// The path cost is w1 sum E + w2 sum t + w3 sum G; the graph's costs do not depend on the query,
// so they are computed once (PtpPlanner's constructor) and a query only searches.
//
// The heuristic H = k |x - x_goal| (m). The default k is a lower bound of the cost per metre of
// tip travel, so H is admissible and consistent and A* returns the optimal path (equal to
// Dijkstra's, a test): every transition takes at least |dx| / V_tip (V_tip an upper bound of the
// tip speed with every cylinder at its speed limit, PlanarArm::tip_speed_bound) and draws at least
// the valves' leakage at P0 (MHSB; 0 otherwise), so k = (w2 + w1 P_min) / V_tip. With all weights
// 0, k = 1 (the path is then the greedy one, the paper's "heuristic only" case); a k given by the
// caller (the paper's unscaled metres, say) may lose optimality when it exceeds the bound.
//
// S3 and S4: see PtpPlanner::plan.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "craneassist/mhsb/mhsb.hpp"
#include "craneassist/planner/planar_arm.hpp"
#include "craneassist/planner/posture_table.hpp"

namespace craneassist::planner {

// How a transition's energy is counted.
enum class PtpEnergy {
  kMhsbSeries,        // MHSB, mhsb::MhsbEnergyModel::kSeries
  kMhsbPaper,         // MHSB, paper 001 eq. 9 as printed
  kLoadSensing,       // LS pump: (max load pressure + margin) Q
  kConstantPressure,  // p_s Q
};
const char* to_string(PtpEnergy energy);

struct PtpSettings {
  // V_L, m/s: 0 takes the circuit's (hydraulics.mhsb.velocity_limit) or, without it, each
  // cylinder's max_speed.
  double velocity_limit_m_s = 0.0;
  // The MHSB energy model (ignored without the circuit, whose pump mode decides).
  mhsb::MhsbEnergyModel energy_model = mhsb::MhsbEnergyModel::kSeries;
  double sample_period_s = 0.02;  // of the S3 time trajectory
  // S3 keeps every cylinder's speed within this share of V_L (and within its max_speed),
  // lengthening segments where the polynomial would exceed it: 1.5 keeps the paper's arm under its
  // 20 mm/s quasi-static speed (12 mm/s V_L).
  double max_speed_ratio = 1.5;
};

struct PtpWeights {
  double energy = 0.0;                    // w1, per J
  double time = 0.0;                      // w2, per s
  double switches = 0.0;                  // w3, per switched joint
  std::optional<double> heuristic_per_m;  // k; default: the admissible bound (see above)
};

enum class PtpSearch { kAStar, kDijkstra };

// One node of an S2 path and what it took to get there.
struct PtpStep {
  int node = 0;
  int pattern = 0;        // index into PostureTable::patterns()
  ArmVector q;            // the table's posture
  double t_s = 0.0;       // arrival, from the start
  double energy_j = 0.0;  // spent up to here
};

struct PtpPath {
  bool found = false;
  std::vector<PtpStep> steps;  // start first
  double cost = 0.0;           // w1 E + w2 t + w3 G
  double energy_j = 0.0, time_s = 0.0, length_m = 0.0;
  int switches = 0;
  int expanded = 0;  // states taken off the queue
};

// The S3/S4 time trajectory: samples of the moving joints.
struct PtpSample {
  double t_s = 0.0;
  ArmVector q, qdot, qddot;
  std::array<mhsb::MhsbMode, dynamics::kMaxJoints> mode{};  // per moving joint (S4)
};

struct PtpPlan {
  PtpPath path;                      // S2
  std::vector<PtpSample> samples;    // S3 + S4
  std::vector<double> node_times_s;  // when the trajectory passes each S2 node
  double energy_j = 0.0;             // along the samples, with the S4 modes
  double time_s = 0.0;
  double length_m = 0.0;                         // tip path length of the samples
  int switches = 0;                              // S4 mode changes, all joints
  double peak_speed_ratio = 0.0;                 // largest cylinder speed / V_L along the samples
  double start_snap_m = 0.0, goal_snap_m = 0.0;  // from the points asked to their nodes
  double planning_time_s = 0.0;                  // S2-S4 of this query
};

class PtpPlanner {
 public:
  // Builds the transition graph (allocates; about 0.1 s for the paper's arm). arm and table must
  // outlive the planner.
  PtpPlanner(const PlanarArm& arm, const PostureTable& table, const PtpSettings& settings);

  const PlanarArm& arm() const { return *arm_; }
  const PostureTable& table() const { return *table_; }
  PtpEnergy energy() const { return energy_; }
  // The velocity limit of moving joint k's cylinder, m/s.
  double velocity_limit_m_s(int k) const { return v_limit_[static_cast<std::size_t>(k)]; }
  long transitions() const { return static_cast<long>(edges_.size()); }
  // k of the heuristic for these weights (see the header comment).
  double heuristic_per_m(const PtpWeights& weights) const;

  // The node nearest a point within the grid's half diagonal, or -1 (outside the workspace).
  int node_near(const Eigen::Vector2d& xz) const;

  // S2 from the start node in all-N to the goal node (any pattern). Reuses the planner's buffers:
  // one query at a time per planner.
  PtpPath search(int start_node, int goal_node, const PtpWeights& weights,
                 PtpSearch kind = PtpSearch::kAStar);

  // S2-S4 from one tip point to another (X, Z in the arm's plane), each snapped to its nearest
  // node; q_start (moving joints), when given, replaces the start node's table posture (a live
  // loop replanning from where the arm is). Path not found: plan.path.found false, no samples.
  // Throws std::invalid_argument for a point outside the workspace.
  PtpPlan plan(const Eigen::Vector2d& from, const Eigen::Vector2d& to, const PtpWeights& weights,
               const std::optional<ArmVector>& q_start = std::nullopt);

  // The power (W) the moving joints draw at posture a with joint rates qdot in these modes (the
  // S4 accounting; modes per moving joint).
  double power_w(const ArmVector& a, const ArmVector& qdot,
                 const std::array<mhsb::MhsbMode, dynamics::kMaxJoints>& modes);

 private:
  struct Edge {
    int to;  // state
    int switches;
    double time_s, energy_j;
  };
  struct EntryStatics {
    ArmVector length_m, force_n;
  };
  std::optional<Edge> transition(int from_state, int to_state) const;
  double stage_power_w(const EntryStatics& at, const ArmVector& v,
                       const mhsb::ModePattern& modes) const;

  const PlanarArm* arm_;
  const PostureTable* table_;
  PtpSettings settings_;
  PtpEnergy energy_;
  std::vector<double> v_limit_;  // per moving joint
  double tip_speed_bound_ = 0.0;
  double min_power_w_ = 0.0;
  std::vector<EntryStatics> statics_;  // per state (node * patterns + pattern)
  std::vector<int> first_edge_;        // CSR: per state
  std::vector<Edge> edges_;
  // Search buffers.
  std::vector<double> g_;
  std::vector<int> parent_;
  std::vector<std::uint8_t> closed_;
  std::vector<std::pair<double, int>> heap_;
  dynamics::KinematicsData data_;
};

}  // namespace craneassist::planner
