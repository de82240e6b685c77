// Joint trajectories: a planned motion as joint positions, rates and accelerations over time
// (what `craneassist research plan` writes and `craneassist replay --trajectory` executes). CSV in
// the style of the replay format; specified in docs/trajectory-format.md.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/input/file_error.hpp"

namespace craneassist::input {

// The crane a trajectory is for: its joints' ranges, base to tip, in the order of q_1..q_n. A
// position outside them, or a file for another number of joints, is refused on reading.
struct TrajectoryJoint {
  std::string name;  // for the message: "joint 'lift'"
  double min = 0.0;  // rad or m
  double max = 0.0;
  std::string unit;  // "rad" or "m", for the message
};
struct TrajectoryLimits {
  std::vector<TrajectoryJoint> joints;  // empty: no crane to check against
};

class JointTrajectory {
 public:
  static constexpr int kMaxJoints = 6;
  static constexpr std::size_t kMaxRows = 1'000'000;

  explicit JointTrajectory(int joints = 0);

  // Reads and validates a file (header t,q_1..q_n,qdot_1..qdot_n,qddot_1..qddot_n with n in
  // 1..kMaxJoints, time >= 0 and strictly increasing, every value finite) and, given the crane's
  // limits, n equal to its joints and every q_i within joint i's range. Throws FileError (the
  // field is the column, e.g. "qdot_2"), as the replay and path readers.
  static JointTrajectory load_file(const std::filesystem::path& path,
                                   const TrajectoryLimits& limits = {});
  static JointTrajectory parse(std::string_view text, std::string_view source_name,
                               const TrajectoryLimits& limits = {});

  // Appends a sample; t must exceed the last one and the vectors have joints() entries (else
  // std::invalid_argument). The second form adds each joint's MHSB mode (0 N, 1 DB, 2 SB;
  // docs/trajectory-format.md#mode-columns): a trajectory has modes on every sample or on none.
  void append(double t_s, const Eigen::Ref<const Eigen::VectorXd>& q,
              const Eigen::Ref<const Eigen::VectorXd>& qdot,
              const Eigen::Ref<const Eigen::VectorXd>& qddot);
  void append(double t_s, const Eigen::Ref<const Eigen::VectorXd>& q,
              const Eigen::Ref<const Eigen::VectorXd>& qdot,
              const Eigen::Ref<const Eigen::VectorXd>& qddot, const std::vector<int>& modes);

  int joints() const { return joints_; }
  std::size_t size() const { return t_s_.size(); }
  bool empty() const { return t_s_.empty(); }
  double t_s(std::size_t i) const { return t_s_[i]; }
  double start_time_s() const { return t_s_.front(); }
  double end_time_s() const { return t_s_.back(); }
  Eigen::Map<const Eigen::VectorXd> q(std::size_t i) const { return column(0, i); }
  Eigen::Map<const Eigen::VectorXd> qdot(std::size_t i) const { return column(1, i); }
  Eigen::Map<const Eigen::VectorXd> qddot(std::size_t i) const { return column(2, i); }

  // Position and rate at time t: quintic Hermite interpolation between samples (position, rate
  // and acceleration continuous); held at the first and last sample outside the time range (a NaN
  // time holds the first sample).
  // q and qdot must have joints() entries. No allocation.
  void sample(double t_s, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> qdot) const;

  // Whether the samples carry modes (the file's optional mode_1..mode_n columns), and joint j's
  // (0-based) mode at sample i: 0 N, 1 DB, 2 SB (mhsb::MhsbMode's order).
  bool has_modes() const { return !modes_.empty(); }
  int mode(std::size_t i, int j) const {
    return modes_[i * static_cast<std::size_t>(joints_) + static_cast<std::size_t>(j)];
  }

  // The comment lines of the file (without '#'), e.g. the planner's summary.
  std::vector<std::string> comments;

 private:
  Eigen::Map<const Eigen::VectorXd> column(int block, std::size_t i) const {
    return {values_.data() + i * 3 * static_cast<std::size_t>(joints_) +
                static_cast<std::size_t>(block * joints_),
            joints_};
  }

  int joints_ = 0;
  std::vector<double> t_s_;
  std::vector<double> values_;       // per sample: q, qdot, qddot
  std::vector<std::uint8_t> modes_;  // per sample: one per joint, or empty
};

void write_joint_trajectory(std::ostream& out, const JointTrajectory& trajectory);

}  // namespace craneassist::input
