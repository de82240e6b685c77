#include "craneassist/input/joint_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <ostream>
#include <stdexcept>

#include "csv_reader.hpp"
#include "text_fields.hpp"

namespace craneassist::input {
namespace {

// The highest mode number (SB).
constexpr double kMaxMode = 2.0;

// The format for n joints: t, then q_1..q_n, qdot_1..qdot_n, qddot_1..qddot_n, and with_modes
// mode_1..mode_n.
detail::CsvFormat trajectory_format(int n, bool with_modes) {
  detail::CsvFormat format;
  format.columns.push_back({"t", detail::CsvKind::kTime});
  for (const char* name : {"q_", "qdot_", "qddot_"}) {
    for (int i = 1; i <= n; ++i) format.columns.push_back({name + std::to_string(i)});
  }
  for (int i = 1; with_modes && i <= n; ++i) {
    format.columns.push_back({"mode_" + std::to_string(i), detail::CsvKind::kNumber, kMaxMode});
  }
  format.max_rows = JointTrajectory::kMaxRows;
  return format;
}

// The joint count a header announces: the number of q_ columns (0 when it is not a trajectory
// header at all).
int joints_in_header(std::string_view header) {
  int n = 0;
  while (header.find("q_" + std::to_string(n + 1)) != std::string_view::npos &&
         n < JointTrajectory::kMaxJoints) {
    ++n;
  }
  return n;
}

}  // namespace

JointTrajectory::JointTrajectory(int joints) : joints_(joints) {
  if (joints < 0 || joints > kMaxJoints) throw std::invalid_argument("bad joint count");
}

JointTrajectory JointTrajectory::load_file(const std::filesystem::path& path,
                                           const TrajectoryLimits& limits) {
  return parse(detail::read_file_text(path, "joint trajectory"), path.string(), limits);
}

JointTrajectory JointTrajectory::parse(std::string_view text, std::string_view source_name,
                                       const TrajectoryLimits& limits) {
  const std::string_view header = detail::header_line(text);
  const int n = std::max(joints_in_header(header), 1);
  const bool with_modes = header.find("mode_1") != std::string_view::npos;
  const auto crane_joints = static_cast<int>(limits.joints.size());
  const bool check_ranges = crane_joints == n;
  JointTrajectory traj(n);
  const auto plain_columns = static_cast<std::size_t>(1 + 3 * n);
  detail::CsvFile file = detail::read_csv(
      text, source_name, trajectory_format(n, with_modes), [&](const detail::CsvRow& row) {
        const std::size_t columns = row.values.size();
        for (std::size_t c = plain_columns; c < columns; ++c) {
          const double mode = row.values[c];
          if (!(mode >= 0.0 && mode == std::floor(mode))) {
            throw row.error(
                "mode_" + std::to_string(c - plain_columns + 1),
                "expected a mode 0 (N), 1 (DB) or 2 (SB), got " + std::string(row.text[c]));
          }
          traj.modes_.push_back(static_cast<std::uint8_t>(mode));
        }
        for (int i = 0; check_ranges && i < n; ++i) {
          const TrajectoryJoint& joint = limits.joints[static_cast<std::size_t>(i)];
          const double q = row.values[static_cast<std::size_t>(1 + i)];
          if (!(q >= joint.min && q <= joint.max)) {
            throw row.error("q_" + std::to_string(i + 1),
                            detail::number(q) + " " + joint.unit +
                                " is outside the range of joint '" + joint.name + "', [" +
                                detail::number(joint.min) + ", " + detail::number(joint.max) +
                                "] " + joint.unit);
          }
        }
        traj.t_s_.push_back(row.values[0]);
        traj.values_.insert(traj.values_.end(), row.values.begin() + 1,
                            row.values.begin() + static_cast<std::ptrdiff_t>(plain_columns));
      });
  if (crane_joints > 0 && !check_ranges) {
    const std::string columns =
        n == 1 ? "1 joint (q_1)" : std::to_string(n) + " joints (q_1..q_" + std::to_string(n) + ")";
    throw FileError(
        std::string(source_name), file.header_line, "",
        "the header names " + columns + ", the crane has " + std::to_string(crane_joints));
  }
  // Keep the comment lines (the planner's summary, for reports).
  traj.comments = std::move(file.comments);
  return traj;
}

void JointTrajectory::append(double t_s, const Eigen::Ref<const Eigen::VectorXd>& q,
                             const Eigen::Ref<const Eigen::VectorXd>& qdot,
                             const Eigen::Ref<const Eigen::VectorXd>& qddot) {
  if (q.size() != joints_ || qdot.size() != joints_ || qddot.size() != joints_) {
    throw std::invalid_argument("JointTrajectory::append: wrong vector size");
  }
  if (!std::isfinite(t_s) || (!t_s_.empty() && !(t_s > t_s_.back()))) {
    throw std::invalid_argument("JointTrajectory::append: time not increasing");
  }
  if (has_modes()) {
    throw std::invalid_argument("JointTrajectory::append: modes on some samples only");
  }
  t_s_.push_back(t_s);
  for (const auto* v : {&q, &qdot, &qddot}) {
    for (Eigen::Index i = 0; i < joints_; ++i) values_.push_back((*v)[i]);
  }
}

void JointTrajectory::append(double t_s, const Eigen::Ref<const Eigen::VectorXd>& q,
                             const Eigen::Ref<const Eigen::VectorXd>& qdot,
                             const Eigen::Ref<const Eigen::VectorXd>& qddot,
                             const std::vector<int>& modes) {
  if (!empty() && !has_modes()) {
    throw std::invalid_argument("JointTrajectory::append: modes on some samples only");
  }
  if (modes.size() != static_cast<std::size_t>(joints_)) {
    throw std::invalid_argument("JointTrajectory::append: wrong number of modes");
  }
  for (int m : modes) {
    if (m < 0 || m > static_cast<int>(kMaxMode)) {
      throw std::invalid_argument("JointTrajectory::append: mode out of range");
    }
  }
  std::vector<std::uint8_t> kept;
  kept.swap(modes_);  // append() takes a trajectory without modes
  append(t_s, q, qdot, qddot);
  kept.swap(modes_);
  for (int m : modes) modes_.push_back(static_cast<std::uint8_t>(m));
}

void JointTrajectory::sample(double t, Eigen::Ref<Eigen::VectorXd> q,
                             Eigen::Ref<Eigen::VectorXd> qdot) const {
  if (t_s_.empty()) return;
  // A NaN time holds the first sample too (and must not reach the search below: no sample
  // compares before NaN, so it would find none).
  if (!(t > t_s_.front()) || t_s_.size() == 1) {
    q = this->q(0);
    qdot.setZero();
    if (t_s_.size() == 1 || t == t_s_.front()) qdot = this->qdot(0);
    return;
  }
  if (t >= t_s_.back()) {
    q = this->q(size() - 1);
    qdot.setZero();
    if (t == t_s_.back()) qdot = this->qdot(size() - 1);
    return;
  }
  const auto it = std::upper_bound(t_s_.begin(), t_s_.end(), t);
  const auto i1 = static_cast<std::size_t>(it - t_s_.begin());
  const std::size_t i0 = i1 - 1;
  const double h = t_s_[i1] - t_s_[i0];
  const double s = (t - t_s_[i0]) / h;
  const double s2 = s * s, s3 = s2 * s, s4 = s3 * s, s5 = s4 * s;
  // Quintic Hermite basis and derivatives (per unit s).
  const double h00 = 1 - 10 * s3 + 15 * s4 - 6 * s5, h01 = 1 - h00;
  const double h10 = s - 6 * s3 + 8 * s4 - 3 * s5, h11 = -4 * s3 + 7 * s4 - 3 * s5;
  const double h20 = 0.5 * (s2 - 3 * s3 + 3 * s4 - s5), h21 = 0.5 * (s3 - 2 * s4 + s5);
  const double d00 = -30 * s2 + 60 * s3 - 30 * s4, d01 = -d00;
  const double d10 = 1 - 18 * s2 + 32 * s3 - 15 * s4, d11 = -12 * s2 + 28 * s3 - 15 * s4;
  const double d20 = 0.5 * (2 * s - 9 * s2 + 12 * s3 - 5 * s4),
               d21 = 0.5 * (3 * s2 - 8 * s3 + 5 * s4);
  const auto p0 = this->q(i0), p1 = this->q(i1);
  const auto v0 = this->qdot(i0), v1 = this->qdot(i1);
  const auto a0 = this->qddot(i0), a1 = this->qddot(i1);
  for (int j = 0; j < joints_; ++j) {
    q[j] = h00 * p0[j] + h01 * p1[j] + h * (h10 * v0[j] + h11 * v1[j]) +
           h * h * (h20 * a0[j] + h21 * a1[j]);
    qdot[j] = (d00 * p0[j] + d01 * p1[j]) / h + (d10 * v0[j] + d11 * v1[j]) +
              h * (d20 * a0[j] + d21 * a1[j]);
  }
}

void write_joint_trajectory(std::ostream& out, const JointTrajectory& traj) {
  for (const auto& c : traj.comments) out << "# " << c << '\n';
  const int n = traj.joints();
  out << detail::csv_header(trajectory_format(n, traj.has_modes())) << '\n';
  for (std::size_t r = 0; r < traj.size(); ++r) {
    out << detail::number(traj.t_s(r));
    for (const auto& v : {traj.q(r), traj.qdot(r), traj.qddot(r)}) {
      for (Eigen::Index j = 0; j < v.size(); ++j) out << ',' << detail::number(v[j]);
    }
    for (int j = 0; traj.has_modes() && j < n; ++j) out << ',' << traj.mode(r, j);
    out << '\n';
  }
}

}  // namespace craneassist::input
