#include "craneassist/input/joint_trajectory.hpp"

#include <algorithm>
#include <fstream>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "csv_table.hpp"
#include "text_fields.hpp"

namespace craneassist::input {
namespace {

std::vector<std::string> columns_for(int n) {
  std::vector<std::string> c{"t"};
  for (const char* name : {"q_", "qdot_", "qddot_"}) {
    for (int i = 1; i <= n; ++i) c.push_back(name + std::to_string(i));
  }
  return c;
}

// The joint count a header announces: the number of q_ columns (0 when it is not a trajectory
// header at all).
int joints_in_header(std::string_view text) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line[first] == '#') continue;
    int n = 0;
    while (line.find("q_" + std::to_string(n + 1)) != std::string_view::npos &&
           n < JointTrajectory::kMaxJoints) {
      ++n;
    }
    return n;
  }
  return 0;
}

}  // namespace

JointTrajectory::JointTrajectory(int joints) : joints_(joints) {
  if (joints < 0 || joints > kMaxJoints) throw std::invalid_argument("bad joint count");
}

JointTrajectory JointTrajectory::load_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TrajectoryError(path.string(), 0, "", "cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse(text.str(), path.string());
}

JointTrajectory JointTrajectory::parse(std::string_view text, std::string_view source_name) {
  const int n = std::max(joints_in_header(text), 1);
  const auto table = detail::read_csv_table(text, source_name, columns_for(n), kMaxRows);
  JointTrajectory traj(n);
  traj.t_s_.reserve(table.rows());
  traj.values_.reserve(table.rows() * 3 * static_cast<std::size_t>(n));
  for (std::size_t r = 0; r < table.rows(); ++r) {
    traj.t_s_.push_back(table.at(r, 0));
    for (std::size_t c = 1; c < table.columns.size(); ++c) traj.values_.push_back(table.at(r, c));
  }
  // Keep the comment lines (the planner's summary, for reports).
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string_view::npos || line[first] != '#') continue;
    line.remove_prefix(first + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (!line.empty() && line.front() == ' ') line.remove_prefix(1);
    traj.comments.emplace_back(line);
  }
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
  t_s_.push_back(t_s);
  for (const auto* v : {&q, &qdot, &qddot}) {
    for (Eigen::Index i = 0; i < joints_; ++i) values_.push_back((*v)[i]);
  }
}

void JointTrajectory::sample(double t, Eigen::Ref<Eigen::VectorXd> q,
                             Eigen::Ref<Eigen::VectorXd> qdot) const {
  if (t_s_.empty()) return;
  if (t <= t_s_.front() || t_s_.size() == 1) {
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
  const auto columns = columns_for(traj.joints());
  for (std::size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
  out << '\n';
  for (std::size_t r = 0; r < traj.size(); ++r) {
    out << detail::number(traj.t_s(r));
    for (const auto& v : {traj.q(r), traj.qdot(r), traj.qddot(r)}) {
      for (Eigen::Index j = 0; j < v.size(); ++j) out << ',' << detail::number(v[j]);
    }
    out << '\n';
  }
}

}  // namespace craneassist::input
