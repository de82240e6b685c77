#include "craneassist/studies/polytope_report.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/control/controller.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/scaling/tip_path.hpp"

namespace craneassist::studies {
namespace {

// What bounds the speed along the joint direction f: the largest share of a limit f uses.
std::string limit_of(const dynamics::CraneModel& model, const dynamics::JointVelocitySet& set,
                     const dynamics::JointVector& f) {
  double worst = 0.0;
  std::string name;
  double flow = 0.0;
  for (int i = 0; i < model.dof(); ++i) {
    const double bound = f[i] > 0.0 ? set.qdot_max[i] : -set.qdot_min[i];
    flow += f[i] > 0.0 ? set.flow_positive_m3[i] * f[i] : -set.flow_negative_m3[i] * f[i];
    if (std::abs(f[i]) <= 1e-12) continue;
    const auto& joint = model.joints[static_cast<std::size_t>(i)];
    if (bound == 0.0) return joint.name + " at its end";
    if (std::abs(f[i]) / bound > worst) {
      worst = std::abs(f[i]) / bound;
      name = joint.name + " cylinder speed";
    }
  }
  if (flow / set.max_flow_m3_s > worst) name = "pump flow";
  return name;
}

}  // namespace

PolytopeReport polytope_report(const config::CraneConfig& cfg, const dynamics::JointVector& q,
                               const std::vector<Eigen::Vector3d>& directions,
                               std::optional<double> intended_speed_m_s,
                               std::optional<mhsb::ModePattern> modes) {
  const auto& model = cfg.model;
  const int n = model.dof();
  PolytopeReport r;
  r.plane = dynamics::planar_task_basis(model);
  r.task_dim = r.plane ? 2 : 3;
  if (r.plane) {
    for (int row = 0; row < 2; ++row) {
      r.axis_names[static_cast<std::size_t>(row)] = "a" + std::to_string(row + 1);
      for (int axis = 0; axis < 3; ++axis) {
        if ((*r.plane)(row, axis) == 1.0) {
          r.axis_names[static_cast<std::size_t>(row)] =
              std::string(1, static_cast<char>('x' + axis));
        }
      }
    }
    r.axis_names[2] = "";
  }
  r.flow_reserve = cfg.control.flow_reserve;
  r.resolution = dynamics::to_string(cfg.redundancy.resolution);

  dynamics::JointVector arms;
  dynamics::cylinder_arms(model, q, arms);
  dynamics::KinematicsData kin;
  dynamics::TaskJacobian jacobian;
  dynamics::tip_jacobian(model, kin, q, jacobian);
  dynamics::JointVelocitySet set;
  const dynamics::FlowPolytopeSettings settings{.flow_reserve = cfg.control.flow_reserve,
                                                .cylinder_speed_reserve = cfg.control.flow_reserve};
  // Joints at an end: the plain set's (an MHSB mode may also stop a joint one way, by its load).
  dynamics::joint_velocity_set(model, q, arms, settings, set);
  for (int i = 0; i < n; ++i) {
    if (set.qdot_max[i] == 0.0 || set.qdot_min[i] == 0.0) {
      r.joints_at_end.push_back(model.joints[static_cast<std::size_t>(i)].name);
    }
  }
  if (model.mhsb) {
    // The cylinders' loads: the joint efforts that hold the arm against gravity, through the arms.
    dynamics::JointVector holding;
    dynamics::RigidBodyTerms(model).gravity(q, holding);
    r.cylinder_force_n = dynamics::JointVector::Zero(n);
    for (int i = 0; i < n; ++i) {
      if (std::abs(arms[i]) > 1e-12) r.cylinder_force_n[i] = holding[i] / arms[i];
    }
    if (!modes) {
      modes = mhsb::ModePattern{};
      modes->dof = n;
    }
    r.modes = modes;
    mhsb::mhsb_joint_velocity_set(model, q, arms, r.cylinder_force_n, *modes, settings, set);
  }
  r.max_flow_m3_s = set.max_flow_m3_s;

  const dynamics::TaskMatrix task =
      r.plane ? dynamics::TaskMatrix(*r.plane * jacobian) : dynamics::TaskMatrix(jacobian);
  dynamics::FlowPolytope poly(n, r.task_dim);
  poly.update(set, task);
  poly.build_hull();
  r.dimension = poly.dimension();
  r.volume_m3_s3 = poly.volume();
  r.area_m2_s2 = poly.area();
  r.joint_vertices = poly.point_count();
  // Sorted, so that a listing reads the same from run to run.
  std::vector<int> order(poly.hull_vertices().begin(), poly.hull_vertices().end());
  const auto points = poly.task_points();
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    const auto &pa = points[static_cast<std::size_t>(a)], &pb = points[static_cast<std::size_t>(b)];
    return std::lexicographical_compare(pa.data(), pa.data() + 3, pb.data(), pb.data() + 3);
  });
  for (const int v : order) {
    r.vertices.push_back(points[static_cast<std::size_t>(v)]);
    r.vertex_qdot.emplace_back(poly.joint_vertex(v));
  }

  if (model.mhsb) {
    dynamics::JointVelocitySet other;
    dynamics::FlowPolytope each(n, r.task_dim);
    for (const auto& pattern : mhsb::mode_patterns(n, model.mhsb->modules)) {
      mhsb::mhsb_joint_velocity_set(model, q, arms, r.cylinder_force_n, pattern, settings, other);
      each.update(other, task);
      each.build_hull();
      r.pattern_measures.emplace_back(pattern, r.task_dim == 3 ? each.volume() : each.area());
    }
  }

  // The controller's resolution of each direction, fresh (no previous cycle to smooth from) and
  // with no loads known (min-ls-power then minimises the flow), as at the first cycle of a move.
  scaling::TipPath path(model, control::tip_path_config(cfg));
  for (const Eigen::Vector3d& d : directions) {
    PolytopeSpeed s;
    dynamics::TaskVector u_task(r.task_dim);
    if (r.plane) {
      u_task = *r.plane * d;
    } else {
      u_task = d;
    }
    if (!(u_task.norm() > 0.0)) continue;
    u_task.normalize();
    s.direction =
        r.plane ? Eigen::Vector3d(r.plane->transpose() * u_task) : Eigen::Vector3d(u_task);
    s.best_m_s = poly.max_speed(u_task);
    s.best_qdot = poly.max_speed_joint_velocity();
    s.intended_m_s = intended_speed_m_s.value_or(s.best_m_s);
    path.reset();
    scaling::TipPathInput in;
    in.direction = s.direction;
    in.intended_speed = s.intended_m_s;
    scaling::TipPathOutput out;
    path.update(q, in, out);
    const dynamics::JointVector& f1 = out.geometry.f1;
    s.resolved_qdot = dynamics::JointVector::Zero(n);
    if (!f1.isZero(0.0) && (jacobian * f1 - s.direction).norm() < 1e-6) {
      s.resolved_m_s = dynamics::speed_along(set, f1);
      s.resolved_limit = limit_of(model, set, f1);
      s.resolved_qdot = f1 * s.resolved_m_s;
    }
    r.speeds.push_back(s);
  }
  return r;
}

}  // namespace craneassist::studies
