#include "craneassist/planner/posture_table.hpp"

#include <nlopt.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <unordered_map>

#include "craneassist/dynamics/cylinders.hpp"

namespace craneassist::planner {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr char kMagic[8] = {'C', 'A', 'P', 'T', 'T', 'A', 'B', '1'};
constexpr double kTipTolerance_m = 1e-6;   // a posture is on its node within this
constexpr double kDegenerateArea = 1e-12;  // m^2/s^2: a polytope without area

std::size_t at(int i) {
  return static_cast<std::size_t>(i);
}

// FNV-1a over the bytes of what the table depends on.
class Fingerprint {
 public:
  void add(double v) { bytes(&v, sizeof v); }
  void add(int v) { bytes(&v, sizeof v); }
  void add(std::uint64_t v) { bytes(&v, sizeof v); }
  std::uint64_t value() const { return h_; }

 private:
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ b[i]) * 1099511628211ULL;
  }
  std::uint64_t h_ = 14695981039346656037ULL;
};

// Pulls a onto the node (damped least squares, joint ranges kept); true when it gets there.
bool pull_onto(const PlanarArm& arm, dynamics::KinematicsData& data, const Eigen::Vector2d& target,
               ArmVector& a) {
  ArmJacobian j;
  for (int it = 0; it < 60; ++it) {
    const Eigen::Vector2d err = target - arm.tip(a, data);
    if (err.norm() < 1e-10) return true;
    arm.jacobian(a, data, j);
    const Eigen::Matrix2d jjt = j * j.transpose() + 1e-6 * Eigen::Matrix2d::Identity();
    a += j.transpose() * jjt.ldlt().solve(err);
    for (int k = 0; k < arm.moving(); ++k) a[k] = std::clamp(a[k], arm.lower(k), arm.upper(k));
  }
  return (target - arm.tip(a, data)).norm() < kTipTolerance_m;
}

// The data of one SLSQP run.
struct Problem {
  const PlanarArm* arm;
  PolytopeArea* area;
  dynamics::KinematicsData* data;
  const mhsb::ModePattern* pattern;
  Eigen::Vector2d target;
  double scale;  // the objective is area * scale (about 1 at the start)
};

double objective(unsigned n, const double* x, double* grad, void* user) {
  auto& p = *static_cast<Problem*>(user);
  ArmVector a = Eigen::Map<const Eigen::VectorXd>(x, n);
  const double f = (*p.area)(a, *p.pattern) * p.scale;
  if (grad != nullptr) {
    for (unsigned k = 0; k < n; ++k) {
      const int kk = static_cast<int>(k);
      const double h = 1e-6 * std::max(1.0, std::abs(a[kk]));
      const double lo = std::max(p.arm->lower(kk), a[kk] - h);
      const double hi = std::min(p.arm->upper(kk), a[kk] + h);
      ArmVector b = a;
      b[kk] = hi;
      const double fh = (*p.area)(b, *p.pattern) * p.scale;
      b[kk] = lo;
      const double fl = (*p.area)(b, *p.pattern) * p.scale;
      grad[k] = hi > lo ? (fh - fl) / (hi - lo) : 0.0;
    }
  }
  return f;
}

void tip_constraint(unsigned m, double* result, unsigned n, const double* x, double* grad,
                    void* user) {
  auto& p = *static_cast<Problem*>(user);
  const ArmVector a = Eigen::Map<const Eigen::VectorXd>(x, n);
  const Eigen::Vector2d e = p.arm->tip(a, *p.data) - p.target;
  result[0] = e.x();
  result[1] = e.y();
  if (grad != nullptr) {
    ArmJacobian j;
    p.arm->jacobian(a, *p.data, j);
    for (unsigned r = 0; r < m; ++r) {
      for (unsigned k = 0; k < n; ++k) grad[r * n + k] = j(r, k);
    }
  }
}

// SLSQP from a; returns the area of the result (a updated) or -1 when it did not end on the node.
double maximise(const PlanarArm& arm, PolytopeArea& area, dynamics::KinematicsData& data,
                const mhsb::ModePattern& pattern, const Eigen::Vector2d& target, ArmVector& a) {
  const auto n = static_cast<unsigned>(arm.moving());
  Problem p{&arm, &area, &data, &pattern, target, 1.0};
  const double start = area(a, pattern);
  p.scale = start > 1e-12 ? 1.0 / start : 1.0;
  nlopt_opt opt = nlopt_create(NLOPT_LD_SLSQP, n);
  std::vector<double> lb(n), ub(n), x(n);
  for (unsigned k = 0; k < n; ++k) {
    lb[k] = arm.lower(static_cast<int>(k));
    ub[k] = arm.upper(static_cast<int>(k));
    x[k] = a[static_cast<int>(k)];
  }
  nlopt_set_lower_bounds(opt, lb.data());
  nlopt_set_upper_bounds(opt, ub.data());
  nlopt_set_max_objective(opt, objective, &p);
  const double tol[2] = {1e-9, 1e-9};
  nlopt_add_equality_mconstraint(opt, 2, tip_constraint, &p, tol);
  nlopt_set_xtol_rel(opt, 1e-6);
  nlopt_set_ftol_rel(opt, 1e-7);
  nlopt_set_maxeval(opt, 100);
  double f = 0.0;
  const nlopt_result r = nlopt_optimize(opt, x.data(), &f);
  nlopt_destroy(opt);
  if (r < 0 && r != NLOPT_ROUNDOFF_LIMITED) return -1.0;
  ArmVector b = Eigen::Map<const Eigen::VectorXd>(x.data(), n);
  for (int k = 0; k < arm.moving(); ++k) b[k] = std::clamp(b[k], arm.lower(k), arm.upper(k));
  // SLSQP keeps the constraint to its tolerance; finish on the node exactly.
  if (!pull_onto(arm, data, target, b)) return -1.0;
  a = b;
  return area(a, pattern);
}

// The other moving joints of a with the last one at `last` (Newton on the tip, damped least
// squares, the last joint held); true when a ends on target within the ranges.
bool solve_with_last_fixed(const PlanarArm& arm, dynamics::KinematicsData& data,
                           const Eigen::Vector2d& target, double last, ArmVector& a) {
  const int m = arm.moving();
  a[m - 1] = last;
  ArmJacobian j;
  ArmJacobian js;
  Eigen::Vector2d err = target - arm.tip(a, data);
  for (int it = 0; it < 40 && err.norm() >= 1e-10; ++it) {
    arm.jacobian(a, data, j);
    js = j.leftCols(m - 1);
    const Eigen::Matrix2d jjt = js * js.transpose() + 1e-9 * Eigen::Matrix2d::Identity();
    const Eigen::Vector2d y = jjt.ldlt().solve(err);
    double norm2 = 0.0;
    for (int k = 0; k + 1 < m; ++k) norm2 += std::pow(js.col(k).dot(y), 2);
    // At most 0.5 rad a step: keeps Newton in its basin.
    const double scale = norm2 > 0.25 ? 0.5 / std::sqrt(norm2) : 1.0;
    for (int k = 0; k + 1 < m; ++k) a[k] += scale * js.col(k).dot(y);
    err = target - arm.tip(a, data);
  }
  if (!(err.norm() < kTipTolerance_m)) return false;
  for (int k = 0; k + 1 < m; ++k) {
    if (arm.model().joints[at(arm.joint(k))].type == dynamics::JointType::kRevolute) {
      a[k] = std::remainder(a[k], 2.0 * M_PI);  // the same posture, nearest zero
      if (a[k] < arm.lower(k)) a[k] += 2.0 * M_PI;
      if (a[k] > arm.upper(k)) a[k] -= 2.0 * M_PI;
    }
    if (a[k] < arm.lower(k) - 1e-12 || a[k] > arm.upper(k) + 1e-12) return false;
  }
  return true;
}

// The polytope area is not smooth (its vertices change), and SLSQP can stop at a kink. A pattern
// search along the arm's self-motion (the last joint stepped, the others solved onto the node)
// from a, steps from 0.14 (8 degrees; metres on a prismatic last joint, the K70M's extension)
// halved down to 1/64 of that (1/8 degree); a and its area updated when it finds more.
void polish_along_last(const PlanarArm& arm, PolytopeArea& area, dynamics::KinematicsData& data,
                       const mhsb::ModePattern& pattern, const Eigen::Vector2d& target,
                       ArmVector& a, double& best) {
  const int last = arm.moving() - 1;
  ArmVector b = a;
  for (double step = 8.0 * M_PI / 180.0; step > M_PI / 180.0 / 16.0; step *= 0.5) {
    for (bool moved = true; moved;) {
      moved = false;
      for (const double dir : {1.0, -1.0}) {
        const double q = a[last] + dir * step;
        if (q < arm.lower(last) || q > arm.upper(last)) continue;
        b = a;
        if (!solve_with_last_fixed(arm, data, target, q, b)) continue;
        const double s = area(b, pattern);
        if (s > best * (1.0 + 1e-9)) {
          a = b;
          best = s;
          moved = true;
          break;
        }
      }
    }
  }
}

}  // namespace

int WorkspaceGrid::node_at(int ix, int iz) const {
  const int i = ix - ix0, k = iz - iz0;
  if (i < 0 || k < 0 || i >= nx || k >= nz) return -1;
  return node_of_cell[at(i + nx * k)];
}

int WorkspaceGrid::nearest_node(const Eigen::Vector2d& xz, double max_distance_m) const {
  const int ix = static_cast<int>(std::lround(xz.x() / spacing_m));
  const int iz = static_cast<int>(std::lround(xz.y() / spacing_m));
  const int reach = static_cast<int>(std::ceil(max_distance_m / spacing_m)) + 1;
  int best = -1;
  double best_d = max_distance_m;
  for (int dk = -reach; dk <= reach; ++dk) {
    for (int di = -reach; di <= reach; ++di) {
      const int node = node_at(ix + di, iz + dk);
      if (node < 0) continue;
      const double d = (node_xz[at(node)] - xz).norm();
      if (d <= best_d) {
        best_d = d;
        best = node;
      }
    }
  }
  return best;
}

int WorkspaceGrid::neighbour(int node, int d) const {
  static constexpr int kDi[8] = {1, 1, 0, -1, -1, -1, 0, 1};
  static constexpr int kDk[8] = {0, 1, 1, 1, 0, -1, -1, -1};
  return node_at(node_i[at(node)] + kDi[d], node_k[at(node)] + kDk[d]);
}

std::vector<mhsb::ModePattern> planner_patterns(const PlanarArm& arm) {
  const auto& model = arm.model();
  if (model.mhsb) return mhsb::mode_patterns(arm.moving(), model.mhsb->modules);
  mhsb::ModePattern all_n;
  all_n.dof = arm.moving();
  return {all_n};
}

mhsb::ModePattern full_pattern(const PlanarArm& arm, const mhsb::ModePattern& moving) {
  mhsb::ModePattern p;
  p.dof = arm.model().dof();
  for (int k = 0; k < arm.moving(); ++k) p.mode[at(arm.joint(k))] = moving.mode[at(k)];
  return p;
}

double arm_reach_m(const PlanarArm& arm) {
  double reach = 0.0;
  for (int k = 0; k < arm.moving(); ++k) {
    const auto& j = arm.model().joints[at(arm.joint(k))];
    reach += std::abs(j.a_m) + (j.type == dynamics::JointType::kPrismatic
                                    ? std::max(std::abs(j.q_min), std::abs(j.q_max))
                                    : 0.0);
  }
  return reach;
}

double grid_cells(const PlanarArm& arm, double spacing_m) {
  const double side = 2.0 * arm_reach_m(arm) / spacing_m;
  return side * side;
}

double default_spacing(const PlanarArm& arm) {
  const double reach = arm_reach_m(arm);
  if (reach <= 2.0) return 0.05;
  return std::ceil(reach / 40.0 / 0.05 - 1e-9) * 0.05;
}

PolytopeArea::PolytopeArea(const PlanarArm& arm) : arm_(&arm), polytope_(arm.moving(), 2) {}

double PolytopeArea::operator()(const ArmVector& a, const mhsb::ModePattern& pattern) {
  const auto& model = arm_->model();
  const dynamics::JointVector q = arm_->full(a);
  dynamics::JointVector dc_dq, effort, force(model.dof());
  dynamics::cylinder_arms(model, q, dc_dq);
  PlanarArm::Statics s;
  arm_->statics(a, data_, s);
  force.setZero();
  for (int k = 0; k < arm_->moving() && !ignore_load_; ++k) force[arm_->joint(k)] = s.force_n[k];
  mhsb::mhsb_joint_velocity_set(model, q, dc_dq, force, pattern, {}, full_set_);
  arm_->restrict_set(full_set_, set_);
  ArmJacobian j;
  arm_->jacobian(a, data_, j);
  dynamics::TaskMatrix task = j;
  polytope_.update(set_, task);
  polytope_.build_hull();
  return polytope_.area();
}

Workspace sample_workspace(const PlanarArm& arm, const PostureTableSettings& settings) {
  const double h = settings.spacing_m > 0.0 ? settings.spacing_m : default_spacing(arm);
  const int m = arm.moving();
  // Samples per joint: one joint's step moves the tip by at most h/2 (the speed bound with unit
  // cylinder speeds times the smallest torque arm is the reach beyond the joint).
  std::vector<int> steps(at(m));
  for (int k = 0; k < m; ++k) {
    ArmVector unit = ArmVector::Zero(m);
    unit[k] = 1.0;
    const auto& c = arm.model().cylinders[at(arm.joint(k))];
    double arm_min = kInf;
    for (int s = 0; s <= 400; ++s) {
      arm_min = std::min(arm_min, std::abs(dynamics::cylinder_arm(
                                      c, arm.lower(k) + (arm.upper(k) - arm.lower(k)) * s / 400)));
    }
    const double reach = arm.tip_speed_bound(unit) * arm_min;
    steps[at(k)] = std::clamp(
        static_cast<int>(std::ceil(reach * (arm.upper(k) - arm.lower(k)) / (0.5 * h))), 8, 160);
  }
  // The last joint sliced at least as finely as the seeds ask.
  steps[at(m - 1)] = std::max(steps[at(m - 1)], 2 * std::max(1, settings.seeds_per_node));
  // Per cell hit by a sample, the sample nearest its node in each slice of the last joint.
  const int slices = std::max(1, settings.seeds_per_node);
  struct Seed {
    double distance = kInf;
    ArmVector a;
  };
  std::unordered_map<long long, std::vector<Seed>> cells;
  auto key = [](long long ix, long long iz) { return (ix << 32) ^ (iz & 0xffffffffLL); };
  dynamics::KinematicsData data;
  std::vector<int> idx(at(m), 0);
  ArmVector a(m);
  for (bool more = true; more;) {
    for (int k = 0; k < m; ++k) {
      a[k] = arm.lower(k) + (arm.upper(k) - arm.lower(k)) * idx[at(k)] / steps[at(k)];
    }
    const Eigen::Vector2d tip = arm.tip(a, data);
    const long long ix = std::llround(tip.x() / h), iz = std::llround(tip.y() / h);
    const Eigen::Vector2d node(static_cast<double>(ix) * h, static_cast<double>(iz) * h);
    constexpr double kEdge = 1e-9;  // a node on the region's edge is in it, rounding aside
    const bool inside =
        !settings.region ||
        ((*settings.region)[0] - kEdge <= node.x() && node.x() <= (*settings.region)[2] + kEdge &&
         (*settings.region)[1] - kEdge <= node.y() && node.y() <= (*settings.region)[3] + kEdge);
    if (inside) {
      auto& slot = cells[key(ix, iz)];
      if (slot.empty()) slot.resize(at(slices));
      const int slice = std::min(slices - 1, idx[at(m - 1)] * slices / (steps[at(m - 1)] + 1));
      Seed& seed = slot[at(slice)];
      const double d = (tip - node).norm();
      if (d < seed.distance) seed = {d, a};
    }
    more = false;
    for (int k = 0; k < m && !more; ++k) {
      if (++idx[at(k)] <= steps[at(k)]) {
        more = true;
      } else {
        idx[at(k)] = 0;
      }
    }
  }
  // Pull the seeds onto their nodes; a node none reaches is dropped.
  struct Candidate {
    long long ix, iz;
    std::vector<ArmVector> starts;
  };
  std::vector<Candidate> found;
  for (auto& [cell_key, slot] : cells) {
    Candidate c{0, 0, {}};
    for (Seed& seed : slot) {
      if (!(seed.distance < kInf)) continue;
      const Eigen::Vector2d tip = arm.tip(seed.a, data);
      c.ix = std::llround(tip.x() / h);
      c.iz = std::llround(tip.y() / h);
      ArmVector s = seed.a;
      const Eigen::Vector2d node(static_cast<double>(c.ix) * h, static_cast<double>(c.iz) * h);
      if (!pull_onto(arm, data, node, s)) continue;
      bool distinct = true;
      for (const auto& other : c.starts) distinct = distinct && (other - s).norm() > 1e-3;
      if (distinct) c.starts.push_back(s);
    }
    if (!c.starts.empty()) found.push_back(std::move(c));
  }
  // Number the nodes row by row (deterministic whatever the hash map's order).
  std::sort(found.begin(), found.end(), [](const Candidate& l, const Candidate& r) {
    return l.iz != r.iz ? l.iz < r.iz : l.ix < r.ix;
  });
  Workspace w;
  WorkspaceGrid& g = w.grid;
  g.spacing_m = h;
  if (found.empty()) return w;
  long long ix_min = found[0].ix, ix_max = found[0].ix, iz_min = found[0].iz, iz_max = found[0].iz;
  for (const auto& c : found) {
    ix_min = std::min(ix_min, c.ix);
    ix_max = std::max(ix_max, c.ix);
    iz_min = std::min(iz_min, c.iz);
    iz_max = std::max(iz_max, c.iz);
  }
  g.ix0 = static_cast<int>(ix_min);
  g.iz0 = static_cast<int>(iz_min);
  g.nx = static_cast<int>(ix_max - ix_min + 1);
  g.nz = static_cast<int>(iz_max - iz_min + 1);
  g.node_of_cell.assign(at(g.nx * g.nz), -1);
  for (auto& c : found) {
    const int i = static_cast<int>(c.ix - ix_min), k = static_cast<int>(c.iz - iz_min);
    g.node_of_cell[at(i + g.nx * k)] = g.nodes();
    g.node_i.push_back(static_cast<int>(c.ix));
    g.node_k.push_back(static_cast<int>(c.iz));
    g.node_xz.emplace_back(static_cast<double>(c.ix) * h, static_cast<double>(c.iz) * h);
    w.starts.push_back(std::move(c.starts));
  }
  return w;
}

ArmVector PostureTable::posture(int node, int pattern) const {
  return Eigen::Map<const Eigen::VectorXd>(q_.data() + entry(node, pattern) * at(moving_), moving_);
}

PostureTable PostureTable::empty(const PlanarArm& arm, const PostureTableSettings& settings,
                                 std::uint64_t fingerprint, Workspace& workspace) {
  PostureTable t;
  t.moving_ = arm.moving();
  t.fingerprint_ = fingerprint;
  t.patterns_ = planner_patterns(arm);
  if (settings.max_patterns > 0 && settings.max_patterns < t.pattern_count()) {
    t.patterns_.resize(at(settings.max_patterns));
  }
  workspace = sample_workspace(arm, settings);
  t.grid_ = workspace.grid;
  const int nodes = t.grid_.nodes(), np = t.pattern_count();
  t.q_.assign(at(nodes * np * t.moving_), 0.0);
  t.area_.assign(at(nodes * np), 0.0);
  return t;
}

PostureTable PostureTable::build(const PlanarArm& arm, const PostureTableSettings& settings,
                                 const std::function<void(int, int)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  Workspace w;
  PostureTable t = empty(arm, settings, posture_table_fingerprint(arm, settings), w);
  const int nodes = t.grid_.nodes(), np = t.pattern_count(), m = t.moving_;
  std::vector<mhsb::ModePattern> full;
  for (const auto& p : t.patterns_) full.push_back(full_pattern(arm, p));
  const double tolerance = std::max(0.0, settings.continuity_tolerance);

  // Per entry the local optima found (with the best start), by the area compared: the true one,
  // or for a degenerate entry the load-free one.
  struct Candidate {
    ArmVector a;
    double area;
  };
  std::vector<std::vector<Candidate>> candidates(at(nodes * np));
  std::vector<char> degenerate_entry(at(nodes * np), 0);
  std::atomic<long> runs{0}, unconverged{0}, degenerate{0}, continued{0};

  // Pass 1, in parallel over nodes: SLSQP from the best starts of each node and pattern.
  std::atomic<int> next{0};
  std::mutex progress_mutex;
  int done = 0;
  auto optimise_nodes = [&] {
    PolytopeArea area(arm);
    dynamics::KinematicsData data;
    std::vector<std::pair<double, int>> ranked;
    for (int node; (node = next.fetch_add(1)) < nodes;) {
      const auto& starts = w.starts[at(node)];
      const Eigen::Vector2d target = t.grid_.node_xz[at(node)];
      for (int p = 0; p < np; ++p) {
        auto& found = candidates[t.entry(node, p)];
        // The best of the starts, then SLSQP from the best few; the best area found.
        const auto optimise = [&] {
          found.clear();
          ranked.clear();
          for (std::size_t s = 0; s < starts.size(); ++s) {
            ranked.emplace_back(area(starts[s], full[at(p)]), static_cast<int>(s));
          }
          std::sort(ranked.begin(), ranked.end(), std::greater<>());
          found.push_back({starts[at(ranked[0].second)], ranked[0].first});
          double best_area = ranked[0].first;
          bool converged = false;
          const int tries = std::min(static_cast<int>(ranked.size()), settings.refined_starts);
          for (int r = 0; r < tries; ++r) {
            ArmVector a = starts[at(ranked[at(r)].second)];
            const double s = maximise(arm, area, data, full[at(p)], target, a);
            runs.fetch_add(1);
            if (s < 0.0) continue;
            converged = true;
            found.push_back({a, s});
            best_area = std::max(best_area, s);
          }
          // The best found, polished along the self-motion (one more candidate when it gains).
          const auto best = std::max_element(
              found.begin(), found.end(),
              [](const Candidate& l, const Candidate& r) { return l.area < r.area; });
          ArmVector a = best->a;
          double s = best->area;
          polish_along_last(arm, area, data, full[at(p)], target, a, s);
          if (s > best_area) {
            found.push_back({a, s});
            best_area = s;
          }
          return std::pair{converged, best_area};
        };
        auto [converged, best_area] = optimise();
        if (!(best_area > kDegenerateArea)) {
          // No posture lets every joint move both ways in this pattern (a joint cannot hold its
          // load from its mode's supply anywhere): the posture of the largest polytope without
          // the load instead, a well-defined one (the stored area stays the true one).
          area.set_ignore_load(true);
          converged = optimise().first;
          area.set_ignore_load(false);
          degenerate_entry[t.entry(node, p)] = 1;
          degenerate.fetch_add(1);
        }
        if (!converged) unconverged.fetch_add(1);
      }
      if (progress) {
        std::lock_guard lock(progress_mutex);
        progress(++done, nodes);
      }
    }
  };

  // Pass 2, in parallel over patterns: each swept over the nodes in their numbering (row by row
  // from the lowest, each in increasing X), so a node's W, SW, S and SE neighbours are done
  // before it. SLSQP also runs from the postures of the first two of them (in the order S, W, SW,
  // SE) pulled onto the node; of the candidates within the tolerance of the best, the one nearest
  // the done neighbours' postures (joint differences as fractions of the joints' ranges) is kept.
  std::vector<double> range(at(m));
  for (int k = 0; k < m; ++k) range[at(k)] = std::max(arm.upper(k) - arm.lower(k), 1e-9);
  const auto distance = [&](const ArmVector& a, const ArmVector& b) {
    double d2 = 0.0;
    for (int k = 0; k < m; ++k) d2 += std::pow((a[k] - b[k]) / range[at(k)], 2);
    return std::sqrt(d2);
  };
  std::atomic<int> next_pattern{0};
  auto sweep_patterns = [&] {
    PolytopeArea area(arm);
    dynamics::KinematicsData data;
    std::vector<ArmVector> done_neighbours, seeds;
    for (int p; (p = next_pattern.fetch_add(1)) < np;) {
      for (int node = 0; node < nodes; ++node) {
        const std::size_t e = t.entry(node, p);
        auto& found = candidates[e];
        const bool load_free = degenerate_entry[e] != 0;
        done_neighbours.clear();
        seeds.clear();
        for (const int d : {6, 4, 5, 7}) {  // S, W, SW, SE
          const int n = t.grid_.neighbour(node, d);
          if (n < 0) continue;
          done_neighbours.push_back(t.posture(n, p));
          if (seeds.size() < 2) seeds.push_back(done_neighbours.back());  // the first two
        }
        if (tolerance > 0.0) {
          area.set_ignore_load(load_free);
          const Eigen::Vector2d target = t.grid_.node_xz[at(node)];
          for (ArmVector a : seeds) {
            if (!pull_onto(arm, data, target, a)) continue;
            const double s = maximise(arm, area, data, full[at(p)], target, a);
            runs.fetch_add(1);
            if (s >= 0.0) found.push_back({a, s});
          }
          area.set_ignore_load(false);
        }
        std::size_t best = 0;
        for (std::size_t c = 1; c < found.size(); ++c) {
          if (found[c].area > found[best].area) best = c;
        }
        std::size_t chosen = best;
        if (tolerance > 0.0 && !done_neighbours.empty()) {
          double nearest = kInf;
          for (std::size_t c = 0; c < found.size(); ++c) {
            if (found[c].area < (1.0 - tolerance) * found[best].area) continue;
            double d = 0.0;
            for (const auto& q : done_neighbours) d += distance(found[c].a, q);
            if (d < nearest) {
              nearest = d;
              chosen = c;
            }
          }
        }
        if (distance(found[chosen].a, found[best].a) > 0.01) continued.fetch_add(1);
        const ArmVector& q = found[chosen].a;
        for (int k = 0; k < m; ++k) t.q_[e * at(m) + at(k)] = q[k];
        t.area_[e] = load_free ? area(q, full[at(p)]) : found[chosen].area;
        std::vector<Candidate>().swap(found);
      }
    }
  };

  const int threads = std::clamp(settings.threads, 1, 64);
  for (const auto& work :
       {std::function<void()>(optimise_nodes), std::function<void()>(sweep_patterns)}) {
    std::vector<std::thread> pool;
    for (int i = 1; i < threads; ++i) pool.emplace_back(work);
    work();
    for (auto& th : pool) th.join();
  }
  t.optimisations = runs.load();
  t.unconverged = unconverged.load();
  t.degenerate = degenerate.load();
  t.continued = continued.load();
  t.build_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
}

int PostureTable::neighbour_pairs() const {
  int pairs = 0;
  for (int n = 0; n < grid_.nodes(); ++n) {
    for (int d = 0; d < 4; ++d) pairs += grid_.neighbour(n, d) >= 0 ? 1 : 0;
  }
  return pairs;
}

int PostureTable::jumps(const PlanarArm& arm, int pattern, double fraction) const {
  int count = 0;
  for (int n = 0; n < grid_.nodes(); ++n) {
    const ArmVector a = posture(n, pattern);
    for (int d = 0; d < 4; ++d) {  // E, NE, N, NW: every pair once
      const int o = grid_.neighbour(n, d);
      if (o < 0) continue;
      const ArmVector b = posture(o, pattern);
      bool jump = false;
      for (int k = 0; k < moving_; ++k) {
        jump = jump || std::abs(a[k] - b[k]) > fraction * (arm.upper(k) - arm.lower(k));
      }
      count += jump ? 1 : 0;
    }
  }
  return count;
}

PostureTable PostureTable::fixed_last_joint(const PlanarArm& arm,
                                            const PostureTableSettings& settings, double last_joint,
                                            double step) {
  const auto t0 = std::chrono::steady_clock::now();
  const int m = arm.moving();
  if (m < 2) throw std::invalid_argument("a fixed last joint needs at least two moving joints");
  if (arm.model().joints[at(arm.joint(m - 1))].type != dynamics::JointType::kRevolute) {
    throw std::invalid_argument("the last moving joint (" +
                                arm.model().joints[at(arm.joint(m - 1))].name +
                                ") is not revolute");
  }
  if (!(last_joint >= arm.lower(m - 1) && last_joint <= arm.upper(m - 1))) {
    char why[160];
    std::snprintf(why, sizeof why, "%.1f deg is outside %s's range [%.1f, %.1f] deg",
                  last_joint * 180.0 / M_PI, arm.model().joints[at(arm.joint(m - 1))].name.c_str(),
                  arm.lower(m - 1) * 180.0 / M_PI, arm.upper(m - 1) * 180.0 / M_PI);
    throw std::invalid_argument(why);
  }
  if (!(step > 0.0)) throw std::invalid_argument("the last joint's step must be positive");
  Fingerprint f;
  f.add(posture_table_fingerprint(arm, settings));
  f.add(last_joint);
  f.add(step);
  Workspace w;
  PostureTable t = empty(arm, settings, f.value(), w);
  t.optimal_ = false;
  const int nodes = t.grid_.nodes(), np = t.pattern_count();
  std::vector<mhsb::ModePattern> full;
  for (const auto& p : t.patterns_) full.push_back(full_pattern(arm, p));

  PolytopeArea area(arm);
  dynamics::KinematicsData data;
  ArmVector reference = arm.moving_part(arm.q_hold());
  reference[m - 1] = last_joint;
  const int max_steps =
      static_cast<int>(std::ceil((arm.upper(m - 1) - arm.lower(m - 1)) / step)) + 1;
  for (int node = 0; node < nodes; ++node) {
    const Eigen::Vector2d target = t.grid_.node_xz[at(node)];
    const auto& starts = w.starts[at(node)];
    // For the last joint at `last`, the solution whose middle joints bend most the way the last
    // one does, then the nearest the reference, if any.
    const auto solve = [&](double last, ArmVector& out) {
      bool found = false;
      double best = kInf;
      for (std::size_t s = 0; s <= starts.size(); ++s) {
        ArmVector a = s < starts.size() ? starts[s] : reference;
        if (!solve_with_last_fixed(arm, data, target, last, a)) continue;
        int against = 0;  // middle joints bent against the last one
        for (int k = 1; k + 1 < m; ++k) against += a[k] * last < 0.0 ? 1 : 0;
        const double d = 100.0 * against + (a - reference).head(m - 1).norm();
        if (d < best) {
          best = d;
          out = a;
          found = true;
        }
      }
      return found;
    };
    ArmVector q;
    bool found = false;
    for (int s = 0; s <= max_steps && !found; ++s) {
      for (const double sign : {1.0, -1.0}) {
        const double last = last_joint + sign * s * step;
        if (found || (s == 0 && sign < 0.0) || last < arm.lower(m - 1) || last > arm.upper(m - 1)) {
          continue;
        }
        found = solve(last, q);
      }
    }
    if (!found) {
      // The solver missed every angle (it should not: the node has starts): the start whose last
      // joint is nearest the fixed one.
      q = starts.front();
      for (const auto& s : starts) {
        if (std::abs(s[m - 1] - last_joint) < std::abs(q[m - 1] - last_joint)) q = s;
      }
    }
    if (std::abs(q[m - 1] - last_joint) > 1e-12) ++t.moved_last_joint;
    for (int p = 0; p < np; ++p) {
      const std::size_t e = t.entry(node, p);
      for (int k = 0; k < m; ++k) t.q_[e * at(m) + at(k)] = q[k];
      t.area_[e] = area(q, full[at(p)]);
    }
  }
  t.build_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
}

void PostureTable::write(std::ostream& out) const {
  auto put = [&](const auto& v) { out.write(reinterpret_cast<const char*>(&v), sizeof v); };
  out.write(kMagic, sizeof kMagic);
  put(fingerprint_);
  put(moving_);
  put(grid_.spacing_m);
  put(grid_.ix0);
  put(grid_.iz0);
  put(grid_.nx);
  put(grid_.nz);
  put(grid_.nodes());
  put(pattern_count());
  for (int n = 0; n < grid_.nodes(); ++n) {
    put(grid_.node_i[at(n)]);
    put(grid_.node_k[at(n)]);
  }
  for (const auto& p : patterns_) {
    for (int k = 0; k < moving_; ++k) put(static_cast<std::uint8_t>(p.mode[at(k)]));
  }
  out.write(reinterpret_cast<const char*>(q_.data()),
            static_cast<std::streamsize>(q_.size() * sizeof(double)));
  out.write(reinterpret_cast<const char*>(area_.data()),
            static_cast<std::streamsize>(area_.size() * sizeof(double)));
}

void PostureTable::save(const std::filesystem::path& file) const {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  // A temporary file of this process's own (two runs may build the same table at once), then
  // a rename: a reader sees the old file or the whole new one.
  const auto tmp = file.string() + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary);
    write(out);
    if (!out) throw std::runtime_error(file.string() + ": cannot write the posture table");
  }
  std::filesystem::rename(tmp, file);
}

std::optional<PostureTable> PostureTable::load(const std::filesystem::path& file,
                                               const PlanarArm& arm,
                                               const PostureTableSettings& settings) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  return read(in, arm, settings);
}

std::optional<PostureTable> PostureTable::read(std::istream& in, const PlanarArm& arm,
                                               const PostureTableSettings& settings) {
  char magic[sizeof kMagic];
  in.read(magic, sizeof magic);
  if (!in || std::memcmp(magic, kMagic, sizeof kMagic) != 0) return std::nullopt;
  auto get = [&](auto& v) {
    in.read(reinterpret_cast<char*>(&v), sizeof v);
    return static_cast<bool>(in);
  };
  PostureTable t;
  int nodes = 0, np = 0;
  get(t.fingerprint_);
  get(t.moving_);
  get(t.grid_.spacing_m);
  get(t.grid_.ix0);
  get(t.grid_.iz0);
  get(t.grid_.nx);
  get(t.grid_.nz);
  get(nodes);
  if (!get(np)) return std::nullopt;
  // What the table must be for this arm and these settings (the fingerprint says it was made
  // for them; a damaged file can still say anything after it).
  std::vector<mhsb::ModePattern> patterns = planner_patterns(arm);
  if (settings.max_patterns > 0 && settings.max_patterns < static_cast<int>(patterns.size())) {
    patterns.resize(at(settings.max_patterns));
  }
  const double spacing = settings.spacing_m > 0.0 ? settings.spacing_m : default_spacing(arm);
  const long long cells = static_cast<long long>(t.grid_.nx) * t.grid_.nz;
  if (t.fingerprint_ != posture_table_fingerprint(arm, settings) || t.moving_ != arm.moving() ||
      t.grid_.spacing_m != spacing || np != static_cast<int>(patterns.size()) || nodes < 0 ||
      t.grid_.nx < 0 || t.grid_.nz < 0 || cells > 100'000'000LL || nodes > cells ||
      std::abs(static_cast<long long>(t.grid_.ix0)) > 1'000'000'000LL ||
      std::abs(static_cast<long long>(t.grid_.iz0)) > 1'000'000'000LL) {
    return std::nullopt;
  }
  t.grid_.node_of_cell.assign(static_cast<std::size_t>(cells), -1);
  for (int n = 0; n < nodes; ++n) {
    int i = 0, k = 0;
    get(i);
    if (!get(k)) return std::nullopt;
    const long long ci = static_cast<long long>(i) - t.grid_.ix0;
    const long long ck = static_cast<long long>(k) - t.grid_.iz0;
    if (ci < 0 || ck < 0 || ci >= t.grid_.nx || ck >= t.grid_.nz) return std::nullopt;
    int& cell = t.grid_.node_of_cell[static_cast<std::size_t>(ci + t.grid_.nx * ck)];
    if (cell != -1) return std::nullopt;  // two nodes on one cell
    cell = n;
    t.grid_.node_i.push_back(i);
    t.grid_.node_k.push_back(k);
    t.grid_.node_xz.emplace_back(i * t.grid_.spacing_m, k * t.grid_.spacing_m);
  }
  for (const mhsb::ModePattern& expected : patterns) {
    for (int k = 0; k < t.moving_; ++k) {
      std::uint8_t mode = 0;
      if (!get(mode) || mode != static_cast<std::uint8_t>(expected.mode[at(k)])) {
        return std::nullopt;
      }
    }
  }
  t.patterns_ = std::move(patterns);
  const std::size_t entries = static_cast<std::size_t>(nodes) * static_cast<std::size_t>(np);
  t.q_.resize(entries * static_cast<std::size_t>(t.moving_));
  t.area_.resize(entries);
  in.read(reinterpret_cast<char*>(t.q_.data()),
          static_cast<std::streamsize>(t.q_.size() * sizeof(double)));
  in.read(reinterpret_cast<char*>(t.area_.data()),
          static_cast<std::streamsize>(t.area_.size() * sizeof(double)));
  if (!in || in.peek() != std::char_traits<char>::eof()) return std::nullopt;
  // Every posture within the joint ranges with the tip on its node (within 0.1 mm), every area a
  // finite non-negative number.
  dynamics::KinematicsData data;
  for (int n = 0; n < nodes; ++n) {
    for (int p = 0; p < np; ++p) {
      const std::size_t e = t.entry(n, p);
      if (!(std::isfinite(t.area_[e]) && t.area_[e] >= 0.0)) return std::nullopt;
      for (int k = 0; k < t.moving_; ++k) {
        const double q = t.q_[e * static_cast<std::size_t>(t.moving_) + at(k)];
        const double slack = 1e-9 * (1.0 + arm.upper(k) - arm.lower(k));
        if (!(q >= arm.lower(k) - slack && q <= arm.upper(k) + slack)) return std::nullopt;
      }
      if (!((arm.tip(t.posture(n, p), data) - t.grid_.node_xz[at(n)]).norm() <= 1e-4)) {
        return std::nullopt;
      }
    }
  }
  return t;
}

std::uint64_t posture_table_fingerprint(const PlanarArm& arm,
                                        const PostureTableSettings& settings) {
  Fingerprint f;
  f.add(4);  // the table's own version: bump when the build changes
  const auto& m = arm.model();
  for (const auto& j : m.joints) {
    f.add(static_cast<int>(j.type));
    for (double v : {j.a_m, j.alpha_rad, j.d_m, j.theta_rad, j.q_min, j.q_max}) f.add(v);
  }
  for (const auto& c : m.cylinders) {
    f.add(static_cast<int>(c.linkage));
    for (double v : {c.arm_m, c.c0_m, c.l1_m, c.l2_m, c.angle_offset_rad, c.area_a_m2, c.area_b_m2,
                     c.stroke_m, c.v_max_m_s}) {
      f.add(v);
    }
    f.add(c.differential_spool ? 1 : 0);
    for (double v : c.poly_coeffs) f.add(v);
  }
  for (const auto& b : m.bodies) {
    f.add(b.frame);
    f.add(b.mass_kg);
    for (int i = 0; i < 3; ++i) f.add(b.com_m[i]);
  }
  for (int i = 0; i < 3; ++i) f.add(m.gravity_m_s2[i]);
  for (int i = 0; i < 9; ++i) f.add(m.task_from_base(i / 3, i % 3));
  for (double v : {m.pump.supply_pressure_pa, m.pump.max_flow_m3_s, m.pump.max_pressure_pa}) {
    f.add(v);
  }
  if (m.mhsb) {
    const auto& h = *m.mhsb;
    f.add(h.modules);
    for (double v :
         {h.servo_pump_max_flow_m3_s, h.max_boost_pa, h.servo_pump_efficiency, h.tank_pressure_pa,
          h.valve.rated_flow_m3_s, h.valve.rated_pressure_drop_pa, h.valve.leakage_m3_s}) {
      f.add(v);
    }
  }
  for (int i = 0; i < m.dof(); ++i) {
    bool moving = false;
    for (int k = 0; k < arm.moving(); ++k) moving = moving || arm.joint(k) == i;
    if (!moving) f.add(arm.q_hold()[i]);
  }
  f.add(settings.spacing_m > 0.0 ? settings.spacing_m : default_spacing(arm));
  f.add(settings.seeds_per_node);
  f.add(settings.refined_starts);
  f.add(settings.max_patterns);
  // Only when set: the default table is the one built before the setting existed.
  if (settings.continuity_tolerance > 0.0) f.add(settings.continuity_tolerance);
  if (settings.region) {
    for (int i = 0; i < 4; ++i) f.add((*settings.region)[i]);
  }
  return f.value();
}

std::optional<std::filesystem::path> default_table_file(const PlanarArm& arm,
                                                        const PostureTableSettings& settings) {
  std::filesystem::path dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg != '\0') {
    dir = xdg;
  } else if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') {
    dir = std::filesystem::path(home) / ".cache";
  } else {
    return std::nullopt;
  }
  char name[64];
  std::snprintf(name, sizeof name, "ptp-table-%016llx.bin",
                static_cast<unsigned long long>(posture_table_fingerprint(arm, settings)));
  return dir / "craneassist" / name;
}

}  // namespace craneassist::planner
