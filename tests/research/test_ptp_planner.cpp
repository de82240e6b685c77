// The point-to-point planner of paper 001 (research/planner/ptp_planner.hpp, docs/mhsb.md): the
// analytic gravity load against the ODE model, the posture table against brute force, A* against
// Dijkstra, the mode rule along found paths, the time trajectory, the table file and the joint
// trajectory's mode columns. Tables are built on small regions of the workspace to stay fast.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/dynamics/static_gravity.hpp"
#include "craneassist/input/joint_trajectory.hpp"
#include "craneassist/planner/ptp_planner.hpp"

namespace {

using namespace craneassist;
using planner::ArmVector;

planner::PtpWeights W(double energy, double time, double switches) {
  planner::PtpWeights w;
  w.energy = energy;
  w.time = time;
  w.switches = switches;
  return w;
}

const config::CraneConfig& arm_config() {
  static const config::CraneConfig cfg = config::mhsb_3link_config();
  return cfg;
}

// A region of the paper's arm: 5 cm grid, the first patterns only, or all of them on a 10 cm grid.
planner::PostureTableSettings region_settings(double spacing, int patterns) {
  planner::PostureTableSettings s;
  s.spacing_m = spacing;
  s.region = Eigen::Vector4d(0.3, -0.2, 0.8, 0.3);
  s.max_patterns = patterns;
  return s;
}

const planner::PlanarArm& arm() {
  static const planner::PlanarArm a(arm_config().model, arm_config().simulation.q_initial);
  return a;
}

const planner::PostureTable& small_table() {
  static const planner::PostureTable t =
      planner::PostureTable::build(arm(), region_settings(0.1, 0));
  return t;
}

TEST(StaticGravity, MatchesTheOdeModel) {
  for (const auto& cfg : {config::default_crane_config(), config::mhsb_3link_config()}) {
    dynamics::RigidBodyTerms terms(cfg.model);
    dynamics::KinematicsData data;
    std::mt19937 rng(7);
    for (int trial = 0; trial < 20; ++trial) {
      dynamics::JointVector q(cfg.model.dof());
      for (int i = 0; i < cfg.model.dof(); ++i) {
        const auto& j = cfg.model.joints[static_cast<std::size_t>(i)];
        q[i] = std::uniform_real_distribution<double>(j.q_min, j.q_max)(rng);
      }
      dynamics::JointVector g_ode, g;
      terms.gravity(q, g_ode);
      dynamics::static_gravity_effort(cfg.model, data, q, g);
      for (int i = 0; i < cfg.model.dof(); ++i) {
        EXPECT_NEAR(g[i], g_ode[i], 1e-6 * (1.0 + g_ode.cwiseAbs().maxCoeff())) << cfg.model.name;
      }
    }
  }
}

TEST(PlanarArm, TheK70MMovesLiftTiltAndExtensionInItsVerticalPlane) {
  const auto cfg = config::default_crane_config();
  const planner::PlanarArm k70(cfg.model, cfg.simulation.q_initial);
  ASSERT_EQ(k70.moving(), 3);
  EXPECT_EQ(k70.joint(0), 1);
  dynamics::KinematicsData data;
  const ArmVector a = k70.moving_part(cfg.simulation.q_initial);
  const Eigen::Vector3d tip = dynamics::tip_position(cfg.model, data, cfg.simulation.q_initial);
  EXPECT_LT((k70.from_plane(k70.tip(a, data)) - tip).norm(), 1e-9);
  EXPECT_GT(k70.tip(a, data).x(), 0.0);
  // The paper's arm: (X, Z) are the crane's (x, y).
  EXPECT_EQ(arm().moving(), 3);
  EXPECT_NEAR(arm().plane()(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(arm().plane()(1, 1), 1.0, 1e-12);
}

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

// jumps() looks at every pair of neighbouring nodes (8-neighbourhood) once: against all pairs of
// nodes, each checked by the rule (a joint moving more than the fraction of its range).
TEST(PostureTable, JumpsCountEveryNeighbourPairOnce) {
  const auto& t = small_table();
  const auto& g = t.grid();
  int pairs = 0;
  for (int p : {0, 5}) {
    for (const double fraction : {0.0, 0.05, 0.25}) {
      int jumps = 0;
      pairs = 0;
      for (int a = 0; a < g.nodes(); ++a) {
        for (int b = a + 1; b < g.nodes(); ++b) {
          const auto sa = static_cast<std::size_t>(a), sb = static_cast<std::size_t>(b);
          if (std::max(std::abs(g.node_i[sa] - g.node_i[sb]),
                       std::abs(g.node_k[sa] - g.node_k[sb])) != 1) {
            continue;
          }
          ++pairs;
          bool jump = false;
          for (int k = 0; k < 3; ++k) {
            jump = jump || std::abs(t.posture(a, p)[k] - t.posture(b, p)[k]) >
                               fraction * (arm().upper(k) - arm().lower(k));
          }
          jumps += jump ? 1 : 0;
        }
      }
      EXPECT_EQ(t.jumps(arm(), p, fraction), jumps) << "pattern " << p << " fraction " << fraction;
    }
  }
  EXPECT_EQ(t.neighbour_pairs(), pairs);
  EXPECT_GT(pairs, 20);
  EXPECT_EQ(t.jumps(arm(), 0, 1.0), 0);  // no joint moves more than its range
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
TEST(PtpPlanner, AStarCostEqualsDijkstras) {
  planner::PtpPlanner ptp(arm(), small_table(), {});
  const int nodes = small_table().grid().nodes();
  ASSERT_GT(nodes, 15);
  int compared = 0;
  for (const planner::PtpWeights& w : {W(0.5, 0, 2), W(0, 15, 2), W(1, 1, 0)}) {
    for (int s = 0; s < nodes; s += 4) {
      for (int g = 1; g < nodes; g += 5) {
        const auto a = ptp.search(s, g, w, planner::PtpSearch::kAStar);
        const auto d = ptp.search(s, g, w, planner::PtpSearch::kDijkstra);
        ASSERT_EQ(a.found, d.found);
        if (!a.found) continue;
        EXPECT_NEAR(a.cost, d.cost, 1e-9 * (1.0 + d.cost));
        EXPECT_LE(a.expanded, d.expanded);
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 30);
}

TEST(PtpPlanner, TransitionsObeyTheModeRule) {
  const auto& model = arm().model();
  planner::PtpPlanner ptp(arm(), small_table(), {});
  dynamics::KinematicsData data;
  int boosted = 0, checked = 0;
  for (const planner::PtpWeights& w : {W(0.5, 0, 2), W(0, 15, 2)}) {
    const auto plan = ptp.plan({0.5, -0.1}, {0.7, 0.3}, w);
    ASSERT_TRUE(plan.path.found);
    const auto& steps = plan.path.steps;
    for (std::size_t i = 1; i < steps.size(); ++i) {
      planner::PlanarArm::Statics a, b;
      arm().statics(steps[i - 1].q, data, a);
      arm().statics(steps[i].q, data, b);
      const double t = steps[i].t_s - steps[i - 1].t_s;
      ASSERT_GT(t, 0.0);
      const auto& pattern = small_table().patterns()[static_cast<std::size_t>(steps[i].pattern)];
      for (int k = 0; k < 3; ++k) {
        const double v = (b.length_m[k] - a.length_m[k]) / t;
        EXPECT_LE(std::abs(v), ptp.velocity_limit_m_s(k) * (1 + 1e-9));
        const auto mode = pattern.mode[static_cast<std::size_t>(k)];
        if (mhsb::is_boost(mode)) {
          EXPECT_LE(std::abs(v) * dynamics::flow_area_m2(model.cylinders[k], v),
                    mhsb::mode_flow_cap_m3_s(*model.mhsb, mode) * (1 + 1e-9));
        }
        const bool need = mhsb::needs_boost(model, k, a.force_n[k], v) ||
                          mhsb::needs_boost(model, k, b.force_n[k], v);
        if (v != 0.0) {
          EXPECT_EQ(need, mhsb::is_boost(mode));
          EXPECT_TRUE(mhsb::mode_allowed(model, k, mode, a.force_n[k], v) ||
                      mhsb::mode_allowed(model, k, mode, b.force_n[k], v));
        }
        // N for a negative load at both ends.
        if (!mhsb::positive_load(a.force_n[k], v) && !mhsb::positive_load(b.force_n[k], v) &&
            v != 0.0) {
          EXPECT_EQ(mode, mhsb::MhsbMode::kNormal);
        }
        boosted += mhsb::is_boost(mode) ? 1 : 0;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 20);
  EXPECT_GT(boosted, 0);  // the lift to (0.7, 0.3) needs a boost somewhere
}

TEST(PtpPlanner, TheTrajectoryRestsAtTheEndsAndPassesThroughTheNodes) {
  planner::PtpPlanner ptp(arm(), small_table(), {});
  const auto plan = ptp.plan({0.5, -0.1}, {0.7, 0.3}, W(0.5, 0, 2));
  ASSERT_TRUE(plan.path.found);
  ASSERT_GT(plan.samples.size(), 10u);
  const auto& first = plan.samples.front();
  const auto& last = plan.samples.back();
  EXPECT_EQ(first.t_s, 0.0);
  EXPECT_NEAR(last.t_s, plan.node_times_s.back(), 1e-9);
  EXPECT_LT(first.qdot.norm() + first.qddot.norm() + last.qdot.norm() + last.qddot.norm(), 1e-9);
  EXPECT_LT((first.q - plan.path.steps.front().q).norm(), 1e-12);
  EXPECT_LT((last.q - plan.path.steps.back().q).norm(), 1e-9);
  // Near each node time the trajectory is at the node's posture (within what it moves in the
  // time between), and the rates are the positions' derivatives.
  double peak_rate = 0.0;
  for (const auto& s : plan.samples) peak_rate = std::max(peak_rate, s.qdot.cwiseAbs().maxCoeff());
  ASSERT_EQ(plan.node_times_s.size(), plan.path.steps.size());
  for (std::size_t i = 0; i < plan.path.steps.size(); ++i) {
    const double t = plan.node_times_s[i];
    EXPECT_GE(t, plan.path.steps[i].t_s - 1e-9);  // S3 only ever lengthens a segment
    const auto it = std::min_element(
        plan.samples.begin(), plan.samples.end(),
        [&](const auto& l, const auto& r) { return std::abs(l.t_s - t) < std::abs(r.t_s - t); });
    EXPECT_LE((it->q - plan.path.steps[i].q).cwiseAbs().maxCoeff(),
              peak_rate * std::abs(it->t_s - t) + 1e-9);
  }
  EXPECT_LE(plan.peak_speed_ratio, 1.5 * 1.05);  // checked on 17 points per segment
  for (std::size_t i = 1; i < plan.samples.size(); ++i) {
    const auto& a = plan.samples[i - 1];
    const auto& b = plan.samples[i];
    const double dt = b.t_s - a.t_s;
    const ArmVector predicted = a.q + 0.5 * (a.qdot + b.qdot) * dt;
    EXPECT_LT((predicted - b.q).cwiseAbs().maxCoeff(), 1e-3 * dt + 2 * peak_rate * dt * dt);
  }
  EXPECT_GT(plan.energy_j, 0.0);
  EXPECT_NEAR(plan.energy_j, plan.path.energy_j, 0.3 * plan.path.energy_j);
}

// A live loop replans from where the arm is: the trajectory starts at that posture, at rest, and
// then follows the table's nodes.
TEST(PtpPlanner, ReplansFromTheArmsPosture) {
  planner::PtpPlanner ptp(arm(), small_table(), {});
  const int start = ptp.node_near({0.5, -0.1});
  ASSERT_GE(start, 0);
  // Another posture on the start node: the table's for another pattern.
  const ArmVector here = small_table().posture(start, 7);
  const auto plan = ptp.plan({0.5, -0.1}, {0.7, 0.3}, W(0.5, 0, 2), here);
  ASSERT_TRUE(plan.path.found);
  EXPECT_LT((plan.samples.front().q - here).norm(), 1e-12);
  EXPECT_LT(plan.samples.front().qdot.norm(), 1e-12);
  EXPECT_LT((plan.samples.back().q - plan.path.steps.back().q).norm(), 1e-9);
  EXPECT_LE(plan.peak_speed_ratio, 1.5 * 1.05);
}

TEST(PtpPlanner, APointOutsideTheWorkspaceIsRefused) {
  planner::PtpPlanner ptp(arm(), small_table(), {});
  EXPECT_THROW(ptp.plan({2.0, 0.0}, {0.5, 0.0}, W(0.5, 0, 2)), std::invalid_argument);
  EXPECT_THROW(ptp.plan({0.5, 0.0}, {0.0, 3.0}, W(0.5, 0, 2)), std::invalid_argument);
}

TEST(PtpPlanner, PlansTheK70MOnALoadSensingPump) {
  const auto cfg = config::default_crane_config();
  const planner::PlanarArm k70(cfg.model, cfg.simulation.q_initial);
  planner::PostureTableSettings s;
  s.spacing_m = 0.5;
  s.region = Eigen::Vector4d(3.0, 0.0, 7.0, 4.0);
  const auto table = planner::PostureTable::build(k70, s);
  ASSERT_EQ(table.pattern_count(), 1);
  ASSERT_GT(table.grid().nodes(), 30);
  planner::PtpPlanner ptp(k70, table, {});
  EXPECT_EQ(ptp.energy(), planner::PtpEnergy::kLoadSensing);
  const auto plan = ptp.plan({4.0, 1.0}, {6.5, 3.5}, W(1.0, 0.0, 0.0));
  ASSERT_TRUE(plan.path.found);
  EXPECT_GT(plan.energy_j, 0.0);
  EXPECT_GT(plan.path.steps.size(), 4u);
  const auto d = ptp.search(plan.path.steps.front().node, plan.path.steps.back().node,
                            W(1.0, 0.0, 0.0), planner::PtpSearch::kDijkstra);
  EXPECT_NEAR(d.cost, plan.path.cost, 1e-9 * d.cost);
}

TEST(JointTrajectoryModes, RoundTripAndErrors) {
  input::JointTrajectory t(2);
  const Eigen::Vector2d z = Eigen::Vector2d::Zero();
  t.append(0.0, z, z, z, {0, 1});
  t.append(0.5, Eigen::Vector2d(0.1, 0.2), z, z, {2, 0});
  EXPECT_THROW(t.append(1.0, z, z, z), std::invalid_argument);
  std::ostringstream out;
  input::write_joint_trajectory(out, t);
  EXPECT_NE(out.str().find("qddot_2,mode_1,mode_2\n"), std::string::npos);
  const auto back = input::JointTrajectory::parse(out.str(), "modes.csv");
  ASSERT_TRUE(back.has_modes());
  EXPECT_EQ(back.mode(1, 0), 2);
  EXPECT_EQ(back.mode(0, 1), 1);
  // Without mode columns as before.
  const auto plain = input::JointTrajectory::parse("t,q_1,qdot_1,qddot_1\n0,1,0,0\n", "p.csv");
  EXPECT_FALSE(plain.has_modes());
  try {
    input::JointTrajectory::parse(
        "t,q_1,q_2,qdot_1,qdot_2,qddot_1,qddot_2,mode_1\n0,0,0,0,0,0,0,1\n", "half.csv");
    ADD_FAILURE() << "a partial set of mode columns was accepted";
  } catch (const input::FileError& e) {
    EXPECT_NE(std::string(e.what()).find("half.csv:1: expected the header "
                                         "'t,q_1,q_2,qdot_1,qdot_2,qddot_1,qddot_2,mode_1,mode_2'"),
              std::string::npos)
        << e.what();
  }
  try {
    input::JointTrajectory::parse("t,q_1,qdot_1,qddot_1,mode_1\n0,0,0,0,1.5\n", "frac.csv");
    ADD_FAILURE() << "mode 1.5 was accepted";
  } catch (const input::FileError& e) {
    EXPECT_NE(std::string(e.what()).find("frac.csv:2: field 'mode_1'"), std::string::npos)
        << e.what();
  }
}

}  // namespace
