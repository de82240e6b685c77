// The measured valve characteristic (hydraulics.valves.tables) and its inverse, the DZI of
// paper 000 appendix A: exact at the table points, continuous and monotone between them, both
// directions, the straight-line fallback unchanged, the differential extension spool, and the
// config's checks naming file, line and field.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "allocation_counter.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "craneassist/valves/proportional_valves.hpp"
#include "curved_valve_table.hpp"
#include "thrown_error.hpp"

namespace {

using namespace craneassist;
using dynamics::ValveTable;

using test::curved_table;

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const std::string kK70mPath = std::string(CRANEASSIST_SOURCE_DIR) + "/config/cranes/k70m.yaml";

// The K70M file with a tables block added under hydraulics.valves.
std::string k70m_with_tables(const std::string& block) {
  std::string text = read_file(kK70mPath);
  const std::string anchor = "    delay: 0.15 s, paper";
  const auto pos = text.find(anchor);
  EXPECT_NE(pos, std::string::npos);
  const auto eol = text.find('\n', pos);
  text.insert(eol + 1, block);
  return text;
}

config::ConfigError table_error(const std::string& block) {
  return test::thrown_error<config::ConfigError>(
      [&] { config::parse_crane_config(k70m_with_tables(block), "tables.yaml"); },
      "no error for\n" + block);
}

int line_in(const std::string& text, const std::string& needle) {
  const auto pos = text.find(needle);
  EXPECT_NE(pos, std::string::npos) << needle;
  return 1 +
         static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n'));
}

TEST(ValveTable, InverseIsExactAtTheTablePoints) {
  const auto t = curved_table();
  ASSERT_EQ(dynamics::check_valve_table(t), "");
  for (std::size_t k = 0; k < t.command.size(); ++k) {
    if (t.velocity_m_s[k] == 0.0) continue;  // the dead band: no velocity to invert
    EXPECT_DOUBLE_EQ(dynamics::valve_table_command(t, t.velocity_m_s[k]), t.command[k]) << k;
    EXPECT_DOUBLE_EQ(dynamics::valve_table_velocity(t, t.command[k]), t.velocity_m_s[k]) << k;
  }
}

TEST(ValveTable, InverseInterpolatesBetweenPoints) {
  const auto t = curved_table();
  // Halfway between (0.7, 0.04) and (0.85, 0.1).
  EXPECT_NEAR(dynamics::valve_table_command(t, 0.07), 0.775, 1e-12);
  // Halfway between (-0.8, -0.07) and (-0.6, -0.02).
  EXPECT_NEAR(dynamics::valve_table_command(t, -0.045), -0.7, 1e-12);
  // First segment beyond the dead band starts at its edge: (0.55, 0) .. (0.6, 0.01).
  EXPECT_NEAR(dynamics::valve_table_command(t, 0.005), 0.575, 1e-12);
  EXPECT_NEAR(dynamics::valve_table_command(t, -0.01), -0.54,
              1e-12);  // (-0.6, -0.02) .. (-0.48, 0)
  // Round trip everywhere outside the dead band.
  for (double u = -1.0; u <= 1.0; u += 0.01) {
    const double v = dynamics::valve_table_velocity(t, u);
    if (std::abs(v) < 1e-4) continue;  // the dead band (and its rounding)
    EXPECT_NEAR(dynamics::valve_table_command(t, v), u, 1e-9) << u;
  }
}

TEST(ValveTable, InverseIsMonotoneContinuousAndSaturates) {
  const auto t = curved_table();
  double last = -2.0;
  double last_v = 0.0;
  for (double v = -0.2; v <= 0.2; v += 1e-5) {
    const double u = dynamics::valve_table_command(t, v);
    EXPECT_GE(u, last) << v;
    // Continuous except where it leaves neutral for the dead-band edge (|v| ~ 1e-4 v_max).
    if (std::abs(v) > 1e-4 && std::abs(last_v) > 1e-4 && v * last_v > 0.0) {
      EXPECT_LT(u - last, 0.01) << v;
    }
    last = u;
    last_v = v;
  }
  EXPECT_EQ(dynamics::valve_table_command(t, 0.5), 1.0);    // beyond the top speed
  EXPECT_EQ(dynamics::valve_table_command(t, -0.5), -1.0);  // both ways
  EXPECT_EQ(dynamics::valve_table_command(t, 0.0), 0.0);
  EXPECT_EQ(dynamics::valve_table_command(t, 1e-6), 0.0);  // below 1e-4 of the top speed
  EXPECT_EQ(dynamics::valve_table_command(t, std::nan("")), 0.0);
  EXPECT_DOUBLE_EQ(dynamics::valve_table_dead_band_edge(t, 1.0), 0.55);
  EXPECT_DOUBLE_EQ(dynamics::valve_table_dead_band_edge(t, -1.0), -0.48);
}

TEST(ValveTable, TableWithoutADeadBandCrossesZeroOnTheLine) {
  ValveTable t;
  t.command = {-1.0, -0.2, 0.4, 1.0};
  t.velocity_m_s = {-0.1, -0.02, 0.04, 0.1};
  ASSERT_EQ(dynamics::check_valve_table(t), "");
  EXPECT_NEAR(dynamics::valve_table_dead_band_edge(t, 1.0), 0.0, 1e-12);
  EXPECT_NEAR(dynamics::valve_table_command(t, 0.01), 0.1, 1e-12);
}

TEST(ValveTable, ChecksRejectUnusableTables) {
  auto t = curved_table();
  t.velocity_m_s[7] = 0.005;  // below its neighbour at a lower command
  EXPECT_NE(dynamics::check_valve_table(t).find("not monotone"), std::string::npos);
  t = curved_table();
  t.velocity_m_s[8] = t.velocity_m_s[7];  // flat outside the dead band: not invertible
  EXPECT_NE(dynamics::check_valve_table(t).find("outside the dead band"), std::string::npos);
  t = curved_table();
  t.command[9] = 1.2;
  EXPECT_NE(dynamics::check_valve_table(t).find("[-1, 1]"), std::string::npos);
  t = curved_table();
  t.command[3] = -0.9;  // commands out of order
  EXPECT_NE(dynamics::check_valve_table(t).find("increase strictly"), std::string::npos);
  t = curved_table();
  t.velocity_m_s.pop_back();
  EXPECT_NE(dynamics::check_valve_table(t).find("one velocity per command"), std::string::npos);
  t.command = {0.5, 1.0};
  t.velocity_m_s = {0.0, 0.1};  // extension only
  EXPECT_NE(dynamics::check_valve_table(t).find("both directions"), std::string::npos);
}

// Without tables the valves are today's straight line, bit for bit; a table that is that straight
// line gives the same commands.
TEST(ProportionalValves, StraightLineFallbackIsUnchanged) {
  auto cfg = config::default_crane_config();
  ASSERT_TRUE(cfg.model.valves.tables.empty());
  const valves::ProportionalValves plain(cfg.model, 2.0);
  auto tabled_model = cfg.model;
  for (const auto& c : tabled_model.cylinders) {
    tabled_model.valves.tables.push_back(
        dynamics::straight_line_valve_table(tabled_model.valves.dead_zone, c.v_max_m_s));
  }
  const valves::ProportionalValves tabled(tabled_model, 2.0);
  valves::ProportionalValvesInput in;
  in.velocity_ref_m_s = dynamics::JointVector::Zero(4);
  in.position_error_m = dynamics::JointVector::Zero(4);
  valves::ValveCommand a, b;
  for (double v = -0.5; v <= 0.5; v += 0.001) {
    for (int i = 0; i < 4; ++i) {
      in.velocity_ref_m_s[i] = v * (i + 1) / 4.0;
      in.position_error_m[i] = 0.001 * (i - 2);
    }
    plain.update(in, a);
    tabled.update(in, b);
    for (int i = 0; i < 4; ++i) {
      const double want = valves::ProportionalValves::spool_from_velocity(
          in.velocity_ref_m_s[i] + 2.0 * in.position_error_m[i], cfg.model.valves.dead_zone,
          cfg.model.cylinders[static_cast<std::size_t>(i)].v_max_m_s);
      EXPECT_EQ(a.spool[i], want);
      EXPECT_NEAR(b.spool[i], want, 1e-12);
    }
  }
  EXPECT_EQ(plain.dead_band_edge(1, -1.0), -0.53);
  EXPECT_NEAR(tabled.dead_band_edge(1, 1.0), 0.53, 1e-15);
}

// The extension cylinder's differential spool: the valve meters a flow Q(u), extending needs
// A_A - A_B per m/s, retracting A_B, so the same command moves it faster out than in. The table is
// in cylinder velocity, so it carries that: the command for an extension velocity is the one whose
// flow fills (A_A - A_B) v, not A_A v.
TEST(ProportionalValves, TableCapturesTheDifferentialExtensionSpool) {
  auto cfg = config::default_crane_config();
  auto& model = cfg.model;
  const auto& ext = model.cylinders[3];
  ASSERT_TRUE(ext.differential_spool);
  const double q_max = 100e-3 / 60.0;  // m^3/s at full command, both ways
  const double dz = 0.5;
  ValveTable t;
  for (double u : {-1.0, -0.8, -0.6, -0.5, 0.5, 0.6, 0.8, 1.0}) {
    const double flow = std::copysign(std::max(std::abs(u) - dz, 0.0) / (1.0 - dz) * q_max, u);
    t.command.push_back(u);
    t.velocity_m_s.push_back(flow / dynamics::flow_area_m2(ext, flow));
  }
  ASSERT_EQ(dynamics::check_valve_table(t), "");
  model.valves.tables.assign(4, ValveTable{});
  model.valves.tables[3] = t;
  const valves::ProportionalValves valves(model, 0.0);
  ASSERT_NE(valves.table(3), nullptr);
  ASSERT_EQ(valves.table(2), nullptr);
  for (double v : {0.05, 0.2, 0.5, -0.05, -0.2}) {
    const double flow = v * dynamics::flow_area_m2(ext, v);
    const double want = std::copysign(dz + (1.0 - dz) * std::abs(flow) / q_max, v);
    EXPECT_NEAR(valves.spool_for(3, v), want, 1e-12) << v;
  }
  // Same speed, less command out than in: extension needs only A_A - A_B.
  EXPECT_LT(valves.spool_for(3, 0.2), -valves.spool_for(3, -0.2));
  // The other sections keep the straight line.
  EXPECT_EQ(valves.spool_for(2, 0.075),
            valves::ProportionalValves::spool_from_velocity(0.075, 0.53, 0.15));
}

TEST(ProportionalValves, TablePathAllocatesNothing) {
  auto cfg = config::default_crane_config();
  cfg.model.valves.tables.assign(4, curved_table());
  const valves::ProportionalValves valves(cfg.model, 2.0, 1e-4, 1e-3);
  valves::ProportionalValvesInput in;
  in.velocity_ref_m_s = dynamics::JointVector::Constant(4, 0.05);
  in.position_error_m = dynamics::JointVector::Constant(4, -0.002);
  valves::ValveCommand out;
  out.spool.setZero(4);
  const auto before = craneassist::test::heap_allocations();
  valves.update(in, out);
  EXPECT_EQ(craneassist::test::heap_allocations(), before);
  EXPECT_NEAR(out.spool[0], dynamics::valve_table_command(curved_table(), 0.046), 1e-15);
}

TEST(CraneConfig, ValveTablesAreReadByJointName) {
  const std::string block =
      "    tables:\n"
      "      extension:\n"
      "        command: -1 -0.53 0.53 0.8 1, measured\n"
      "        velocity: -400 0 0 200 400 mm/s, measured\n";
  const auto cfg = config::parse_crane_config(k70m_with_tables(block), "tables.yaml");
  const auto& tables = cfg.model.valves.tables;
  ASSERT_EQ(tables.size(), 4u);
  EXPECT_TRUE(tables[0].empty());
  EXPECT_TRUE(tables[2].empty());
  ASSERT_EQ(tables[3].command.size(), 5u);
  EXPECT_DOUBLE_EQ(tables[3].command[3], 0.8);
  EXPECT_DOUBLE_EQ(tables[3].velocity_m_s[0], -0.4);
  EXPECT_EQ(cfg.unsourced_quantities, 0);
  // The shipped config has none: the straight line.
  EXPECT_TRUE(config::default_crane_config().model.valves.tables.empty());
}

TEST(CraneConfig, ValveTableErrorsNameLineAndField) {
  const std::string not_monotone =
      "    tables:\n"
      "      lift:\n"
      "        command: -1 -0.53 0.53 0.8 1, measured\n"
      "        velocity: -0.15 0 0 0.1 0.09 m/s, measured\n";
  auto e = table_error(not_monotone);
  EXPECT_EQ(e.field(), "hydraulics.valves.tables.lift.velocity");
  EXPECT_EQ(e.line(), line_in(k70m_with_tables(not_monotone), "velocity: -0.15"));
  EXPECT_NE(e.reason().find("not monotone"), std::string::npos) << e.reason();
  EXPECT_NE(std::string(e.what()).find("tables.yaml:"), std::string::npos);

  e = table_error(
      "    tables:\n"
      "      lift:\n"
      "        command: -1 -0.53 0.53 0.8 1.5\n"
      "        velocity: -0.15 0 0 0.1 0.15 m/s\n");
  EXPECT_EQ(e.field(), "hydraulics.valves.tables.lift.command");
  EXPECT_NE(e.reason().find("[-1, 1]"), std::string::npos) << e.reason();

  e = table_error(
      "    tables:\n"
      "      boom:\n"
      "        command: -1 1\n"
      "        velocity: -0.15 0.15 m/s\n");
  EXPECT_EQ(e.field(), "hydraulics.valves.tables.boom");
  EXPECT_NE(e.reason().find("no joint"), std::string::npos);

  e = table_error(
      "    tables:\n"
      "      tilt:\n"
      "        command: -1 1\n"
      "        velocity: -0.15 0.15\n");
  EXPECT_EQ(e.field(), "hydraulics.valves.tables.tilt.velocity");  // missing unit

  e = table_error(
      "    tables:\n"
      "      tilt:\n"
      "        command: -1 1\n"
      "        speed: -0.15 0.15 m/s\n");
  EXPECT_EQ(e.field(), "hydraulics.valves.tables.tilt.speed");
}

}  // namespace
