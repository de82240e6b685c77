// scaling::TipScaler, the tip motion of the controller at the reference level (with TipPath, a
// machine that follows perfectly): velocity changes along the straight segment to the command,
// reversals at rest on the line, jerk-limited stops, no slow-down for a joint end while the
// others carry on, and every singular pose of the K70M approached smoothly, with every cylinder
// within its speed, and left again.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "allocation_counter.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/controller.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/pendulum.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/scaling/tip_path.hpp"
#include "craneassist/scaling/tip_scaler.hpp"

using namespace craneassist;
using dynamics::JointVector;

namespace {

// The scaling part of control::Controller::update_full, on a machine at the reference.
class TipMotion {
 public:
  explicit TipMotion(const config::CraneConfig& cfg)
      : cfg_(cfg),
        terms_(cfg_.model),
        path_(cfg_.model, control::tip_path_config(cfg_)),
        scaler_(cfg_.model, control::tip_scaler_config(cfg_), terms_),
        q(cfg_.simulation.q_initial) {}

  // One cycle; returns the reference tip velocity (J(q) qdot_ref) of the cycle. A pendulum
  // (omega > 0): the reference is shaped to it (sway damping).
  Eigen::Vector3d step(const Eigen::Vector3d& command, bool stale = false,
                       const dynamics::Pendulum& pendulum = {}) {
    const Eigen::Vector3d u = scaler_.direction(command);
    scaling::TipPathInput in;
    in.direction = u;
    in.sdot = scaler_.speed();
    in.intended_speed = stale ? in.sdot : scaler_.intended_speed(command);
    path_.update(q, in, path_out);
    scaling::TipScalerInput scaler_in = control::tip_scaler_input(command, u, path_out, stale);
    scaler_in.sway_omega_rad_s = pendulum.omega_rad_s;
    scaler_in.sway_zeta = pendulum.zeta;
    scaler_.update(q, path_out.geometry, scaler_in, out);
    const auto& g = path_out.geometry;
    for (int i = 0; i < cfg_.model.dof(); ++i) {
      const auto& joint = cfg_.model.joints[static_cast<std::size_t>(i)];
      q[i] = std::clamp(q[i] + g.f1[i] * out.ds + 0.5 * g.f2[i] * out.ds * out.ds, joint.q_min,
                        joint.q_max);
    }
    qdot = g.f1 * out.velocity.dot(u);
    return u * out.velocity.dot(u);
  }

  double period() const { return 1.0 / cfg_.control.rate_hz; }
  dynamics::RigidBodyTerms& terms() { return terms_; }

  // Largest cylinder speed of the reference over its limit (1: at the limit).
  double cylinder_speed_share() const {
    JointVector arms(cfg_.model.dof());
    dynamics::cylinder_arms(cfg_.model, q, arms);
    double worst = 0.0;
    for (int i = 0; i < cfg_.model.dof(); ++i) {
      worst = std::max(worst, std::abs(arms[i] * qdot[i]) /
                                  cfg_.model.cylinders[static_cast<std::size_t>(i)].v_max_m_s);
    }
    return worst;
  }

  Eigen::Vector3d tip() {
    dynamics::KinematicsData kin;
    return dynamics::tip_position(cfg_.model, kin, q);
  }

  scaling::TipPathOutput path_out;
  scaling::TipScalerOutput out;

 private:
  config::CraneConfig cfg_;
  dynamics::RigidBodyTerms terms_;
  scaling::TipPath path_;
  scaling::TipScaler scaler_;

 public:
  JointVector q, qdot;
};

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

const char* kResolutions[] = {"pinv-joint", "pinv-actuator", "min-flow", "min-ls-power"};

// The outer boom folded back and down (lift 0.3 rad, tilt -2.6 rad) so that the tip is over the
// slew axis, at the given radius (x, m): the extension found by bisection.
JointVector tip_over_the_slew_axis(const dynamics::CraneModel& model, double radius) {
  JointVector q(4);
  q << 0.0, 0.3, -2.6, 0.0;
  dynamics::KinematicsData kin;
  double lo = 0.0, hi = 3.7;
  for (int k = 0; k < 60; ++k) {
    q[3] = 0.5 * (lo + hi);
    (dynamics::tip_position(model, kin, q).x() > radius ? lo : hi) = q[3];
  }
  return q;
}

config::CraneConfig with_resolution(const char* r) {
  auto cfg = config::default_crane_config();
  config::set_resolution(cfg, r);
  return cfg;
}

}  // namespace

TEST(TipMotion, AReversalComesToRestOnTheLineAndLeavesAlongIt) {
  for (const char* r : kResolutions) {
    TipMotion m(with_resolution(r));
    const Eigen::Vector3d line = Eigen::Vector3d(0.4, 0.3, 0.0);
    double worst_off_line = 0.0;
    int rests = 0;
    for (int k = 0; k < 600; ++k) {
      // Out-and-up, then the exact opposite, then flicked every 0.5 s.
      const double sign = k < 200 ? 1.0 : k < 350 ? -1.0 : ((k / 50) % 2 == 0 ? 1.0 : -1.0);
      const Eigen::Vector3d v = m.step(sign * line);
      worst_off_line = std::max(worst_off_line, v.cross(line.normalized()).norm());
      EXPECT_LE(m.out.velocity.cross(line.normalized()).norm(), 1e-9) << r;
      rests += m.out.at_rest;
    }
    EXPECT_LT(worst_off_line, 1e-9) << r;
    EXPECT_GE(rests, 3) << r << ": the reversals pass through rest";
  }
}

TEST(TipMotion, ATurnRoundsInsideThePlaneOfTheTwoCommands) {
  for (const char* r : kResolutions) {
    TipMotion m(with_resolution(r));
    const Eigen::Vector3d a(0.5, 0.0, 0.0), b(0.0, 0.35, 0.35);
    const Eigen::Vector3d normal = a.cross(b).normalized();
    for (int k = 0; k < 200; ++k) m.step(a);
    ASSERT_NEAR(m.out.velocity.norm(), 0.5, 1e-9) << r;
    // From steady motion the velocity moves along the straight segment from a to b.
    const Eigen::Vector3d along = (b - a).normalized();
    int turning = 0;
    for (int k = 0; k < 200; ++k) {
      m.step(b);
      EXPECT_LT(std::abs(m.out.velocity.dot(normal)), 1e-9) << r;
      const Eigen::Vector3d d = m.out.velocity - a;
      if (d.norm() > 1e-6) {
        EXPECT_LT(d.cross(along).norm(), 1e-6 * (1.0 + d.norm())) << r << " cycle " << k;
      }
      turning += angle_deg(m.out.velocity, b) > 0.5;
    }
    EXPECT_GT(turning, 10) << r << ": the turn takes time";
    EXPECT_LT(angle_deg(m.out.velocity, b), 1e-6) << r;
  }
}

TEST(TipMotion, JerkAndAccelerationStayBounded) {
  const auto cfg = config::default_crane_config();
  TipMotion m(cfg);
  const double jerk = cfg.scaling.jerk_max_m_s3, period = m.period();
  const Eigen::Vector3d moves[] = {
      {0.6, 0.0, 0.0}, {-0.5, 0.2, 0.3}, {0.0, -0.4, 0.0}, {0.3, 0.3, -0.3}};
  Eigen::Vector3d last_a = Eigen::Vector3d::Zero();
  for (int k = 0; k < 1200; ++k) {
    m.step(moves[k / 300]);
    const Eigen::Vector3d a = m.out.acceleration;
    EXPECT_LE((a - last_a).norm(), jerk * period * (1 + 1e-9)) << "cycle " << k;
    EXPECT_LE(m.out.sdddot, jerk * (1 + 1e-9));
    last_a = a;
  }
}

TEST(TipMotion, AStaleInputStopsAlongTheDirectionAndHoldsExactlyAtRest) {
  TipMotion m(config::default_crane_config());
  const Eigen::Vector3d v(0.3, 0.2, 0.4);
  for (int k = 0; k < 200; ++k) m.step(v);
  ASSERT_GT(m.out.sdot, 0.5);
  double last_speed = m.out.sdot;
  int cycles = 0;
  while (!m.out.at_rest && cycles < 500) {
    m.step(Eigen::Vector3d::Zero(), true);
    EXPECT_EQ(m.out.limit, scaling::ActiveLimit::kStaleInput);
    EXPECT_LT(angle_deg(m.out.velocity, v), 1e-6 + (m.out.sdot == 0.0 ? 180.0 : 0.0));
    ++cycles;
  }
  EXPECT_TRUE(m.out.at_rest);
  EXPECT_GT(cycles, 10) << "a stop from speed takes time";
  EXPECT_LT(cycles, 100);
  (void)last_speed;
  const JointVector q = m.q;
  for (int k = 0; k < 50; ++k) m.step(Eigen::Vector3d::Zero(), true);
  EXPECT_TRUE(m.out.at_rest);
  EXPECT_EQ((m.q - q).norm(), 0.0) << "at rest nothing moves";
}

TEST(TipMotion, AFailedDynamicsStepStopsInsteadOfThrowing) {
  // The scaler's update cannot throw (a throw inside would end this test binary), and a failed
  // ODE step (the RigidBodyTerms test hook; on a machine: ODE out of memory) stops the reference
  // jerk-limited along its direction, with the operator still commanding motion.
  static_assert(noexcept(std::declval<scaling::TipScaler&>().update(
      std::declval<const JointVector&>(), std::declval<const scaling::PathGeometry&>(),
      std::declval<const scaling::TipScalerInput&>(), std::declval<scaling::TipScalerOutput&>())));
  static_assert(noexcept(std::declval<scaling::TipPath&>().update(
      std::declval<const JointVector&>(), std::declval<const scaling::TipPathInput&>(),
      std::declval<scaling::TipPathOutput&>())));
  const auto cfg = config::default_crane_config();
  TipMotion m(cfg);
  const double jerk = cfg.scaling.jerk_max_m_s3;
  const Eigen::Vector3d v(0.3, 0.2, 0.4);
  for (int k = 0; k < 200; ++k) m.step(v);
  ASSERT_GT(m.out.sdot, 0.5);
  ASSERT_FALSE(m.out.dynamics_failed);

  m.terms().fail_steps_for_testing(true);
  Eigen::Vector3d last_a = m.out.acceleration;
  double last_speed = m.out.sdot;
  int cycles = 0;
  while (!m.out.at_rest && cycles < 500) {
    m.step(v);  // the command stays: the failure alone stops the motion
    EXPECT_TRUE(m.out.dynamics_failed);
    EXPECT_EQ(m.out.limit, scaling::ActiveLimit::kDynamicsFailed);
    EXPECT_EQ(m.out.terms.b.norm(), 0.0) << "no terms without the dynamics";
    EXPECT_LT(angle_deg(m.out.velocity, v), 1e-6 + (m.out.sdot == 0.0 ? 180.0 : 0.0));
    EXPECT_LE((m.out.acceleration - last_a).norm(), jerk * m.period() * (1 + 1e-9));
    EXPECT_LE(m.out.sdot, last_speed + 1e-12) << "cycle " << cycles;
    last_a = m.out.acceleration;
    last_speed = m.out.sdot;
    ++cycles;
  }
  EXPECT_TRUE(m.out.at_rest);
  EXPECT_GT(cycles, 10) << "a jerk-limited stop from speed takes time";
  EXPECT_LT(cycles, 100);
  const JointVector q = m.q;
  for (int k = 0; k < 50; ++k) m.step(v);
  EXPECT_TRUE(m.out.at_rest);
  EXPECT_EQ((m.q - q).norm(), 0.0) << "held exactly at rest while the dynamics fail";

  // The dynamics back: the motion goes on.
  m.terms().fail_steps_for_testing(false);
  for (int k = 0; k < 100; ++k) m.step(v);
  EXPECT_FALSE(m.out.dynamics_failed);
  EXPECT_NE(m.out.limit, scaling::ActiveLimit::kDynamicsFailed);
  EXPECT_GT(m.out.sdot, 0.3);
}

// The tip speed along the stick from the default pose, pushing out: the reference keeps the
// commanded speed until the real edge of the workspace, where it stops smoothly (no stall and go:
// the tilt runs into its end on the way, and the other joints carry on).
TEST(TipMotion, NoSlowDownForAJointEndWhileTheOthersCarryOn) {
  for (const char* r : kResolutions) {
    TipMotion m(with_resolution(r));
    const Eigen::Vector3d v(0.6, 0.0, 0.0);
    bool reached = false, slowed = false, rested = false;
    int stalls = 0;
    double max_speed = 0.0, after_rest = 0.0;
    for (int k = 0; k < 1300; ++k) {
      m.step(v);
      const double along = m.out.velocity.dot(v.normalized());
      max_speed = std::max(max_speed, along);
      if (along > 0.59) reached = true;
      // Come (nearly) to rest at the end of the workspace, it stays there: no stop-and-go.
      if (reached && along < 0.01) rested = true;
      if (rested) after_rest = std::max(after_rest, along);
      if (reached && along < 0.3) slowed = true;
      if (slowed && along > 0.42) {
        ++stalls;
        slowed = false;
      }
      EXPECT_LE(m.cylinder_speed_share(), 1.0 + 1e-6) << r << " cycle " << k;
    }
    EXPECT_TRUE(reached) << r;
    EXPECT_EQ(stalls, 0) << r;
    EXPECT_LT(after_rest, 0.02) << r << ": restarted after coming to rest at the end";
    // It went out to (near) full reach, and is at rest there.
    EXPECT_GT(m.tip().x(), 8.8) << r;
    EXPECT_EQ(m.out.sdot, 0.0) << r;
    // Moving back in is never limited.
    for (int k = 0; k < 200; ++k) m.step(-v);
    EXPECT_NEAR(m.out.velocity.dot(-v.normalized()), 0.6, 1e-6) << r;
  }
}

// Singular poses of the K70M: the tip over the slew axis (lateral motion unreachable), the boom
// stretched with the telescope out (radial motion needs the ends the joints sit at), the telescope
// at its end with the task along it. From each, every direction: cylinders within their speeds,
// the direction kept, nothing non-finite; then the way out is free.
TEST(TipMotion, SingularPosesSlowSmoothlyAndTheOperatorCanMoveOut) {
  auto cfg = config::default_crane_config();
  const auto& model = cfg.model;
  struct Pose {
    const char* name;
    JointVector q;
    Eigen::Vector3d way_out;
  };
  // Tip over the slew axis: its radius 5 cm.
  const JointVector over_axis = tip_over_the_slew_axis(model, 0.05);
  JointVector stretched(4), telescope_out(4);
  stretched << 0.0, 0.0, -0.2501, 3.6999;
  telescope_out << 0.0, 0.35, -1.2, 3.6999;
  const Pose poses[] = {
      {"tip over the slew axis", over_axis, Eigen::Vector3d(-1, 0, 0)},
      {"boom stretched, telescope out", stretched, Eigen::Vector3d(-1, 0, 0)},
      {"telescope out along the task", telescope_out, Eigen::Vector3d(-1, -0.5, 0)}};
  for (const auto& pose : poses) {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          cfg.simulation.q_initial = pose.q;
          TipMotion m(cfg);
          const Eigen::Vector3d v = 0.5 * Eigen::Vector3d(dx, dy, dz).normalized();
          for (int k = 0; k < 250; ++k) {
            const Eigen::Vector3d ref = m.step(v);
            ASSERT_TRUE(m.q.allFinite() && m.qdot.allFinite()) << pose.name;
            EXPECT_LE(m.cylinder_speed_share(), 1.0 + 1e-6)
                << pose.name << " direction " << v.transpose() << " cycle " << k;
            if (ref.norm() > 1e-3) {
              EXPECT_LT(angle_deg(ref, v), 1.0) << pose.name << " " << v.transpose();
            }
          }
          // The way out.
          for (int k = 0; k < 300; ++k) m.step(0.5 * pose.way_out.normalized());
          EXPECT_GT(m.out.velocity.dot(pose.way_out.normalized()), 0.1)
              << pose.name << " after " << v.transpose();
        }
      }
    }
  }
}

TEST(TipMotion, LateralMotionAtTheSlewAxisSaysSingularity) {
  auto cfg = config::default_crane_config();
  cfg.simulation.q_initial = tip_over_the_slew_axis(cfg.model, 0.03);
  TipMotion m(cfg);
  // Sideways along a line that passes 3 cm from the slew axis: the slew must turn at
  // v x / (x^2 + z^2), so the tip crawls while it passes the axis and speeds up beyond.
  int near_axis = 0, singular_near_axis = 0;
  double peak_near_axis = 0.0, peak_beyond = 0.0;
  for (int k = 0; k < 300; ++k) {
    m.step(Eigen::Vector3d(0.0, 0.0, 0.5));
    const double z = m.tip().z();
    if (std::abs(z) < 0.01) {
      ++near_axis;
      singular_near_axis += m.out.limit == scaling::ActiveLimit::kSingularity;
      peak_near_axis = std::max(peak_near_axis, m.out.sdot);
    } else if (z > 0.3) {
      peak_beyond = std::max(peak_beyond, m.out.sdot);
    }
    EXPECT_LE(m.cylinder_speed_share(), 1.0 + 1e-6);
  }
  EXPECT_GT(near_axis, 10);
  EXPECT_GT(singular_near_axis, near_axis / 2);
  EXPECT_LT(peak_near_axis, 0.05) << "past the slew axis only at a crawl";
  EXPECT_GT(peak_beyond, 0.4) << "and at speed again beyond it";
}

// Sway damping after a hand-over (docs/sway.md): a dropout stops the crane unshaped, handing the
// shaped reference to the motion; when the stick comes back within half a swing period and keeps
// moving (an arc: never steady), shaping starts again at once, so what the arc and the stop after
// it add to the swing is a fraction of what they add undamped. (The swing the unshaped stop left is
// the same in both runs and is taken out: the pendulum is linear, so the runs with and without the
// arc differ by what the arc and its stop did.) Within the jerk bound and without a jump.
TEST(TipMotion, SwayDampingStartsAgainAfterAStopOnAMotionThatIsNeverSteady) {
  const auto cfg = config::default_crane_config();
  const dynamics::Pendulum pendulum = dynamics::grapple_pendulum(cfg.model, 0.0);
  ASSERT_GT(pendulum.omega_rad_s, 0.0);
  // The pendulum's state (x, z swing and their rates) at the end of a run.
  const auto final_swing = [&](bool damped, bool arc) {
    TipMotion m(cfg);
    const dynamics::Pendulum p = damped ? pendulum : dynamics::Pendulum{};
    // A linear pendulum under the reference's horizontal acceleration (crane frame x and z).
    const double w = pendulum.omega_rad_s, length = 9.81 / (w * w);
    Eigen::Vector2d x = Eigen::Vector2d::Zero(), xd = Eigen::Vector2d::Zero();
    Eigen::Vector3d last = Eigen::Vector3d::Zero(), last_a = Eigen::Vector3d::Zero();
    const double dt = m.period();
    for (int k = 0; k < 1400; ++k) {
      const double t = k * dt;
      Eigen::Vector3d command = Eigen::Vector3d::Zero();
      bool stale = false;
      if (t < 2.0) {
        command = Eigen::Vector3d(0.3, 0.0, 0.0);
      } else if (t < 2.8) {
        stale = true;  // a dropout: the stop hands the shaped reference over
      } else if (arc && t < 6.8) {
        const double phi = 0.25 * (t - 2.8);  // an arc: the command turns all the time
        command = 0.3 * Eigen::Vector3d(std::cos(phi), 0.0, std::sin(phi));
      }
      m.step(command, stale, p);
      // The reference's own velocity and acceleration: continuous, within the jerk bound.
      const Eigen::Vector3d v = m.out.velocity, a = m.out.acceleration;
      EXPECT_LE(m.out.sdddot, cfg.scaling.jerk_max_m_s3 * (1.0 + 1e-9)) << "t " << t;
      EXPECT_LE((a - last_a).norm(), cfg.scaling.jerk_max_m_s3 * dt * (1.0 + 1e-9)) << "t " << t;
      EXPECT_LE((v - last).norm(), 0.5 * dt * (a.norm() + last_a.norm()) + 1e-12) << "t " << t;
      last = v;
      last_a = a;
      for (int j = 0; j < 10; ++j) {
        const double h = dt / 10.0;
        xd += h * (-w * w * x - Eigen::Vector2d(a.x(), a.z()) / length);
        x += h * xd;
      }
    }
    EXPECT_TRUE(m.out.at_rest);
    Eigen::Vector4d state;
    state << x, xd / w;
    return state;
  };
  const double damped = (final_swing(true, true) - final_swing(true, false)).norm();
  const double undamped = (final_swing(false, true) - final_swing(false, false)).norm();
  std::printf(
      "[ figures  ] the swing an arc and a stop add after a dropout: %.3f deg damped, "
      "%.3f deg undamped\n",
      damped * 180.0 / M_PI, undamped * 180.0 / M_PI);
  EXPECT_GT(undamped * 180.0 / M_PI, 1.0);
  EXPECT_LT(damped, 0.1 * undamped);
}

TEST(TipMotion, CyclesAllocateNothing) {
  TipMotion m(config::default_crane_config());
  m.step(Eigen::Vector3d(0.1, 0.1, 0.1));
  const long before = craneassist::test::heap_allocations();
  for (int k = 0; k < 300; ++k) m.step(Eigen::Vector3d(0.3, 0.2 * (k % 3), -0.4));
  for (int k = 0; k < 50; ++k) m.step(Eigen::Vector3d::Zero(), true);
  EXPECT_EQ(craneassist::test::heap_allocations() - before, 0);
}
