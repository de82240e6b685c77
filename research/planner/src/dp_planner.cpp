#include "craneassist/planner/dp_planner.hpp"

#include <algorithm>
#include <barrier>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"

namespace craneassist::planner {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The plan's point of stage k at (c, v) with the control a, and the stage cost of a (none at the
// last point, which has no stage after it).
void fill_point(const StageModel& stages, int k, double c, double v, double a,
                const PositionTerms& pos, const VelocityTerms& vel, PlanPoint& out) {
  if (k < stages.stages()) {
    const StageCost sc = stages.cost(vel, a);
    out.cost = sc.cost;
    out.penalty = sc.penalty;
  }
  out.t_s = k * stages.dt();
  out.c_m = c;
  out.v_m_s = v;
  out.a_m_s2 = a;
  out.q = pos.q;
  out.qdot = vel.qdot;
  stages.joint_accelerations(pos, vel, a, out.qddot);
  out.flow_m3_s = vel.flow_m3_s;
}

void sum_plan(Plan& plan) {
  plan.total_cost = plan.total_penalty = 0.0;
  plan.penalised_stages = 0;
  for (const auto& p : plan.points) {
    plan.total_cost += p.cost;
    plan.total_penalty += p.penalty;
    if (p.penalty > 0.0) ++plan.penalised_stages;
  }
}

}  // namespace

bool feasible_extension_range(const StageModel& stages, int k, double& c_lo, double& c_hi) {
  dynamics::RigidBodyTerms terms(stages.model());
  constexpr int kSweep = 400;
  bool any = false;
  c_lo = c_hi = 0.0;
  PositionTerms pos;
  for (int i = 0; i <= kSweep; ++i) {
    const double c = stages.c_min() + (stages.c_max() - stages.c_min()) * i / kSweep;
    stages.position_terms(k, c, terms, pos);
    if (!pos.reachable || pos.violation > 0.0) continue;
    if (!any) c_lo = c;
    c_hi = c;
    any = true;
  }
  return any;
}

// One backward phase over a grid. The coarse pass spans the whole stroke and velocity range;
// a refinement pass spans a tube around the previous pass's trajectory (per-stage origins) with
// finer spacing, iterative dynamic programming in the manner of Luus.
struct DpSolution::Impl {
  const StageModel& stages;
  DpOptions options;
  int nc = 0, nv = 0, nu = 0, n_stages = 0;
  double dc = 0.0, dv = 0.0, du = 0.0;
  std::vector<double> c_origin, v_origin;  // per stage: the grid's first position and velocity
  bool tube = false;                       // a refinement pass: leaving the grid is penalised
  std::vector<float> table;                // J_k(i, j) at [(k * nc + i) * nv + j]
  bool ok = false;
  double backward_s = 0.0;

  // The coarse grid over the whole stroke and velocity range.
  Impl(const StageModel& s, const DpOptions& o) : stages(s), options(o) {
    const auto& g = options.grid;
    if (g.positions < 2 || g.velocities < 2 || g.controls < 2) {
      throw std::invalid_argument("the DP grid needs at least 2 points per dimension");
    }
    n_stages = stages.stages();
    setup(g, (stages.c_max() - stages.c_min()) / (g.positions - 1),
          2.0 * stages.v_max() / (g.velocities - 1));
    std::fill(c_origin.begin(), c_origin.end(), stages.c_min());
    std::fill(v_origin.begin(), v_origin.end(), -stages.v_max());
  }

  // A tube of the given grid around a trajectory (the previous pass's plan).
  Impl(const StageModel& s, const DpOptions& o, const DpGrid& g, const Plan& around,
       double c_half_width, double v_half_width)
      : stages(s), options(o) {
    n_stages = stages.stages();
    tube = true;
    setup(g, 2.0 * c_half_width / (g.positions - 1), 2.0 * v_half_width / (g.velocities - 1));
    for (int k = 0; k <= n_stages; ++k) {
      const auto& p = around.points[static_cast<std::size_t>(k)];
      c_origin[static_cast<std::size_t>(k)] = p.c_m - c_half_width;
      v_origin[static_cast<std::size_t>(k)] = p.v_m_s - v_half_width;
    }
  }

  void setup(const DpGrid& g, double c_step, double v_step) {
    nc = g.positions;
    nv = g.velocities;
    nu = g.controls;
    dc = c_step;
    dv = v_step;
    du = 2.0 * stages.a_max() / (nu - 1);
    c_origin.assign(static_cast<std::size_t>(n_stages + 1), 0.0);
    v_origin.assign(static_cast<std::size_t>(n_stages + 1), 0.0);
    table.assign(static_cast<std::size_t>(n_stages + 1) * nc * nv, 0.0f);
  }

  double c_at(int k, int i) const { return c_origin[static_cast<std::size_t>(k)] + dc * i; }
  double v_at(int k, int j) const { return v_origin[static_cast<std::size_t>(k)] + dv * j; }
  double u_at(int l) const { return -stages.a_max() + du * l; }
  double penalty() const { return stages.options().penalty_factor * stages.stage_scale(); }
  float* row(int k, int i) { return table.data() + (static_cast<std::size_t>(k) * nc + i) * nv; }
  const float* row(int k, int i) const {
    return table.data() + (static_cast<std::size_t>(k) * nc + i) * nv;
  }

  // Bilinear interpolation of J_k at (c, v). States off the grid are clamped onto it and pay the
  // limit penalty: on the coarse grid they are beyond the stroke or the velocity limit; in a tube,
  // outside the tube.
  double interpolate(int k, double c, double v) const {
    double fc = (c - c_origin[static_cast<std::size_t>(k)]) / dc;
    double fv = (v - v_origin[static_cast<std::size_t>(k)]) / dv;
    double excess = 0.0;
    if (fc < 0.0 || fc > nc - 1) {
      const double clamped = std::clamp(fc, 0.0, static_cast<double>(nc - 1));
      excess += std::abs(fc - clamped) * dc / (stages.c_max() - stages.c_min());
      fc = clamped;
    }
    if (fv < 0.0 || fv > nv - 1) {
      const double clamped = std::clamp(fv, 0.0, static_cast<double>(nv - 1));
      excess += std::abs(fv - clamped) * dv / stages.v_max();
      fv = clamped;
    }
    const int i = std::min(static_cast<int>(fc), nc - 2);
    const int j = std::min(static_cast<int>(fv), nv - 2);
    const double wc = fc - i, wv = fv - j;
    const float* r0 = row(k, i);
    const float* r1 = row(k, i + 1);
    const double value = (1.0 - wc) * ((1.0 - wv) * r0[j] + wv * r0[j + 1]) +
                         wc * ((1.0 - wv) * r1[j] + wv * r1[j + 1]);
    return excess > 0.0 ? value + penalty() * (1.0 + excess) : value;
  }

  // Terminal cost: the extension at rest when the tip is (a penalty on |v|), and within the
  // stroke.
  void terminal() {
    for (int i = 0; i < nc; ++i) {
      const double c = c_at(n_stages, i);
      const double outside = std::max({stages.c_min() - c, c - stages.c_max(), 0.0});
      float* r = row(n_stages, i);
      for (int j = 0; j < nv; ++j) {
        double value = penalty() * std::abs(v_at(n_stages, j)) / stages.v_max();
        if (outside > 0.0) value += penalty() * (1.0 + outside / (stages.c_max() - stages.c_min()));
        r[j] = static_cast<float>(value);
      }
    }
  }

  // Minimum over the control grid of stage cost plus interpolated J_{k+1}; returns the control.
  double best_control(int k, double c, double v, const VelocityTerms& vel,
                      std::vector<double>& totals, double& best) const {
    const double dt = stages.dt();
    stages.total_costs(vel, u_at(0), du, nu, totals.data());
    best = std::numeric_limits<double>::infinity();
    double best_u = 0.0;
    for (int l = 0; l < nu; ++l) {
      const double a = u_at(l);
      const double total = totals[static_cast<std::size_t>(l)] +
                           interpolate(k + 1, c + v * dt + 0.5 * a * dt * dt, v + a * dt);
      if (total < best) {
        best = total;
        best_u = a;
      }
    }
    return best_u;
  }

  // The forward phase is not bound to the control grid: golden-section search of stage cost plus
  // interpolated J_{k+1} over the grid cells either side of the best grid control.
  double refine_control(int k, double c, double v, const VelocityTerms& vel, double a_grid) const {
    const double dt = stages.dt();
    const auto total = [&](double a) {
      return stages.cost(vel, a).total() +
             interpolate(k + 1, c + v * dt + 0.5 * a * dt * dt, v + a * dt);
    };
    double lo = std::max(a_grid - du, -stages.a_max()), hi = std::min(a_grid + du, stages.a_max());
    constexpr double kRatio = 0.6180339887498949;
    double x1 = hi - kRatio * (hi - lo), x2 = lo + kRatio * (hi - lo);
    double f1 = total(x1), f2 = total(x2);
    for (int it = 0; it < 24; ++it) {
      if (f1 < f2) {
        hi = x2;
        x2 = x1;
        f2 = f1;
        x1 = hi - kRatio * (hi - lo);
        f1 = total(x1);
      } else {
        lo = x1;
        x1 = x2;
        f1 = f2;
        x2 = lo + kRatio * (hi - lo);
        f2 = total(x2);
      }
    }
    const double a_refined = 0.5 * (lo + hi);
    return total(a_refined) < total(a_grid) ? a_refined : a_grid;
  }

  void backward_row(int k, int i, dynamics::RigidBodyTerms& terms, PositionTerms& pos,
                    VelocityTerms& vel, std::vector<double>& totals) {
    const double c = c_at(k, i);
    stages.position_terms(k, c, terms, pos);
    float* out = row(k, i);
    for (int j = 0; j < nv; ++j) {
      const double v = v_at(k, j);
      stages.velocity_terms(pos, v, vel);
      double best = 0.0;
      best_control(k, c, v, vel, totals, best);
      out[j] = static_cast<float>(std::min(best, 1e30));
    }
  }

  void backward(int stages_before, int stages_in_all) {
    const auto start = Clock::now();
    terminal();
    int threads = options.threads > 0 ? options.threads
                                      : static_cast<int>(std::thread::hardware_concurrency());
    threads = std::clamp(threads, 1, 64);
    std::atomic<int> next_row{0};
    std::atomic<bool> cancelled{false};
    int stage = n_stages - 1;
    // After each stage, one thread moves everyone on to the next (and reports progress).
    auto on_stage_done = [&]() noexcept {
      if (options.progress) options.progress(stages_before + n_stages - stage, stages_in_all);
      if (options.cancel != nullptr && options.cancel->load()) cancelled = true;
      --stage;
      next_row = 0;
    };
    std::barrier sync(threads, on_stage_done);
    auto work = [&]() {
      dynamics::RigidBodyTerms terms(stages.model());
      PositionTerms pos;
      VelocityTerms vel;
      std::vector<double> totals(static_cast<std::size_t>(nu));
      while (true) {
        const int k = stage;
        if (k < 0 || cancelled) break;
        for (int i = next_row++; i < nc; i = next_row++)
          backward_row(k, i, terms, pos, vel, totals);
        sync.arrive_and_wait();
      }
    };
    std::vector<std::jthread> workers;
    for (int t = 1; t < threads; ++t) workers.emplace_back(work);
    work();
    workers.clear();
    ok = !cancelled;
    backward_s = seconds_since(start);
  }

  Plan forward(double c_initial) const {
    const auto start = Clock::now();
    Plan plan;
    plan.method = "dp";
    plan.cost_function = stages.options().cost;
    plan.ok = ok;
    plan.table_bytes = table.size() * sizeof(float);
    plan.backward_s = backward_s;
    if (!ok) return plan;
    dynamics::RigidBodyTerms terms(stages.model());
    PositionTerms pos;
    VelocityTerms vel;
    std::vector<double> totals(static_cast<std::size_t>(nu));
    plan.points.resize(static_cast<std::size_t>(n_stages + 1));
    double c = c_initial, v = 0.0;
    const double dt = stages.dt();
    for (int k = 0; k <= n_stages; ++k) {
      stages.position_terms(k, c, terms, pos);
      stages.velocity_terms(pos, v, vel);
      double a = 0.0;
      if (k < n_stages) {
        double best = 0.0;
        a = refine_control(k, c, v, vel, best_control(k, c, v, vel, totals, best));
      }
      fill_point(stages, k, c, v, a, pos, vel, plan.points[static_cast<std::size_t>(k)]);
      c += v * dt + 0.5 * a * dt * dt;
      v += a * dt;
    }
    sum_plan(plan);
    plan.forward_s = seconds_since(start);
    return plan;
  }
};

DpSolution::DpSolution(const StageModel& stages, const DpOptions& options)
    : impl_(std::make_unique<Impl>(stages, options)) {
  const int n = stages.stages();
  impl_->backward(0, n * (1 + std::max(options.refinement.passes, 0)));
}
DpSolution::~DpSolution() = default;
bool DpSolution::ok() const {
  return impl_->ok;
}
double DpSolution::backward_s() const {
  return impl_->backward_s;
}
std::size_t DpSolution::table_bytes() const {
  return impl_->table.size() * sizeof(float);
}
double DpSolution::cost_to_go(int k, double c, double v) const {
  return impl_->interpolate(k, c, v);
}

Plan DpSolution::forward(double c_initial) const {
  Plan plan = impl_->forward(c_initial);
  const auto& options = impl_->options;
  const auto& refinement = options.refinement;
  const int n = impl_->n_stages;
  double width = 1.0;
  for (int pass = 0; pass < refinement.passes && plan.ok; ++pass, width *= 0.5) {
    Impl tube(impl_->stages, options, refinement.grid, plan, refinement.c_half_width_m * width,
              refinement.v_half_width_m_s * width);
    tube.backward(n * (pass + 1), n * (1 + refinement.passes));
    Plan refined = tube.forward(c_initial);
    refined.backward_s += plan.backward_s;
    refined.forward_s += plan.forward_s;
    refined.table_bytes = std::max(refined.table_bytes, plan.table_bytes);
    refined.refinement_passes = pass + 1;
    if (!refined.ok) return refined;
    const bool better =
        refined.total_cost + refined.total_penalty <= plan.total_cost + plan.total_penalty;
    if (better) {
      plan = std::move(refined);
    } else {
      plan.backward_s = refined.backward_s;
      plan.forward_s = refined.forward_s;
    }
  }
  return plan;
}

Plan plan_dp(const StageModel& stages, double c_initial, const DpOptions& options) {
  const DpSolution solution(stages, options);
  return solution.forward(c_initial);
}

Plan plan_online(const StageModel& stages, dynamics::Resolution resolution, double c_initial) {
  const auto start = Clock::now();
  const auto& model = stages.model();
  const int n = 4;
  const int n_stages = stages.stages();
  const double dt = stages.dt();
  dynamics::RigidBodyTerms terms(model);
  PositionTerms pos, next_pos;
  VelocityTerms vel;
  dynamics::KinematicsData kin;
  dynamics::TaskJacobian jac;
  dynamics::JointRateBounds bounds;
  dynamics::SnsResult sns;
  dynamics::ExtensionResolutionResult res;
  JointVector qdot_max(n), qddot_max(n), force(n);

  Plan plan;
  plan.method = dynamics::to_string(resolution);
  plan.cost_function = stages.options().cost;
  plan.points.resize(static_cast<std::size_t>(n_stages + 1));
  double c = c_initial, v = 0.0, a_prev = 0.0;
  for (int k = 0; k <= n_stages; ++k) {
    stages.position_terms(k, c, terms, pos);
    stages.velocity_terms(pos, v, vel);
    double a = 0.0;
    if (k < n_stages && pos.reachable) {
      // The resolution at the next stage's predicted configuration and tip velocity.
      const double c_next = c + v * dt;
      stages.position_terms(k + 1, c_next, terms, next_pos);
      double v_target = v;
      if (next_pos.reachable) {
        dynamics::tip_jacobian(model, kin, next_pos.q, jac);
        for (int i = 0; i < n; ++i) {
          const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
          qdot_max[i] = cyl.v_max_m_s / std::abs(next_pos.arm[i]);
          qddot_max[i] = cyl.a_max_m_s2 / std::abs(next_pos.arm[i]);
        }
        dynamics::joint_rate_bounds(model, next_pos.q, qdot_max, qddot_max, dt, bounds);
        // Acceleration limits: the joint rates can change by at most qddot_max dt per stage.
        for (int i = 0; i < n; ++i) {
          const double lo = std::max(bounds.lower[i], vel.qdot[i] - qddot_max[i] * dt);
          const double hi = std::min(bounds.upper[i], vel.qdot[i] + qddot_max[i] * dt);
          if (lo <= hi) {
            bounds.lower[i] = lo;
            bounds.upper[i] = hi;
          }
        }
        const Eigen::Vector3d v_tip = stages.samples().v_m_s[static_cast<std::size_t>(k + 1)];
        if (resolution == dynamics::Resolution::kPinvJoint) {
          dynamics::sns_velocity_ik(jac, v_tip, bounds, sns);
          v_target = sns.qdot[3] * stages.extension_arm();
        } else {
          for (int i = 0; i < n; ++i) force[i] = vel.force0[i] + vel.force1[i] * a_prev;
          dynamics::ExtensionResolutionInput in;
          in.jacobian = &jac;
          in.v_tip = v_tip;
          in.dc_dq = &next_pos.arm;
          in.bounds = &bounds;
          in.cylinder_force = &force;
          dynamics::resolve_by_extension(model, resolution, in, res);
          if (res.feasible) v_target = res.extension_rate * stages.extension_arm();
        }
      }
      a = std::clamp((v_target - v) / dt, -stages.a_max(), stages.a_max());
    }
    fill_point(stages, k, c, v, a, pos, vel, plan.points[static_cast<std::size_t>(k)]);
    c += v * dt + 0.5 * a * dt * dt;
    v += a * dt;
    a_prev = a;
  }
  sum_plan(plan);
  plan.ok = true;
  plan.forward_s = seconds_since(start);
  return plan;
}

void evaluate_plan(const StageModel& stages, Plan& plan) {
  dynamics::RigidBodyTerms terms(stages.model());
  const int n_stages = stages.stages();
  if (static_cast<int>(plan.points.size()) != n_stages + 1) {
    throw std::invalid_argument("the plan does not match the stage model's path");
  }
  for (int k = 0; k < n_stages; ++k) {
    auto& p = plan.points[static_cast<std::size_t>(k)];
    const StageCost sc = stages.evaluate(k, p.c_m, p.v_m_s, p.a_m_s2, terms);
    p.cost = sc.cost;
    p.penalty = sc.penalty;
  }
  plan.cost_function = stages.options().cost;
  sum_plan(plan);
}

}  // namespace craneassist::planner
