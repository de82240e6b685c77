// The optimal posture table of paper 001's point-to-point planner (research/planner/
// posture_table.hpp, docs/mhsb.md#s1-the-optimal-posture-table): entries on their nodes within
// the ranges and better than random postures, the continuity tie-break, the file's round trip
// and its refusal when damaged, the jump count, the fixed last joint of Case 4.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>
#include <utility>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/planner/posture_table.hpp"
#include "ptp_arm.hpp"

namespace {

using namespace craneassist;
using namespace craneassist::test;
using planner::ArmVector;

TEST(PostureTable, EntriesAreOnTheirNodesWithinTheRangesAndBeatRandomPostures) {
  const auto settings = region_settings(0.05, 4);
  const auto table = planner::PostureTable::build(arm(), settings);
  ASSERT_GT(table.grid().nodes(), 20);
  ASSERT_EQ(table.pattern_count(), 4);
  dynamics::KinematicsData data;
  planner::PolytopeArea area(arm());
  std::mt19937 rng(3);
  int compared = 0;
  for (int n = 0; n < table.grid().nodes(); n += 3) {
    const Eigen::Vector2d node = table.grid().node_xz[static_cast<std::size_t>(n)];
    // Random feasible postures at the node: random last joints, the first two by 2R inverse
    // kinematics (both elbows).
    std::vector<ArmVector> randoms;
    for (int r = 0; r < 300; ++r) {
      ArmVector a(3);
      a[2] = std::uniform_real_distribution<double>(arm().lower(2), arm().upper(2))(rng);
      const double phi = std::uniform_real_distribution<double>(-M_PI, M_PI)(rng);
      const double l1 = 0.45, l2 = 0.4, l3 = 0.179;
      const Eigen::Vector2d wrist = node - l3 * Eigen::Vector2d(std::cos(phi), std::sin(phi));
      const double c2 = (wrist.squaredNorm() - l1 * l1 - l2 * l2) / (2 * l1 * l2);
      if (std::abs(c2) > 1.0) continue;
      a[1] = (r % 2 ? 1 : -1) * std::acos(c2);
      a[0] = std::atan2(wrist.y(), wrist.x()) -
             std::atan2(l2 * std::sin(a[1]), l1 + l2 * std::cos(a[1]));
      a[2] = phi - a[0] - a[1];
      bool inside = true;
      for (int k = 0; k < 3; ++k)
        inside = inside && a[k] >= arm().lower(k) && a[k] <= arm().upper(k);
      if (!inside) continue;
      ASSERT_LT((arm().tip(a, data) - node).norm(), 1e-9);
      randoms.push_back(a);
    }
    for (int p = 0; p < table.pattern_count(); ++p) {
      const ArmVector q = table.posture(n, p);
      EXPECT_LT((arm().tip(q, data) - node).norm(), 1e-6);
      for (int k = 0; k < 3; ++k) {
        EXPECT_GE(q[k], arm().lower(k));
        EXPECT_LE(q[k], arm().upper(k));
      }
      const auto full = planner::full_pattern(arm(), table.patterns()[static_cast<std::size_t>(p)]);
      EXPECT_NEAR(area(q, full), table.area(n, p), 1e-12);
      double best_random = 0.0;
      for (const auto& a : randoms) best_random = std::max(best_random, area(a, full));
      EXPECT_GE(table.area(n, p), best_random * (1.0 - 0.01) - 1e-12)
          << "node " << node.transpose() << " pattern " << p;
      ++compared;
    }
  }
  EXPECT_GT(compared, 20);
}

// The continuity tie-break (docs/mhsb.md#s1-the-optimal-posture-table): the all-N table of a
// region where the largest polytopes jump between the arm's mirror branches, built with and
// without it. With it, fewer neighbouring nodes jump, and no entry falls more than the tolerance
// below the best-only table (its first pass is the same).
TEST(PostureTable, TheContinuityTieBreakKeepsNeighboursOnOneBranch) {
  auto settings = region_settings(0.05, 1);
  const auto best_only = planner::PostureTable::build(arm(), settings);
  settings.continuity_tolerance = 0.3;
  const auto continued = planner::PostureTable::build(arm(), settings);
  ASSERT_EQ(continued.grid().nodes(), best_only.grid().nodes());
  EXPECT_EQ(best_only.continued, 0);
  EXPECT_GT(continued.continued, 0);
  const int jumps_before = best_only.jumps(arm(), 0), jumps_after = continued.jumps(arm(), 0);
  EXPECT_GT(jumps_before, 0);  // else the region shows nothing
  EXPECT_LT(jumps_after, jumps_before);
  for (int n = 0; n < continued.grid().nodes(); ++n) {
    EXPECT_GE(continued.area(n, 0), (1.0 - 0.3) * best_only.area(n, 0) - 1e-12) << "node " << n;
  }
  // A tolerance is another table: its fingerprint differs.
  EXPECT_NE(continued.fingerprint(), best_only.fingerprint());
}

TEST(PostureTable, TheFileRoundTripsAndAnotherModelOrGridRebuilds) {
  const auto settings = region_settings(0.1, 0);
  const auto file = std::filesystem::path(testing::TempDir()) / "ptp-table-test.bin";
  small_table().save(file);
  const auto back = planner::PostureTable::load(file, arm(), settings);
  ASSERT_TRUE(back.has_value());
  ASSERT_EQ(back->grid().nodes(), small_table().grid().nodes());
  for (int n = 0; n < back->grid().nodes(); ++n) {
    EXPECT_EQ(back->posture(n, 5), small_table().posture(n, 5));
  }
  auto other = settings;
  other.spacing_m = 0.05;
  EXPECT_FALSE(planner::PostureTable::load(file, arm(), other).has_value());
  auto cfg = arm_config();
  config::set_payload_mass(cfg.model, 5.0);
  const planner::PlanarArm lighter(cfg.model, cfg.simulation.q_initial);
  EXPECT_FALSE(planner::PostureTable::load(file, lighter, settings).has_value());
  std::filesystem::remove(file);
}

// A damaged table file (cut short, its grid, patterns, postures or areas changed) is refused
// and rebuilt, never used: the bytes after the fingerprint are checked too.
TEST(PostureTable, ADamagedFileIsRefused) {
  const auto settings = region_settings(0.1, 0);
  std::ostringstream out;
  small_table().write(out);
  const std::string good = out.str();
  const auto read = [&](const std::string& bytes) {
    std::istringstream in(bytes);
    return planner::PostureTable::read(in, arm(), settings).has_value();
  };
  ASSERT_TRUE(read(good));
  const int nodes = small_table().grid().nodes(), np = small_table().pattern_count();
  const int m = small_table().moving();
  // Layout: magic 8, fingerprint 8, moving 4, spacing 8, ix0 iz0 nx nz 16, nodes 4, patterns 4,
  // node cells 8 each, pattern modes m each, postures 8 m each entry, areas 8 each entry.
  const std::size_t nodes_at = 44, patterns_at = 48, cells_at = 52;
  const std::size_t modes_at = cells_at + 8 * static_cast<std::size_t>(nodes);
  const std::size_t q_at = modes_at + static_cast<std::size_t>(np * m);
  const std::size_t area_at = q_at + 8 * static_cast<std::size_t>(nodes * np * m);
  ASSERT_EQ(good.size(), area_at + 8 * static_cast<std::size_t>(nodes * np));
  const auto with = [&](std::size_t at, const auto& value) {
    std::string bytes = good;
    std::memcpy(bytes.data() + at, &value, sizeof value);
    return bytes;
  };
  EXPECT_FALSE(read(good.substr(0, good.size() - 1)));           // cut short
  EXPECT_FALSE(read(good + '\0'));                               // a byte too many
  EXPECT_FALSE(read(with(20, 0.2)));                             // another spacing
  EXPECT_FALSE(read(with(nodes_at, std::int32_t{nodes + 1})));   // more nodes than written
  EXPECT_FALSE(read(with(patterns_at, std::int32_t{1 << 30})));  // a billion patterns
  EXPECT_FALSE(read(with(patterns_at, std::int32_t{np - 1})));
  std::string two_on_one = good;  // node 1 on node 0's cell
  std::memcpy(two_on_one.data() + cells_at + 8, good.data() + cells_at, 8);
  EXPECT_FALSE(read(two_on_one));
  EXPECT_FALSE(read(with(modes_at + 1, std::uint8_t{2})));  // another pattern
  EXPECT_FALSE(read(with(q_at, std::numeric_limits<double>::quiet_NaN())));
  EXPECT_FALSE(read(with(q_at + 8, 10.0)));  // outside the joint's range
  const double q0 = small_table().posture(0, 0)[0];
  EXPECT_FALSE(read(with(q_at, q0 + (q0 > 0.0 ? -0.01 : 0.01))));  // the tip off its node
  EXPECT_FALSE(read(with(area_at, -1.0)));
  EXPECT_FALSE(read(with(area_at + 8, std::numeric_limits<double>::infinity())));
}

// Every pair of the grid's nodes that are neighbours (8-neighbourhood), each once, counted here
// by brute force, apart from the table's own count.
std::vector<std::pair<int, int>> neighbour_pairs(const planner::WorkspaceGrid& g) {
  std::vector<std::pair<int, int>> pairs;
  for (int a = 0; a < g.nodes(); ++a) {
    for (int b = a + 1; b < g.nodes(); ++b) {
      const auto sa = static_cast<std::size_t>(a), sb = static_cast<std::size_t>(b);
      if (std::max(std::abs(g.node_i[sa] - g.node_i[sb]), std::abs(g.node_k[sa] - g.node_k[sb])) ==
          1) {
        pairs.emplace_back(a, b);
      }
    }
  }
  return pairs;
}

// jumps() looks at every pair of neighbouring nodes (8-neighbourhood) once: against all pairs of
// nodes, each checked by the rule (a joint moving more than the fraction of its range).
TEST(PostureTable, JumpsCountEveryNeighbourPairOnce) {
  const auto& t = small_table();
  const auto pairs = neighbour_pairs(t.grid());
  for (int p : {0, 5}) {
    for (const double fraction : {0.0, 0.05, 0.25}) {
      int jumps = 0;
      for (const auto& [a, b] : pairs) {
        bool jump = false;
        for (int k = 0; k < 3; ++k) {
          jump = jump || std::abs(t.posture(a, p)[k] - t.posture(b, p)[k]) >
                             fraction * (arm().upper(k) - arm().lower(k));
        }
        jumps += jump ? 1 : 0;
      }
      EXPECT_EQ(t.jumps(arm(), p, fraction), jumps) << "pattern " << p << " fraction " << fraction;
    }
  }
  EXPECT_EQ(t.neighbour_pairs(), static_cast<int>(pairs.size()));
  EXPECT_GT(pairs.size(), 20u);
  EXPECT_EQ(t.jumps(arm(), 0, 1.0), 0);  // no joint moves more than its range
}

// The shipped arm bends J2 and J3 one way (docs/mhsb.md#the-posture-table-one-elbow): the all-N
// table's neighbouring nodes never take mirror postures. With J3 allowed to -120 degrees, J3's
// sign flipped between dozens of neighbouring pairs (by up to 249 degrees) and Case 2-2's first
// step moved J3 175 degrees.
TEST(PostureTable, TheShippedArmsNeighboursNeverFlipAnElbow) {
  planner::PostureTableSettings s;
  s.spacing_m = 0.05;
  s.max_patterns = 1;  // all N
  const auto t = planner::PostureTable::build(arm(), s);
  const auto pairs = neighbour_pairs(t.grid());
  double largest_deg = 0.0;
  for (const auto& [a, b] : pairs) {
    const ArmVector qa = t.posture(a, 0), qb = t.posture(b, 0);
    for (int k = 1; k < 3; ++k) {  // the elbows J2, J3
      EXPECT_GE(qa[k] * qb[k], -1e-6) << "J" << k + 1 << " flips between nodes " << a << ", " << b;
      largest_deg = std::max(largest_deg, std::abs(qa[k] - qb[k]) * 180.0 / M_PI);
    }
  }
  EXPECT_GT(pairs.size(), 2500u);  // the whole workspace
  EXPECT_LT(largest_deg, 90.0);    // 65 degrees measured (J3, where the area is flat)
}

// The 2R inverse kinematics of the paper's arm with J3 held at q3: both elbows, within the ranges.
std::vector<ArmVector> fixed_j3_solutions(const Eigen::Vector2d& node, double q3) {
  const double l1 = 0.45, l2 = 0.4, l3 = 0.179;
  // Joint 2 to the tip with J3 at q3: a link of length r at angle beta to link 2.
  const Eigen::Vector2d b(l2 + l3 * std::cos(q3), l3 * std::sin(q3));
  const double r = b.norm(), beta = std::atan2(b.y(), b.x());
  const double c = (node.squaredNorm() - l1 * l1 - r * r) / (2 * l1 * r);
  std::vector<ArmVector> out;
  if (std::abs(c) > 1.0) return out;
  for (const double elbow : {1.0, -1.0}) {
    const double g = elbow * std::acos(c);  // the angle of link "r" to link 1
    ArmVector a(3);
    a[0] = std::atan2(node.y(), node.x()) - std::atan2(r * std::sin(g), l1 + r * std::cos(g));
    a[1] = std::remainder(g - beta, 2 * M_PI);
    a[2] = q3;
    a[0] = std::remainder(a[0], 2 * M_PI);
    bool inside = true;
    for (int k = 0; k < 3; ++k) inside = inside && a[k] >= arm().lower(k) && a[k] <= arm().upper(k);
    if (inside) out.push_back(a);
  }
  return out;
}

// Paper 001's Case 4 conventional method: J3 held where the other joints can reach the node, else
// changed by the fewest 1-degree steps; J1, J2 one of the inverse kinematics' solutions.
TEST(PostureTable, FixedLastJointHoldsItWhereverTheOthersReachTheNode) {
  const auto settings = region_settings(0.1, 3);
  const double held = 120.0 * M_PI / 180.0, step = M_PI / 180.0;
  const auto table = planner::PostureTable::fixed_last_joint(arm(), settings, held);
  EXPECT_FALSE(table.optimal());
  ASSERT_GT(table.grid().nodes(), 20);
  ASSERT_EQ(table.pattern_count(), 3);
  dynamics::KinematicsData data;
  planner::PolytopeArea area(arm());
  int moved = 0, curled_nodes = 0;
  for (int n = 0; n < table.grid().nodes(); ++n) {
    const Eigen::Vector2d node = table.grid().node_xz[static_cast<std::size_t>(n)];
    const ArmVector q = table.posture(n, 0);
    EXPECT_LT((arm().tip(q, data) - node).norm(), 1e-6);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(q[k], arm().lower(k));
      EXPECT_LE(q[k], arm().upper(k));
    }
    for (int p = 1; p < table.pattern_count(); ++p) EXPECT_EQ(table.posture(n, p), q);
    for (int p = 0; p < table.pattern_count(); ++p) {
      const auto full = planner::full_pattern(arm(), table.patterns()[static_cast<std::size_t>(p)]);
      EXPECT_NEAR(area(q, full), table.area(n, p), 1e-12);
    }
    // J3 is on the 1-degree ladder from the held angle, and no rung nearer it has a solution.
    const double steps = std::round((q[2] - held) / step);
    EXPECT_NEAR(q[2], held + steps * step, 1e-9) << "node " << node.transpose();
    for (int s = 0; s < std::abs(steps); ++s) {
      for (const double sign : {1.0, -1.0}) {
        const double q3 = held + sign * s * step;
        if (q3 < arm().lower(2) || q3 > arm().upper(2)) continue;
        EXPECT_TRUE(fixed_j3_solutions(node, q3).empty())
            << "node " << node.transpose() << " reachable with J3 at " << q3 * 180 / M_PI;
      }
    }
    // J1, J2 are one of the analytic solutions at that J3, bent J3's way when one is.
    double nearest = 1e9;
    bool curled = false;
    for (const auto& a : fixed_j3_solutions(node, q[2])) {
      nearest = std::min(nearest, (a - q).norm());
      curled = curled || a[1] * a[2] >= 0.0;
    }
    EXPECT_LT(nearest, 1e-6) << "node " << node.transpose();
    if (curled) {
      EXPECT_GE(q[1] * q[2], 0.0) << "node " << node.transpose();
      ++curled_nodes;
    }
    if (steps != 0.0) ++moved;
  }
  EXPECT_EQ(moved, table.moved_last_joint);
  EXPECT_GT(curled_nodes, table.grid().nodes() / 2);
  // At 120 deg the arm reaches 0.80 m at most: the far nodes need J3 moved, the near ones not.
  EXPECT_GT(moved, 0);
  EXPECT_LT(moved, table.grid().nodes() / 2);
  EXPECT_THROW(planner::PostureTable::fixed_last_joint(arm(), settings, 2.5),
               std::invalid_argument);
}

// Every pair of some nodes, several weights: A* and Dijkstra find the same cost.

}  // namespace
