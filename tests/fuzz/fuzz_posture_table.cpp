// Posture table files of the point-to-point planner (planner::PostureTable::read, the cache file
// of `craneassist research ptp` and `sim --input goal`, docs/mhsb.md#s1-the-optimal-posture-table):
// a damaged or foreign file is refused (nullopt, never an exception or a crash), and a table that
// is read keeps what the planner relies on: each node on its own cell, postures within the joint
// ranges with the tip on the node, finite non-negative areas; the planner builds its graph on it
// and plans between two of its nodes.
//
// The bytes past the fingerprint are what a damaged file can change, so the input is applied to
// a real table (a small region of paper 001's arm, built once): the first byte picks how.
//   0: the input after it replaces everything after the header (magic, fingerprint, joints);
//   1: the input after it is a list of 3-byte patches (16-bit offset, new byte) of the table;
//   2: as 1, then the table is cut to the length the first two input bytes give.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/planner/ptp_planner.hpp"
#include "fuzz_check.hpp"

namespace planner = craneassist::planner;

namespace {

constexpr std::size_t kHeader = 8 + 8 + 4;  // magic, fingerprint, moving joints

struct Fixture {
  craneassist::config::CraneConfig cfg = craneassist::config::mhsb_3link_config();
  planner::PlanarArm arm{cfg.model, cfg.simulation.q_initial};
  planner::PostureTableSettings settings;
  std::string good;
  Fixture() {
    settings.spacing_m = 0.1;
    settings.region = Eigen::Vector4d(0.3, -0.1, 0.6, 0.2);
    settings.max_patterns = 3;
    settings.threads = 1;
    std::ostringstream out;
    planner::PostureTable::build(arm, settings).write(out);
    good = out.str();
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

void check_table(const planner::PostureTable& t, const Fixture& f) {
  const planner::WorkspaceGrid& g = t.grid();
  FUZZ_CHECK(t.moving() == f.arm.moving(), "the arm's moving joints");
  craneassist::dynamics::KinematicsData data;
  for (int n = 0; n < g.nodes(); ++n) {
    FUZZ_CHECK(g.node_at(g.node_i[static_cast<std::size_t>(n)],
                         g.node_k[static_cast<std::size_t>(n)]) == n,
               "each node on its own cell");
    for (int d = 0; d < 8; ++d) {
      const int other = g.neighbour(n, d);
      FUZZ_CHECK(other >= -1 && other < g.nodes(), "neighbours are nodes");
    }
    for (int p = 0; p < t.pattern_count(); ++p) {
      const planner::ArmVector q = t.posture(n, p);
      for (int k = 0; k < t.moving(); ++k) {
        FUZZ_CHECK(q[k] >= f.arm.lower(k) - 1e-6 && q[k] <= f.arm.upper(k) + 1e-6,
                   "postures within the joint ranges");
      }
      FUZZ_CHECK((f.arm.tip(q, data) - g.node_xz[static_cast<std::size_t>(n)]).norm() <= 1e-4,
                 "the tip on its node");
      FUZZ_CHECK(std::isfinite(t.area(n, p)) && t.area(n, p) >= 0.0, "areas finite, >= 0");
    }
  }
  (void)t.jumps(f.arm, 0);
  if (g.nodes() < 2) return;
  planner::PtpPlanner ptp(f.arm, t, planner::PtpSettings{});
  planner::PtpWeights w;
  w.energy = 0.5;
  w.switches = 2.0;
  const planner::PtpPlan plan = ptp.plan(g.node_xz.front(), g.node_xz.back(), w);
  if (plan.path.found) {
    FUZZ_CHECK(std::isfinite(plan.energy_j) && std::isfinite(plan.time_s), "a finite plan");
    for (const auto& s : plan.samples) FUZZ_CHECK(s.q.allFinite(), "finite samples");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const Fixture& f = fixture();
  std::string bytes;
  const std::uint8_t* in = data + 1;
  std::size_t n = size - 1;
  switch (data[0] % 3) {
    case 0:
      bytes = f.good.substr(0, kHeader) + std::string(reinterpret_cast<const char*>(in), n);
      break;
    default: {
      bytes = f.good;
      std::size_t cut = bytes.size();
      if (data[0] % 3 == 2 && n >= 2) {
        cut = (static_cast<std::size_t>(in[0]) | static_cast<std::size_t>(in[1]) << 8) %
              (bytes.size() + 1);
        in += 2;
        n -= 2;
      }
      for (std::size_t i = 0; i + 3 <= n; i += 3) {
        const std::size_t at = static_cast<std::size_t>(in[i]) | static_cast<std::size_t>(in[i + 1])
                                                                     << 8;
        bytes[at % bytes.size()] = static_cast<char>(in[i + 2]);
      }
      bytes.resize(cut);
      break;
    }
  }
  std::istringstream stream(bytes);
  const auto table = planner::PostureTable::read(stream, f.arm, f.settings);
  if (table) check_table(*table, f);
  return 0;
}
