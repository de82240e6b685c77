#include "craneassist/foxglove/channels.hpp"

#include <algorithm>

#include "craneassist/foxglove/cdr.hpp"

namespace craneassist::foxglove {

// ROS 2 Jazzy's definitions (without comments), in the form of @foxglove/rosmsg-msgs-common's
// ros2jazzy msgdefs; tests/foxglove checks them against those files.
#define CRANEASSIST_SEPARATOR \
  "================================================================================\n"
#define CRANEASSIST_HEADER_MSG \
  CRANEASSIST_SEPARATOR        \
  "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
#define CRANEASSIST_VECTOR3_MSG \
  CRANEASSIST_SEPARATOR         \
  "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"

const char* const kJointStateSchema =
    "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
    "float64[] effort\n" CRANEASSIST_HEADER_MSG;
const char* const kTfMessageSchema =
    "geometry_msgs/TransformStamped[] transforms\n" CRANEASSIST_SEPARATOR
    "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\n"
    "Transform transform\n" CRANEASSIST_HEADER_MSG CRANEASSIST_SEPARATOR
    "MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion "
    "rotation\n" CRANEASSIST_VECTOR3_MSG CRANEASSIST_SEPARATOR
    "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";
const char* const kTwistStampedSchema =
    "std_msgs/Header header\nTwist twist\n" CRANEASSIST_HEADER_MSG CRANEASSIST_SEPARATOR
    "MSG: geometry_msgs/Twist\nVector3  linear\nVector3  angular\n" CRANEASSIST_VECTOR3_MSG;
const char* const kStringSchema = "string data\n";

#undef CRANEASSIST_VECTOR3_MSG
#undef CRANEASSIST_HEADER_MSG
#undef CRANEASSIST_SEPARATOR

namespace {

void header(CdrWriter& w, std::int64_t stamp_ns, std::string_view frame_id) {
  const std::int64_t sec =
      stamp_ns >= 0 ? stamp_ns / 1000000000 : (stamp_ns - 999999999) / 1000000000;
  w.i32(static_cast<std::int32_t>(sec));
  w.u32(static_cast<std::uint32_t>(stamp_ns - sec * 1000000000));
  w.str(frame_id);
}

}  // namespace

ChannelSet::ChannelSet(const dynamics::CraneModel& model, bool base)
    : model_(model),
      dof_(std::min(model.dof(), control::LogRow::kMaxJoints)),
      urdf_(dynamics::to_urdf(model)),
      frames_(dynamics::urdf_frames(model)),
      hanger_axes_(dynamics::hanger_axes(model)),
      transforms_(frames_.size()),
      // task_from_base is orthonormal: its inverse is its transpose.
      base_from_crane_(model.task_from_base.transpose()) {
  for (int i = 0; i < dof_; ++i)
    joint_names_.push_back(model.joints[static_cast<std::size_t>(i)].name);
  if (model.grapple.hangs()) {
    joint_names_.insert(joint_names_.end(), dynamics::kHangerJointNames.begin(),
                        dynamics::kHangerJointNames.end());
  }
  const auto add = [&](Kind kind, std::string topic, const char* type, const char* schema) {
    channels_.push_back(
        {std::move(topic), "cdr", type, "ros2msg", schema, kind == Kind::kRobotDescription});
    kinds_.push_back(kind);
    groups_.push_back(control::FieldGroup::kStatus);
  };
  add(Kind::kRobotDescription, "/robot_description", "std_msgs/msg/String", kStringSchema);
  add(Kind::kJointStates, "/joint_states", "sensor_msgs/msg/JointState", kJointStateSchema);
  add(Kind::kTf, "/tf", "tf2_msgs/msg/TFMessage", kTfMessageSchema);
  add(Kind::kCommand, "/craneassist/tip_velocity/command", "geometry_msgs/msg/TwistStamped",
      kTwistStampedSchema);
  add(Kind::kReference, "/craneassist/tip_velocity/reference", "geometry_msgs/msg/TwistStamped",
      kTwistStampedSchema);
  for (const control::FieldGroup g : control::kFieldGroups) {
    if (g == control::FieldGroup::kBase && !base) continue;
    const std::string name = std::string("craneassist/") + control::to_string(g);
    channels_.push_back({"/" + name, "json", name, "jsonschema", control::group_json_schema(g)});
    kinds_.push_back(Kind::kGroup);
    groups_.push_back(g);
  }
  json_.reserve(4096);
}

void ChannelSet::encode(std::size_t k, const control::LogRow& row, std::int64_t stamp_ns,
                        std::vector<std::uint8_t>& out) {
  switch (kinds_[k]) {
    case Kind::kRobotDescription: {
      CdrWriter w(out);
      w.str(urdf_);
      return;
    }
    case Kind::kJointStates: {
      CdrWriter w(out);
      header(w, stamp_ns, "");
      w.count(joint_names_.size());
      for (const auto& name : joint_names_) w.str(name);
      const std::size_t hangers = joint_names_.size() - static_cast<std::size_t>(dof_);
      w.count(joint_names_.size());
      for (int i = 0; i < dof_; ++i) w.f64(row.q[static_cast<std::size_t>(i)]);
      for (std::size_t i = 0; i < hangers; ++i) w.f64(row.hanger_rad[i]);
      w.count(joint_names_.size());
      for (int i = 0; i < dof_; ++i) w.f64(row.qdot[static_cast<std::size_t>(i)]);
      for (std::size_t i = 0; i < hangers; ++i) w.f64(row.hanger_rate_rad_s[i]);
      w.count(0);  // effort: not measured
      return;
    }
    case Kind::kTf: {
      dynamics::urdf_transforms(model_, hanger_axes_, row.q.data(), row.hanger_rad,
                                transforms_.data());
      CdrWriter w(out);
      w.count(frames_.size());
      for (std::size_t i = 0; i < frames_.size(); ++i) {
        header(w, stamp_ns, frames_[i].parent);
        w.str(frames_[i].child);
        const Eigen::Isometry3d& t = transforms_[i];
        const Eigen::Quaterniond r(t.linear());
        for (int a = 0; a < 3; ++a) w.f64(t.translation()[a]);
        w.f64(r.x());
        w.f64(r.y());
        w.f64(r.z());
        w.f64(r.w());
      }
      return;
    }
    case Kind::kCommand:
    case Kind::kReference: {
      const auto& v = kinds_[k] == Kind::kCommand ? row.cmd : row.ref_v;
      const Eigen::Vector3d linear = base_from_crane_ * Eigen::Vector3d(v[0], v[1], v[2]);
      CdrWriter w(out);
      header(w, stamp_ns, "base_link");
      for (int a = 0; a < 3; ++a) w.f64(linear[a]);
      for (int a = 0; a < 3; ++a) w.f64(0.0);
      return;
    }
    case Kind::kGroup: {
      json_.clear();
      control::append_group_json(row, dof_, groups_[k], json_);
      out.assign(json_.begin(), json_.end());
      return;
    }
  }
}

}  // namespace craneassist::foxglove
