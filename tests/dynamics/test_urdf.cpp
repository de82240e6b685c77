// The URDF that `craneassist urdf` writes, read back by urdfdom (the ROS parser, Debian's
// liburdfdom-dev): it parses, has the config's joints and limits and the bodies' mass, and its
// forward kinematics equal the model's at every pose.
#include <gtest/gtest.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <random>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/pendulum.hpp"
#include "craneassist/dynamics/urdf.hpp"

using namespace craneassist;

namespace {

Eigen::Isometry3d to_eigen(const urdf::Pose& p) {
  double x, y, z, w;
  p.rotation.getQuaternion(x, y, z, w);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(w, x, y, z).toRotationMatrix();
  t.translation() << p.position.x, p.position.y, p.position.z;
  return t;
}

// base_link to `link` at q (the joints in the model's order) and the hanger's angles, composed
// from the URDF alone.
Eigen::Isometry3d urdf_pose(const urdf::ModelInterface& m, const std::string& link,
                            const dynamics::CraneModel& model, const dynamics::JointVector& q,
                            const std::array<double, 2>& hanger = {0.0, 0.0}) {
  auto l = m.getLink(link);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  while (l && l->parent_joint) {
    const auto& j = *l->parent_joint;
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d axis(j.axis.x, j.axis.y, j.axis.z);
    for (int i = 0; i < model.dof(); ++i) {
      if (model.joints[static_cast<std::size_t>(i)].name != j.name) continue;
      if (j.type == urdf::Joint::REVOLUTE)
        motion.linear() = Eigen::AngleAxisd(q[i], axis).toRotationMatrix();
      if (j.type == urdf::Joint::PRISMATIC) motion.translation() = q[i] * axis;
    }
    for (std::size_t i = 0; i < hanger.size(); ++i) {
      if (j.name == dynamics::kHangerJointNames[i]) {
        EXPECT_EQ(j.type, urdf::Joint::REVOLUTE);
        motion.linear() = Eigen::AngleAxisd(hanger[i], axis).toRotationMatrix();
      }
    }
    t = to_eigen(j.parent_to_joint_origin_transform) * motion * t;
    l = m.getLink(j.parent_link_name);
  }
  return t;
}

void check_crane(const config::CraneConfig& cfg) {
  const auto& model = cfg.model;
  const auto urdf_model = urdf::parseURDF(dynamics::to_urdf(model));
  ASSERT_TRUE(urdf_model) << model.name << ": urdfdom refused the URDF";
  EXPECT_EQ(urdf_model->getRoot()->name, "base_link");
  double mass = 0.0;
  for (const auto& b : model.bodies) mass += b.mass_kg;
  double urdf_mass = 0.0;
  for (const auto& [name, link] : urdf_model->links_) {
    if (link->inertial && link->inertial->mass > 0.01) urdf_mass += link->inertial->mass;
  }
  EXPECT_NEAR(urdf_mass, mass, 1e-6 * mass) << model.name;
  for (const auto& j : model.joints) {
    const auto uj = urdf_model->getJoint(j.name);
    ASSERT_TRUE(uj) << j.name;
    EXPECT_DOUBLE_EQ(uj->limits->lower, j.q_min);
    EXPECT_DOUBLE_EQ(uj->limits->upper, j.q_max);
    EXPECT_GT(uj->limits->velocity, 0.0);
    EXPECT_EQ(uj->type, j.type == dynamics::JointType::kPrismatic ? urdf::Joint::PRISMATIC
                                                                  : urdf::Joint::REVOLUTE);
  }
  std::mt19937 rng(7);
  dynamics::KinematicsData data;
  const dynamics::HangerAxes axes = dynamics::hanger_axes(model);
  if (model.grapple.hangs()) {
    for (const char* name : dynamics::kHangerJointNames) EXPECT_TRUE(urdf_model->getJoint(name));
    ASSERT_TRUE(urdf_model->getLink("grapple_link"));
    // The grapple, rotator and payload hang: grapple_link carries them, tip_link nothing.
    double at_tip = 0.0;
    for (const auto& b : model.bodies) {
      if (b.frame == model.dof() && b.com_m.norm() < dynamics::kAtTipM) at_tip += b.mass_kg;
    }
    const auto& inertial = urdf_model->getLink("grapple_link")->inertial;
    ASSERT_TRUE(inertial);
    EXPECT_NEAR(inertial->mass, at_tip, 1e-9 * at_tip + 1e-3);
  }
  for (int k = 0; k < 200; ++k) {
    dynamics::JointVector q(model.dof());
    for (int i = 0; i < model.dof(); ++i) {
      const auto& j = model.joints[static_cast<std::size_t>(i)];
      q[i] = std::uniform_real_distribution<double>(j.q_min, j.q_max)(rng);
    }
    dynamics::forward_kinematics(model, data, q);
    const Eigen::Isometry3d tip = urdf_pose(*urdf_model, "tip_link", model, q);
    EXPECT_LT((tip.translation() - data.frames[model.dof()].translation()).norm(), 1e-6)
        << model.name << " pose " << k;
    EXPECT_LT((tip.linear() - data.frames[model.dof()].linear()).norm(), 1e-6);
    if (!model.grapple.hangs()) continue;
    // The grapple where the swing puts it: the URDF's grapple_link, at the hanger angles of a
    // swing, holds the grapple's centre of mass where grapple_position() (the simulator's
    // measure, drawn back) has it.
    const double radial = std::uniform_real_distribution<double>(-0.6, 0.6)(rng);
    const double tangential = std::uniform_real_distribution<double>(-0.6, 0.6)(rng);
    const auto angles =
        dynamics::hanger_joint_angles(model, axes, data.frames[model.dof()], radial, tangential);
    const Eigen::Isometry3d grapple = urdf_pose(*urdf_model, "grapple_link", model, q, angles);
    const Eigen::Vector3d com = grapple * (model.grapple.com_below_m * axes.hang);
    const Eigen::Vector3d expected = dynamics::grapple_position(
        model, data.frames[model.dof()].translation(), radial, tangential);
    EXPECT_LT((com - expected).norm(), 1e-6) << model.name << " pose " << k;
    // A swing nothing measures: straight down.
    const auto still =
        dynamics::hanger_joint_angles(model, axes, data.frames[model.dof()], NAN, NAN);
    const Eigen::Vector3d down =
        urdf_pose(*urdf_model, "grapple_link", model, q, still) * axes.hang -
        data.frames[model.dof()].translation();
    EXPECT_LT((down.normalized() - dynamics::down_direction(model)).norm(), 1e-6);
  }
}

}  // namespace

TEST(Urdf, TheReferenceCraneReadsBackWithTheModelsKinematicsAndMass) {
  check_crane(config::default_crane_config());
}

TEST(Urdf, APayloadIsInTheGrapplesMass) {
  auto cfg = config::default_crane_config();
  config::set_payload_mass(cfg.model, 650.0);
  check_crane(cfg);
}

TEST(Urdf, ThePlanar2rCraneToo) {
  check_crane(config::load_crane_config(std::string(CRANEASSIST_SOURCE_DIR) +
                                        "/config/cranes/planar_2r.yaml"));
}
