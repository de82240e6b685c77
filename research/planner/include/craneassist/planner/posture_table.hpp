// S1 of paper 001 (section 2.1, eq. 7; docs/mhsb.md#s1-the-optimal-posture-table): for every node
// of a square grid over the arm's reachable workspace and every mode pattern, the posture with the
// largest flow manipulability polytope (its area in the arm's plane, flow_polytope.hpp) among those
// that put the tip on the node within the joint ranges:
//     max_q S(q)  subject to  tip(q) = node,  q_min <= q <= q_max.
// The polytope of a pattern is that of mhsb_joint_velocity_set (each joint's servo-valve from its
// mode's supply against the cylinder force that holds the load at q, the servo-pumps' flow in
// DB/SB, the main pump's flow on the sum); a crane without the circuit has one pattern, all N, and
// its cylinders' and pump's limits (joint_velocity_set).
//
// The solver is NLopt's SLSQP (sequential least-squares quadratic programming, as the paper's SQP):
// the area's gradient by central differences, the tip constraint's by the Jacobian. Multi-start:
// the joint space is sampled (each joint's range in steps that move the tip by at most half a grid
// spacing); the samples nearest each node, one per slice of the last moving joint's range, are
// pulled onto the node (damped least squares); they are the node's feasible starting postures
// (a node none of them reaches is outside the workspace). Per pattern the polytope is evaluated at
// each, and SLSQP runs from the best few; the best feasible result is kept. Where the pattern's
// polytope has no area at any posture of the node (a joint that cannot hold its load from its
// mode's supply: N where the arm needs a boost to hold), every posture is as good as another; the
// table then keeps the posture of the largest polytope without the load, so that neighbouring
// nodes get neighbouring postures rather than arbitrary ones.
//
// Continuity (optional, continuity_tolerance > 0): a redundant arm often has optima on two
// branches (the paper's arm: its mirror postures, elbow one way or the other), and the best alone
// jumps between branches from node to node. Then each pattern is swept over the nodes row by row
// (from the lowest, each row in increasing X); at a node whose lower or left neighbours are done,
// SLSQP also runs from their postures pulled onto the node, and of the results whose area is
// within continuity_tolerance of the node's best, the one nearest those neighbours' postures is
// kept. The table is then no longer the largest polytope per node, only within the tolerance.
//
// The table is built in parallel over nodes (the continuity sweep over patterns) and kept in a
// binary file whose header holds a fingerprint of everything it depends on (model, held joints,
// grid, settings): a file that does not match is rebuilt (save(), load()).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "craneassist/mhsb/mhsb.hpp"
#include "craneassist/planner/planar_arm.hpp"

namespace craneassist::planner {

// Nodes at (i h, k h) in the arm's plane, i and k integers: the reachable ones numbered 0..N-1.
struct WorkspaceGrid {
  double spacing_m = 0.05;
  int ix0 = 0, iz0 = 0;             // the first cell's indices
  int nx = 0, nz = 0;               // cells
  std::vector<int> node_of_cell;    // nx * nz, cell (i, k) at i + nx k; -1: not reachable
  std::vector<int> node_i, node_k;  // each node's cell
  std::vector<Eigen::Vector2d> node_xz;

  int nodes() const { return static_cast<int>(node_xz.size()); }
  // Node of the cell (ix, iz) (absolute indices), -1 for none.
  int node_at(int ix, int iz) const;
  // The node nearest to xz and within max_distance_m of it, or -1.
  int nearest_node(const Eigen::Vector2d& xz, double max_distance_m) const;
  // The neighbour of a node in direction d (0..7: E, NE, N, NW, W, SW, S, SE), or -1.
  int neighbour(int node, int d) const;
};

// The mode patterns the planner considers, over the moving joints: with the MHSB circuit every
// pattern of its modules (23 for three joints and four modules); without it, all N only.
std::vector<mhsb::ModePattern> planner_patterns(const PlanarArm& arm);
// A pattern over the moving joints as one over all the crane's joints (held joints N).
mhsb::ModePattern full_pattern(const PlanarArm& arm, const mhsb::ModePattern& moving);

// The arm's reach: the DH lengths of the moving joints, extensions at full stroke.
double arm_reach_m(const PlanarArm& arm);
// The default grid spacing: 5 cm (the paper's), or for an arm reaching further than 2 m its
// reach / 40 rounded up to 5 cm (the K70M: 0.2 m).
double default_spacing(const PlanarArm& arm);
// The cells of the square around the arm's reach at this spacing ((2 reach / h)^2): what a table
// of that grid costs at most. Above kMaxGridCells a table would take hours and gigabytes (the
// K70M at 1 cm: 4 million); the commands refuse such a grid.
double grid_cells(const PlanarArm& arm, double spacing_m);
inline constexpr double kMaxGridCells = 1.0e6;

struct PostureTableSettings {
  double spacing_m = 0.0;  // 0: default_spacing()
  int threads = 2;
  int seeds_per_node = 36;  // starting postures per node (slices of the last joint's range)
  int refined_starts = 4;   // SLSQP runs per node and pattern
  // Of the postures whose area is within this fraction of the node's best, the one nearest the
  // neighbours' (the continuity sweep above); 0 (default): the best, paper 001's S1.
  double continuity_tolerance = 0.0;
  // Only nodes inside this box (X, Z min, max; tests); empty: the whole workspace.
  std::optional<Eigen::Vector4d> region;
  int max_patterns = 0;  // the first patterns only (tests); 0: all
};

// The polytope area (m^2/s^2) of a pattern at moving-joint posture a; one per thread.
class PolytopeArea {
 public:
  explicit PolytopeArea(const PlanarArm& arm);
  double operator()(const ArmVector& a, const mhsb::ModePattern& full_pattern);
  // With the cylinder forces taken as 0 (the table's fallback for a pattern whose polytope has no
  // area anywhere at a node).
  void set_ignore_load(bool ignore) { ignore_load_ = ignore; }

 private:
  const PlanarArm* arm_;
  bool ignore_load_ = false;
  dynamics::KinematicsData data_;
  dynamics::FlowPolytope polytope_;
  dynamics::JointVelocitySet full_set_, set_;
};

// The reachable grid and each node's starting postures (already on the node).
struct Workspace {
  WorkspaceGrid grid;
  std::vector<std::vector<ArmVector>> starts;  // per node
};
Workspace sample_workspace(const PlanarArm& arm, const PostureTableSettings& settings);

class PostureTable {
 public:
  int moving() const { return moving_; }
  const WorkspaceGrid& grid() const { return grid_; }
  const std::vector<mhsb::ModePattern>& patterns() const { return patterns_; }
  int pattern_count() const { return static_cast<int>(patterns_.size()); }
  ArmVector posture(int node, int pattern) const;
  double area(int node, int pattern) const { return area_[entry(node, pattern)]; }
  std::uint64_t fingerprint() const { return fingerprint_; }

  // Builds it (progress: called with nodes done and in all, from the building threads, serially).
  static PostureTable build(const PlanarArm& arm, const PostureTableSettings& settings,
                            const std::function<void(int, int)>& progress = {});
  // The conventional posture rule of paper 001's Case 4 (its reference [18]): no S1, the redundancy
  // resolved beforehand by holding the last moving joint at last_joint (rad). At each node of the
  // same grid as build()'s, the other joints come from the inverse kinematics with the last joint
  // there; where no solution lies within the ranges, the last joint is changed by step (rad; the
  // paper: 1 degree) at a time, +step, -step, +2 step, ... from last_joint, until one does. Of
  // the solutions (elbow up or down) the one whose middle joints bend the way the last one does
  // (the arm curled one way, as the optimal table's postures of the paper's arm), then the one
  // nearest the arm's reference posture (q_hold with the last joint at last_joint), is kept. Every
  // pattern gets the node's posture, with its own polytope area. Not cached (it takes about a
  // second). Throws std::invalid_argument when the arm has fewer than two moving joints, its last
  // one is not revolute, or last_joint is outside the joint's range.
  static PostureTable fixed_last_joint(const PlanarArm& arm, const PostureTableSettings& settings,
                                       double last_joint, double step = M_PI / 180.0);
  // Whether the table is the optimal one (build(), load()) or fixed_last_joint()'s.
  bool optimal() const { return optimal_; }
  // fixed_last_joint(): the nodes where the last joint had to leave last_joint.
  long moved_last_joint = 0;

  // Writes the binary file (throws std::runtime_error naming it when it cannot), through a
  // temporary file and a rename.
  void save(const std::filesystem::path& file) const;
  void write(std::ostream& out) const;
  // The table in the file when it exists and matches arm and settings; nullopt otherwise. A file
  // made for another arm or grid, cut short or damaged (a grid, patterns, postures outside the
  // joint ranges, areas that are not finite non-negative numbers) is refused, never trusted.
  static std::optional<PostureTable> load(const std::filesystem::path& file, const PlanarArm& arm,
                                          const PostureTableSettings& settings);
  static std::optional<PostureTable> read(std::istream& in, const PlanarArm& arm,
                                          const PostureTableSettings& settings);

  // What the build did (not saved): wall time, SLSQP runs, entries where none converged (the best
  // starting posture is kept).
  double build_time_s = 0.0;
  long optimisations = 0;
  long unconverged = 0;
  long degenerate = 0;  // entries whose polytope has no area (posture: the load-free optimum)
  long continued = 0;   // entries the continuity tie-break moved off the best optimum found

  // Neighbouring nodes (E, N, NE and NW of each node: every pair once) whose postures of pattern
  // differ in some moving joint by more than `fraction` of its range: a jump between branches.
  int jumps(const PlanarArm& arm, int pattern, double fraction = 0.25) const;
  // The neighbour pairs jumps() looks at.
  int neighbour_pairs() const;

 private:
  // A table with its grid and patterns sized and no postures yet; the workspace sampled for it
  // (with each node's starting postures) in `workspace`.
  static PostureTable empty(const PlanarArm& arm, const PostureTableSettings& settings,
                            std::uint64_t fingerprint, Workspace& workspace);
  std::size_t entry(int node, int pattern) const {
    return static_cast<std::size_t>(node) * patterns_.size() + static_cast<std::size_t>(pattern);
  }
  int moving_ = 0;
  WorkspaceGrid grid_;
  std::vector<mhsb::ModePattern> patterns_;
  std::vector<double> q_;  // per entry: moving() coordinates
  std::vector<double> area_;
  std::uint64_t fingerprint_ = 0;
  bool optimal_ = true;
};

// What the table depends on, hashed: the model, the held joints, spacing, seeds and starts.
std::uint64_t posture_table_fingerprint(const PlanarArm& arm, const PostureTableSettings& settings);

// The default cache file: $XDG_CACHE_HOME/craneassist (else ~/.cache/craneassist) /
// ptp-table-<fingerprint>.bin; nullopt when neither variable is set.
std::optional<std::filesystem::path> default_table_file(const PlanarArm& arm,
                                                        const PostureTableSettings& settings);

}  // namespace craneassist::planner
