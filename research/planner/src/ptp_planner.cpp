#include "craneassist/planner/ptp_planner.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/hydraulics.hpp"

namespace craneassist::planner {
namespace {

using mhsb::MhsbMode;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kRestSpeed = 1e-6;  // m/s: a cylinder slower than this is at rest (S4)

std::size_t at(int i) {
  return static_cast<std::size_t>(i);
}

double sign(double x) {
  return x > 0.0 ? 1.0 : x < 0.0 ? -1.0 : 0.0;
}

// The sixth-degree segment on tau in [0, 1]: c0..c2 from the start (q0, h v0, h^2 a0 / 2), c3..c6
// from q(1) = q1, q'(1) = h v1, q''(1) = h^2 a1 and q(1/2) = (q0 + q1) / 2 (the midpoint of the
// S2 segment's constant-rate motion; the rate at the midpoint instead would be singular).
const Eigen::Matrix4d& segment_inverse() {
  static const Eigen::Matrix4d inv = [] {
    Eigen::Matrix4d m;
    m << 1, 1, 1, 1,                            // q(1)
        3, 4, 5, 6,                             // q'(1)
        6, 12, 20, 30,                          // q''(1)
        1.0 / 8, 1.0 / 16, 1.0 / 32, 1.0 / 64;  // q(1/2)
    return Eigen::Matrix4d(m.inverse());
  }();
  return inv;
}

}  // namespace

const char* to_string(PtpEnergy energy) {
  switch (energy) {
    case PtpEnergy::kMhsbSeries:
      return "MHSB (series)";
    case PtpEnergy::kMhsbPaper:
      return "MHSB (paper eq. 9)";
    case PtpEnergy::kLoadSensing:
      return "load-sensing pump";
    case PtpEnergy::kConstantPressure:
      return "constant-pressure pump";
  }
  return "?";
}

PtpPlanner::PtpPlanner(const PlanarArm& arm, const PostureTable& table, const PtpSettings& settings)
    : arm_(&arm), table_(&table), settings_(settings) {
  const auto& model = arm.model();
  const int m = arm.moving();
  if (table.moving() != m) throw std::invalid_argument("the posture table is for another arm");
  if (model.mhsb) {
    energy_ = settings.energy_model == mhsb::MhsbEnergyModel::kPaper ? PtpEnergy::kMhsbPaper
                                                                     : PtpEnergy::kMhsbSeries;
  } else {
    energy_ = model.pump.mode == dynamics::PumpMode::kConstantPressure
                  ? PtpEnergy::kConstantPressure
                  : PtpEnergy::kLoadSensing;
  }
  ArmVector vmax(m);
  for (int k = 0; k < m; ++k) {
    double v = settings.velocity_limit_m_s;
    if (!(v > 0.0)) {
      v = model.mhsb && model.mhsb->velocity_limit_m_s > 0.0
              ? model.mhsb->velocity_limit_m_s
              : model.cylinders[at(arm.joint(k))].v_max_m_s;
    }
    v_limit_.push_back(v);
    vmax[k] = v;
  }
  tip_speed_bound_ = arm.tip_speed_bound(vmax);
  if (model.mhsb) {
    min_power_w_ = m * model.pump.supply_pressure_pa * model.mhsb->valve.leakage_m3_s;
  }
  // Statics of every table entry.
  const int nodes = table.grid().nodes(), np = table.pattern_count();
  statics_.resize(at(nodes * np));
  PlanarArm::Statics s;
  for (int n = 0; n < nodes; ++n) {
    for (int p = 0; p < np; ++p) {
      arm.statics(table.posture(n, p), data_, s);
      statics_[at(n * np + p)] = {s.length_m, s.force_n};
    }
  }
  // The graph.
  first_edge_.assign(at(nodes * np + 1), 0);
  for (int n = 0; n < nodes; ++n) {
    for (int p = 0; p < np; ++p) {
      const int from = n * np + p;
      first_edge_[at(from)] = static_cast<int>(edges_.size());
      for (int d = 0; d < 8; ++d) {
        const int next = table.grid().neighbour(n, d);
        if (next < 0) continue;
        for (int p2 = 0; p2 < np; ++p2) {
          if (auto e = transition(from, next * np + p2)) edges_.push_back(*e);
        }
      }
    }
  }
  first_edge_[at(nodes * np)] = static_cast<int>(edges_.size());
  g_.resize(at(nodes * np));
  parent_.resize(at(nodes * np));
  closed_.resize(at(nodes * np));
  heap_.reserve(edges_.size() + 1);
}

double PtpPlanner::stage_power_w(const EntryStatics& s, const ArmVector& v,
                                 const mhsb::ModePattern& modes) const {
  const auto& model = arm_->model();
  const int m = arm_->moving();
  if (energy_ == PtpEnergy::kMhsbSeries || energy_ == PtpEnergy::kMhsbPaper) {
    const auto em = energy_ == PtpEnergy::kMhsbPaper ? mhsb::MhsbEnergyModel::kPaper
                                                     : mhsb::MhsbEnergyModel::kSeries;
    double p = 0.0;
    for (int k = 0; k < m; ++k) {
      p += mhsb::mhsb_actuator_power_w(model, arm_->joint(k), modes.mode[at(k)], s.force_n[k], v[k],
                                       em);
    }
    return p;
  }
  double flow = 0.0, load = 0.0;
  for (int k = 0; k < m; ++k) {
    const auto& c = model.cylinders[at(arm_->joint(k))];
    flow += dynamics::cylinder_flow_m3_s(c, v[k]);
    if (mhsb::positive_load(s.force_n[k], v[k])) {
      load = std::max(load, v[k] > 0.0 ? s.force_n[k] / c.area_a_m2 : -s.force_n[k] / c.area_b_m2);
    }
  }
  if (energy_ == PtpEnergy::kConstantPressure) return model.pump.supply_pressure_pa * flow;
  const double supply = flow > 0.0 ? load + model.pump.ls_margin_pa : 0.0;
  return std::max(supply, flow > 0.0 ? model.pump.standby_pressure_pa : 0.0) * flow;
}

std::optional<PtpPlanner::Edge> PtpPlanner::transition(int from, int to) const {
  const auto& model = arm_->model();
  const int m = arm_->moving(), np = table_->pattern_count();
  const EntryStatics& a = statics_[at(from)];
  const EntryStatics& b = statics_[at(to)];
  const mhsb::ModePattern& pa = table_->patterns()[at(from % np)];
  const mhsb::ModePattern& pb = table_->patterns()[at(to % np)];
  double t = 0.0, flow = 0.0;
  for (int k = 0; k < m; ++k) {
    const auto& c = model.cylinders[at(arm_->joint(k))];
    const double dc = b.length_m[k] - a.length_m[k];
    const double area = dynamics::flow_area_m2(c, dc);
    double cap = v_limit_[at(k)];
    if (model.mhsb)
      cap = std::min(cap, mhsb::mode_flow_cap_m3_s(*model.mhsb, pb.mode[at(k)]) / area);
    t = std::max(t, std::abs(dc) / cap);
    flow += area * std::abs(dc);
  }
  if (model.pump.max_flow_m3_s > 0.0) t = std::max(t, flow / model.pump.max_flow_m3_s);
  if (!(t > 0.0)) return std::nullopt;
  ArmVector v(m);
  for (int k = 0; k < m; ++k) v[k] = (b.length_m[k] - a.length_m[k]) / t;
  if (model.mhsb) {
    const auto& h = *model.mhsb;
    for (int k = 0; k < m; ++k) {
      const int j = arm_->joint(k);
      const MhsbMode mode = pb.mode[at(k)];
      // At rest the need is whether the valve holds the load from P0.
      auto needs = [&](double f) {
        const double vv = v[k] != 0.0 ? v[k] : 1e-9 * sign(f);
        return mhsb::needs_boost(model, j, f, vv);
      };
      const bool need = needs(a.force_n[k]) || needs(b.force_n[k]);
      if (need != mhsb::is_boost(mode)) return std::nullopt;
      if (need) {
        const auto& c = model.cylinders[at(j)];
        const double supply = mhsb::mode_supply_pressure_pa(model, mode);
        for (double f : {a.force_n[k], b.force_n[k]}) {
          if (mhsb::required_supply_pressure_pa(c, h.valve, h.tank_pressure_pa, f, v[k]) > supply) {
            return std::nullopt;
          }
        }
      }
    }
  }
  const double e = t * 0.5 * (stage_power_w(a, v, pb) + stage_power_w(b, v, pb));
  return Edge{to, pb.switches_from(pa), t, e};
}

double PtpPlanner::heuristic_per_m(const PtpWeights& w) const {
  if (w.heuristic_per_m) return *w.heuristic_per_m;
  if (w.energy == 0.0 && w.time == 0.0 && w.switches == 0.0) return 1.0;
  if (!(tip_speed_bound_ > 0.0) || !std::isfinite(tip_speed_bound_)) return 0.0;
  return (w.time + w.energy * min_power_w_) / tip_speed_bound_;
}

int PtpPlanner::node_near(const Eigen::Vector2d& xz) const {
  const double h = table_->grid().spacing_m;
  return table_->grid().nearest_node(xz, 0.5 * std::sqrt(2.0) * h + 1e-9);
}

PtpPath PtpPlanner::search(int start_node, int goal_node, const PtpWeights& w, PtpSearch kind) {
  PtpPath path;
  const int np = table_->pattern_count();
  const auto& grid = table_->grid();
  if (start_node < 0 || goal_node < 0 || start_node >= grid.nodes() || goal_node >= grid.nodes()) {
    return path;
  }
  const double k = kind == PtpSearch::kAStar ? heuristic_per_m(w) : 0.0;
  const Eigen::Vector2d goal = grid.node_xz[at(goal_node)];
  auto h = [&](int state) { return k * (grid.node_xz[at(state / np)] - goal).norm(); };
  std::fill(g_.begin(), g_.end(), kInf);
  std::fill(closed_.begin(), closed_.end(), 0);
  heap_.clear();
  const auto later = [](const std::pair<double, int>& l, const std::pair<double, int>& r) {
    return l.first != r.first ? l.first > r.first : l.second > r.second;
  };
  const int start = start_node * np;  // all N
  g_[at(start)] = 0.0;
  parent_[at(start)] = -1;
  heap_.emplace_back(h(start), start);
  int reached = -1;
  while (!heap_.empty()) {
    std::pop_heap(heap_.begin(), heap_.end(), later);
    const int s = heap_.back().second;
    heap_.pop_back();
    if (closed_[at(s)] != 0) continue;
    closed_[at(s)] = 1;
    ++path.expanded;
    if (s / np == goal_node) {
      reached = s;
      break;
    }
    const double gs = g_[at(s)];
    for (int e = first_edge_[at(s)]; e < first_edge_[at(s + 1)]; ++e) {
      const Edge& edge = edges_[at(e)];
      if (closed_[at(edge.to)] != 0) continue;
      const double g =
          gs + w.energy * edge.energy_j + w.time * edge.time_s + w.switches * edge.switches;
      if (g < g_[at(edge.to)]) {
        g_[at(edge.to)] = g;
        parent_[at(edge.to)] = s;
        heap_.emplace_back(g + h(edge.to), edge.to);
        std::push_heap(heap_.begin(), heap_.end(), later);
      }
    }
  }
  if (reached < 0) return path;
  std::vector<int> states;
  for (int s = reached; s >= 0; s = parent_[at(s)]) states.push_back(s);
  std::reverse(states.begin(), states.end());
  path.found = true;
  path.cost = g_[at(reached)];
  for (std::size_t i = 0; i < states.size(); ++i) {
    const int s = states[i];
    PtpStep step;
    step.node = s / np;
    step.pattern = s % np;
    step.q = table_->posture(step.node, step.pattern);
    if (i > 0) {
      const int prev = states[i - 1];
      for (int e = first_edge_[at(prev)]; e < first_edge_[at(prev + 1)]; ++e) {
        const Edge& edge = edges_[at(e)];
        if (edge.to != s) continue;
        path.time_s += edge.time_s;
        path.energy_j += edge.energy_j;
        path.switches += edge.switches;
        break;
      }
      path.length_m += (grid.node_xz[at(step.node)] - grid.node_xz[at(prev / np)]).norm();
    }
    step.t_s = path.time_s;
    step.energy_j = path.energy_j;
    path.steps.push_back(step);
  }
  return path;
}

double PtpPlanner::power_w(const ArmVector& a, const ArmVector& qdot,
                           const std::array<MhsbMode, dynamics::kMaxJoints>& modes) {
  PlanarArm::Statics s;
  arm_->statics(a, data_, s);
  mhsb::ModePattern p;
  p.dof = arm_->moving();
  p.mode = modes;
  ArmVector v = s.arm.cwiseProduct(qdot);
  return stage_power_w({s.length_m, s.force_n}, v, p);
}

PtpPlan PtpPlanner::plan(const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                         const PtpWeights& w, const std::optional<ArmVector>& q_start) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto& model = arm_->model();
  const auto& grid = table_->grid();
  const int m = arm_->moving();
  const int start = node_near(from), goal = node_near(to);
  if (start < 0) throw std::invalid_argument("the start is outside the workspace");
  if (goal < 0) throw std::invalid_argument("the goal is outside the workspace");
  PtpPlan plan;
  plan.start_snap_m = (grid.node_xz[at(start)] - from).norm();
  plan.goal_snap_m = (grid.node_xz[at(goal)] - to).norm();
  plan.path = search(start, goal, w);
  const auto& steps = plan.path.steps;
  if (!plan.path.found) return plan;

  // S3: node postures and times; rates at the nodes; one sixth-degree polynomial per segment.
  const std::size_t nn = steps.size();
  std::vector<ArmVector> q(nn), v(nn);
  std::vector<double> t(nn);
  for (std::size_t i = 0; i < nn; ++i) {
    q[i] = steps[i].q;
    t[i] = steps[i].t_s;
  }
  if (q_start) {
    q[0] = *q_start;
    // The first segment from there, at the limits of the first step's pattern.
    if (nn > 1) {
      PlanarArm::Statics s0, s1;
      arm_->statics(q[0], data_, s0);
      arm_->statics(q[1], data_, s1);
      double t1 = 0.0;
      for (int k = 0; k < m; ++k)
        t1 = std::max(t1, std::abs(s1.length_m[k] - s0.length_m[k]) / v_limit_[at(k)]);
      const double shift = std::max(t1, 1e-3) - t[1];
      for (std::size_t i = 1; i < nn; ++i) t[i] += shift;
    }
  }
  // Node rates: 0 at the ends and where a joint turns, else the slower of its two segments' mean
  // rates (no overshoot of the node postures).
  const auto node_rates = [&] {
    for (std::size_t i = 0; i < nn; ++i) v[i] = ArmVector::Zero(m);
    for (std::size_t i = 1; i + 1 < nn; ++i) {
      for (int k = 0; k < m; ++k) {
        const double s0 = (q[i][k] - q[i - 1][k]) / (t[i] - t[i - 1]);
        const double s1 = (q[i + 1][k] - q[i][k]) / (t[i + 1] - t[i]);
        v[i][k] = s0 * s1 > 0.0 ? sign(s0) * std::min(std::abs(s0), std::abs(s1)) : 0.0;
      }
    }
  };
  using Coefficients = Eigen::Matrix<double, 7, dynamics::kMaxJoints>;
  std::vector<Coefficients> coeffs(nn > 1 ? nn - 1 : 0);
  const auto fit = [&](std::size_t seg) {
    const double h = t[seg + 1] - t[seg];
    Coefficients& c = coeffs[seg];
    for (int k = 0; k < m; ++k) {
      c(0, k) = q[seg][k];
      c(1, k) = h * v[seg][k];
      c(2, k) = 0.0;
      const Eigen::Vector4d rhs(q[seg + 1][k] - c(0, k) - c(1, k), h * v[seg + 1][k] - c(1, k), 0.0,
                                0.5 * (q[seg][k] + q[seg + 1][k]) - c(0, k) - 0.5 * c(1, k));
      c.block<4, 1>(3, k) = segment_inverse() * rhs;
    }
  };
  // Position, rate and acceleration of segment seg at tau in [0, 1].
  const auto evaluate = [&](std::size_t seg, double tau, ArmVector& pos, ArmVector& rate,
                            ArmVector& acc) {
    const double h = t[seg + 1] - t[seg];
    const Coefficients& c = coeffs[seg];
    for (int k = 0; k < m; ++k) {
      double p = 0.0, d = 0.0, dd = 0.0;  // Horner, on the derived coefficients too
      for (int j = 6; j >= 0; --j) p = p * tau + c(j, k);
      for (int j = 6; j >= 1; --j) d = d * tau + j * c(j, k);
      for (int j = 6; j >= 2; --j) dd = dd * tau + j * (j - 1) * c(j, k);
      pos[k] = p;
      rate[k] = d / h;
      acc[k] = dd / (h * h);
    }
  };
  // Quasi-static speeds: a segment whose cylinder speed peaks above max_speed_ratio V_L (at most
  // the cylinder's max_speed) is lengthened by the excess, the later nodes shifted; a few passes.
  // Cylinder velocity of moving joint k at joint position qk and rate.
  const auto arm_rate = [&](int k, double qk, double rate_k) {
    return dynamics::cylinder_arm(model.cylinders[at(arm_->joint(k))], qk) * rate_k;
  };
  PlanarArm::Statics st;
  ArmVector pos(m), rate(m), acc(m);
  for (int pass = 0; pass < 4; ++pass) {
    node_rates();
    bool stretched = false;
    for (std::size_t seg = 0; seg + 1 < nn; ++seg) {
      fit(seg);
      double ratio = 0.0;
      for (int j = 0; j <= 16; ++j) {
        evaluate(seg, j / 16.0, pos, rate, acc);
        for (int k = 0; k < m; ++k) {
          const double cap = std::min(settings_.max_speed_ratio * v_limit_[at(k)],
                                      model.cylinders[at(arm_->joint(k))].v_max_m_s);
          ratio = std::max(ratio, std::abs(arm_rate(k, pos[k], rate[k])) / cap);
        }
      }
      if (ratio > 1.0 + 1e-6) {
        const double extra = (t[seg + 1] - t[seg]) * (ratio - 1.0);
        for (std::size_t i = seg + 1; i < nn; ++i) t[i] += extra;
        stretched = true;
      }
    }
    if (!stretched) break;
  }
  for (std::size_t seg = 0; seg + 1 < nn; ++seg) fit(seg);
  const double dt = settings_.sample_period_s;
  const double total = t[nn - 1];
  const int count = nn == 1 ? 1 : static_cast<int>(std::ceil(total / dt - 1e-9)) + 1;
  std::size_t seg = 0;
  std::vector<double> powers;
  std::vector<Eigen::Vector2d> tips;
  powers.reserve(static_cast<std::size_t>(count));
  tips.reserve(static_cast<std::size_t>(count));
  plan.samples.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    PtpSample sample;
    sample.t_s = std::min(i * dt, total);
    sample.q = q[nn - 1];
    sample.qdot = ArmVector::Zero(m);
    sample.qddot = ArmVector::Zero(m);
    if (nn > 1) {
      while (seg + 2 < nn && sample.t_s > t[seg + 1]) ++seg;
      const double tau = std::clamp((sample.t_s - t[seg]) / (t[seg + 1] - t[seg]), 0.0, 1.0);
      evaluate(seg, tau, sample.q, sample.qdot, sample.qddot);
    }
    // S4: the modes the sample's cylinder velocities and forces call for.
    arm_->statics(sample.q, data_, st);
    for (int k = 0; k < m; ++k) {
      const double vc = st.arm[k] * sample.qdot[k];
      sample.mode[at(k)] = MhsbMode::kNormal;
      if (!model.mhsb) continue;
      // At rest (the trajectory's ends: rates of rounding size) the need is whether the valve
      // holds the load from P0, as in S2.
      const double vv = std::abs(vc) > kRestSpeed ? vc : 1e-9 * sign(st.force_n[k]);
      if (!mhsb::needs_boost(model, arm_->joint(k), st.force_n[k], vv)) continue;
      const MhsbMode planned =
          table_->patterns()[at(steps[std::min(seg + 1, nn - 1)].pattern)].mode[at(k)];
      const auto& c = model.cylinders[at(arm_->joint(k))];
      const double one_pump = model.mhsb->servo_pump_max_flow_m3_s;
      sample.mode[at(k)] = mhsb::is_boost(planned) ? planned
                           : dynamics::flow_area_m2(c, vc) * std::abs(vc) <= one_pump
                               ? MhsbMode::kDecoupledBoost
                               : MhsbMode::kSharedBoost;
    }
    // Its power and tip, from the same statics (the frames are those of sample.q).
    mhsb::ModePattern modes;
    modes.dof = m;
    modes.mode = sample.mode;
    powers.push_back(
        stage_power_w({st.length_m, st.force_n}, st.arm.cwiseProduct(sample.qdot), modes));
    tips.push_back(arm_->plane() *
                   (model.task_from_base * data_.frames[at(model.dof())].translation()));
    plan.samples.push_back(sample);
  }
  // What the samples do.
  double prev_power = 0.0;
  Eigen::Vector2d prev_tip = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < plan.samples.size(); ++i) {
    const PtpSample& s = plan.samples[i];
    const double p = powers[i];
    const Eigen::Vector2d tip = tips[i];
    for (int k = 0; k < m; ++k) {
      plan.peak_speed_ratio = std::max(plan.peak_speed_ratio,
                                       std::abs(arm_rate(k, s.q[k], s.qdot[k])) / v_limit_[at(k)]);
    }
    if (i > 0) {
      const PtpSample& r = plan.samples[i - 1];
      plan.energy_j += 0.5 * (p + prev_power) * (s.t_s - r.t_s);
      plan.length_m += (tip - prev_tip).norm();
      for (int k = 0; k < m; ++k) plan.switches += s.mode[at(k)] != r.mode[at(k)] ? 1 : 0;
    }
    prev_power = p;
    prev_tip = tip;
  }
  plan.time_s = plan.samples.back().t_s;
  plan.node_times_s = t;
  plan.planning_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return plan;
}

}  // namespace craneassist::planner
