// Offline energy-optimal redundancy resolution along a prescribed tip path by discrete-time
// dynamic programming (paper 000 section 5, Algorithm 1; docs/algorithms.md section 7).
//
// States: extension cylinder position c and velocity v on a uniform grid; control: its
// acceleration a on a uniform grid; dynamics c' = c + v dt + a dt^2 / 2, v' = v + a dt (paper 000
// eqs. 30-31). The backward phase computes the optimal cost-to-go J_k(c, v) for every stage and
// grid state, interpolating J_{k+1} bilinearly at the successor state; the forward phase starts
// from the given initial state and, at each stage, picks the control that minimises the exact
// stage cost plus the interpolated J_{k+1} at the exact (off-grid) state. Storing J (one float
// per state and stage) rather than the argmin controls lets the forward phase re-optimise at the
// real state; it also makes a new initial configuration cost only another forward phase.
//
// Work: the stage model's per-position terms (four ODE inverse-dynamics probes) once per grid
// position and stage, then a handful of multiply-adds per (state, control). The grid rows are
// shared among worker threads; each worker owns an ODE probe.
//
// Memory: (N + 1) Nc Nv floats for J plus per-thread row buffers: 29 MB for the paper's
// 356 x 101 grid over 200 stages. Refinement passes (see DpRefinement) then re-solve in a narrow
// tube around the trajectory on a finer grid; they depend on the initial state, so a new initial
// configuration costs another (small) backward phase for them.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <vector>

#include "craneassist/dynamics/resolutions.hpp"
#include "craneassist/planner/stage_model.hpp"

namespace craneassist::planner {

struct DpGrid {
  int positions = 356;   // Nx1: extension cylinder positions over its stroke
  int velocities = 101;  // Nx2: extension cylinder velocities over +-v_max (odd: 0 on the grid)
  int controls = 151;    // Nu: extension cylinder accelerations over +-a_max (odd: 0 on the grid)
};

// Refinement passes (iterative dynamic programming): a finer grid in a tube around the previous
// pass's trajectory, half as wide on every pass. The coarse grid's bilinear interpolation smears
// the kinks of the flow and power costs (a cylinder coming to rest); the tube resolves them.
struct DpRefinement {
  int passes = 3;
  DpGrid grid{41, 41, 81};
  double c_half_width_m = 0.02;     // first pass: +-4 cells of the paper's position grid
  double v_half_width_m_s = 0.024;  // first pass: +-3 cells of the paper's velocity grid
};

struct DpOptions {
  DpGrid grid;
  DpRefinement refinement;
  int threads = 0;  // 0: std::thread::hardware_concurrency()
  // Called from the calling thread after each backward stage: (stages done, stages in all).
  std::function<void(int, int)> progress;
  // Set to true from another thread to stop early (the result then has ok == false).
  const std::atomic<bool>* cancel = nullptr;
};

// One sample of a planned motion.
struct PlanPoint {
  double t_s = 0.0;
  double c_m = 0.0, v_m_s = 0.0, a_m_s2 = 0.0;  // extension cylinder state and control
  JointVector q, qdot, qddot;
  double cost = 0.0, penalty = 0.0;  // of the stage starting here (0 at the last point)
  double flow_m3_s = 0.0;            // pump flow of the cylinder velocities
};

struct Plan {
  bool ok = false;
  std::string method;  // "dp" or the online resolution's name
  PlanCost cost_function = PlanCost::kLoadSensing;
  std::vector<PlanPoint> points;  // stages 0..N
  double total_cost = 0.0;        // sum of stage costs (J, or m^2/s for the extension cost)
  double total_penalty = 0.0;     // sum of limit penalties (0: every limit respected)
  int penalised_stages = 0;
  int refinement_passes = 0;                 // tube passes that improved the plan
  double backward_s = 0.0, forward_s = 0.0;  // wall time of the phases
  std::size_t table_bytes = 0;               // memory of the cost-to-go table
};

// Extension cylinder positions at stage 0 where the inverse kinematics keeps every joint within
// its range (on a fine sweep). Returns false when there is none.
bool feasible_extension_range(const StageModel& stages, int k, double& c_lo, double& c_hi);

// The whole DP: backward phase, then a forward phase from (c_initial, v = 0).
Plan plan_dp(const StageModel& stages, double c_initial, const DpOptions& options);

// The cost-to-go table of a backward phase, for repeated forward phases from other initial states.
class DpSolution {
 public:
  DpSolution(const StageModel& stages, const DpOptions& options);
  ~DpSolution();
  DpSolution(const DpSolution&) = delete;
  DpSolution& operator=(const DpSolution&) = delete;

  bool ok() const;  // false when cancelled
  double backward_s() const;
  std::size_t table_bytes() const;
  // Cost-to-go interpolated at stage k and state (c, v), with the out-of-grid penalty.
  double cost_to_go(int k, double c, double v) const;
  Plan forward(double c_initial) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// An online resolution driven along the same path (a baseline for the planner): at each stage the
// resolution picks the extension rate for the next stage's tip velocity (with joint-rate bounds
// from the cylinder velocity limits, the joint ranges and the acceleration limits), and the
// extension cylinder accelerates towards it within its acceleration limit. Evaluated with the
// stage model's cost, so the result compares with plan_dp directly.
Plan plan_online(const StageModel& stages, dynamics::Resolution resolution, double c_initial);

// Re-evaluates a plan's stage costs with `stages` (another cost function on the same path).
void evaluate_plan(const StageModel& stages, Plan& plan);

}  // namespace craneassist::planner
