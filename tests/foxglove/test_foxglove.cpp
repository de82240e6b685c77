// The field table and what is built on it (docs/foxglove.md, docs/log-format.md): the table and
// the DDS IDL hold together, the CSV header is the documented one, the JSON channels parse and
// match their schemas' fields, the ROS 2 schemas are ROS 2 Jazzy's, the /tf tree is the model's
// forward kinematics, the MCAP file's framing and CRCs, the Foxglove server's address parsing,
// and the loop observers allocate nothing.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "../allocation_counter.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/log_fields.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/foxglove/channels.hpp"
#include "craneassist/foxglove/mcap_recorder.hpp"
#include "craneassist/foxglove/mcap_writer.hpp"
#ifdef CRANEASSIST_FOXGLOVE_SERVER
#include "craneassist/foxglove/foxglove_server.hpp"
#endif

using namespace craneassist;
using json = nlohmann::json;

namespace {

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// struct name -> member names, from the IDL's telemetry structs.
std::map<std::string, std::set<std::string>> idl_members(const std::string& idl) {
  std::map<std::string, std::set<std::string>> out;
  const std::regex struct_re(R"(struct\s+(\w+)\s*\{([^}]*)\})");
  const std::regex member_re(R"(^\s*[\w:<>,\s]+?\s+(\w+)\s*(\[\d+\])?\s*;)");
  for (std::sregex_iterator it(idl.begin(), idl.end(), struct_re), end; it != end; ++it) {
    std::istringstream body((*it)[2].str());
    std::string line;
    while (std::getline(body, line)) {
      line = line.substr(0, line.find("//"));
      std::smatch m;
      if (std::regex_search(line, m, member_re)) out[(*it)[1].str()].insert(m[1].str());
    }
  }
  return out;
}

// One cycle as the loop hands it to its observers (a default machine state).
struct Cycle {
  control::LogRow row;
  valves::MachineState state;
  valves::ValveCommand command;
  control::CycleTime time;
  control::CycleRecord record{time, state, command, row, control::CycleStatus::kRunning, nullptr};
};

// The heap allocations of 500 cycles through `observer` (10 ms apart) on the calling thread (the
// loop's), after a first one that sets its clock. The observer's own writer or I/O thread may
// allocate meanwhile (the MCAP chunks, the WebSocket frames): that is not the loop's.
long allocations_of_cycles(control::CycleObserver& observer, Cycle& c) {
  observer.on_cycle(c.record);
  const long before = test::heap_allocations_on_this_thread();
  for (int k = 0; k < 500; ++k) {
    c.time.t_s = 0.01 * k;
    observer.on_cycle(c.record);
  }
  return test::heap_allocations_on_this_thread() - before;
}

}  // namespace

TEST(FieldTable, HoldsTogetherWithTheIdl) {
  const auto idl = idl_members(
      read_text(std::string(CRANEASSIST_SOURCE_DIR) + "/app/dds/idl/craneassist_msgs.idl"));
  ASSERT_TRUE(idl.count("Status") && idl.count("JointState") && idl.count("Hydraulics") &&
              idl.count("CommandPath") && idl.count("BaseState"));
  std::set<std::string> referenced;
  for (const control::Field& f : control::field_table()) {
    if (f.dds == nullptr) continue;
    const std::string ref(f.dds);
    const auto dot = ref.find('.');
    ASSERT_NE(dot, std::string::npos) << f.name;
    const std::string type = ref.substr(0, dot), member = ref.substr(dot + 1);
    ASSERT_TRUE(idl.count(type)) << f.name << ": no IDL struct " << type;
    EXPECT_TRUE(idl.at(type).count(member)) << f.name << ": no member " << ref << " in the IDL";
    referenced.insert(ref);
  }
  // The IDL's members that are not a field of the table, and why.
  const std::set<std::string> not_fields = {
      "Status.header",
      "JointState.header",
      "Hydraulics.header",
      "CommandPath.header",
      "BaseState.header",
      "Status.crane",
      "Status.backend",
      "Hydraulics.pump_mode",  // fixed for a run
      "JointState.names",
      "JointState.prismatic",  // fixed for a run
      "Status.tip_speed_m_s",  // |tip_v|
      "Status.pump_limit",     // Hydraulics.pump_limit again
      "CommandPath.input_source",
      "CommandPath.deadman",
      "CommandPath.scale",  // Status's again
  };
  for (const char* type : {"Status", "JointState", "Hydraulics", "CommandPath", "BaseState"}) {
    for (const std::string& member : idl.at(type)) {
      const std::string ref = std::string(type) + "." + member;
      EXPECT_TRUE(referenced.count(ref) || not_fields.count(ref))
          << ref << " is in the IDL but neither in the field table nor explained here";
    }
  }
}

TEST(FieldTable, NamesAreUniqueAndDescribed) {
  std::set<std::string> names;
  for (const control::Field& f : control::field_table()) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    EXPECT_GT(std::strlen(f.unit), 0u) << f.name;
    EXPECT_GT(std::strlen(f.meaning), 10u) << f.name;
    EXPECT_GT(std::strlen(f.source), 0u) << f.name;
  }
  EXPECT_GT(names.size(), 60u);
}

TEST(FieldTable, CsvHeaderIsTheDocumentedOne) {
  // docs/log-format.md's columns, in order (as before the table drove the log).
  EXPECT_EQ(control::csv_header(2, false),
            "t,cmd_vx,cmd_vy,cmd_vz,ref_vx,ref_vy,ref_vz,tip_x,tip_y,tip_z,tip_vx,tip_vy,tip_vz,"
            "q1,q2,q1_ref,q2_ref,pump_flow_m3s,pump_pressure_pa,pump_power_w,energy_j,"
            "active_limit,scale,flow_demand_m3s,pump_limit,s,sdot,sddot,sdddot,sddot_min,"
            "sddot_max,tip_error_m,ref_power_w,avail_speed_m_s,avail_speed_resolved_m_s,"
            "polytope_volume_m3s3,spool1,spool2,p_load1_pa,p_load2_pa,load_kg,"
            "payload_estimate_kg,load_moment_ratio,status,swing_deg,swing_radial_deg,"
            "swing_tangential_deg");
  EXPECT_EQ(control::csv_header(2, true),
            control::csv_header(2, false) +
                ",base_x,base_y,base_phi,base_v,base_omega,base_v_cmd,base_omega_cmd,"
                "base_flow_fl_m3s,base_flow_fr_m3s,base_flow_rl_m3s,base_flow_rr_m3s,"
                "base_flow_sum_m3s,base_flow_max_m3s");
}

TEST(FieldTable, GroupJsonFollowsItsSchema) {
  control::LogRow row;
  row.t = 1.25;
  row.q = {0.1, 0.2, 0.3, 0.4};
  row.cmd = {NAN, 0.0, 1.0};
  row.status = "running";
  row.active_limit = "pow\"er";  // escaped
  row.payload_converged = true;
  row.loop_overruns = 3;
  std::set<std::string> every;
  for (const control::FieldGroup g : control::kFieldGroups) {
    std::string text;
    control::append_group_json(row, 4, g, text);
    const json value = json::parse(text);
    const json schema = json::parse(control::group_json_schema(g));
    ASSERT_TRUE(value.is_object()) << text;
    for (const auto& [name, _] : schema["properties"].items()) {
      EXPECT_TRUE(value.contains(name)) << control::to_string(g) << "." << name;
      every.insert(name);
    }
    EXPECT_EQ(value.size(), schema["properties"].size()) << control::to_string(g);
    EXPECT_EQ(schema["required"].size(), schema["properties"].size());
    if (g == control::FieldGroup::kJoints) {
      EXPECT_EQ(value["q"], json::parse("[0.1,0.2,0.3,0.4]"));
      EXPECT_TRUE(value["tip"].contains("x"));
    }
    if (g == control::FieldGroup::kCommand) {
      EXPECT_TRUE(value["cmd"]["x"].is_null());  // NaN
      EXPECT_EQ(value["cmd"]["z"], 1.0);
    }
    if (g == control::FieldGroup::kLimits) {
      EXPECT_EQ(value["active_limit"], "pow\"er");
    }
    if (g == control::FieldGroup::kStatus) {
      EXPECT_EQ(value["t"], 1.25);
      EXPECT_EQ(value["loop_overruns"], 3);
    }
  }
  EXPECT_EQ(every.size(), control::field_table().size());  // every field in one group
}

TEST(FieldTable, FlatValuesFollowTheirNames) {
  control::LogRow row;
  row.q = {1, 2, 3, 4};
  row.tip = {5, 6, 7};
  row.deadman = true;
  std::vector<std::string> names;
  for (const auto& f : control::flat_fields(4, false)) names.push_back(f.name);
  std::vector<double> values(names.size() + 5, -1.0);
  const int n =
      control::flat_field_values(row, 4, false, values.data(), static_cast<int>(values.size()));
  ASSERT_EQ(static_cast<std::size_t>(n), names.size());
  const auto at = [&](const char* name) {
    return values[static_cast<std::size_t>(std::find(names.begin(), names.end(), name) -
                                           names.begin())];
  };
  EXPECT_EQ(at("q.3"), 3.0);
  EXPECT_EQ(at("tip.y"), 6.0);
  EXPECT_EQ(at("deadman"), 1.0);
  EXPECT_EQ(std::count(names.begin(), names.end(), "base_pose.x"), 0);
  const auto with_base = control::flat_fields(4, true);
  EXPECT_EQ(with_base.size(), names.size() + 15);
  const auto phi = std::find_if(with_base.begin(), with_base.end(),
                                [](const auto& f) { return f.name == "base_pose.phi"; });
  ASSERT_NE(phi, with_base.end());
  EXPECT_EQ(phi->unit, "rad");
}

TEST(Channels, Ros2SchemasAreJazzys) {
#ifdef CRANEASSIST_ROS2_MSGDEFS
  // @foxglove/rosmsg-msgs-common's ros2jazzy definitions, comments and blank lines left out.
  const auto definition = [](const char* pkg_msg) {
    std::string p(pkg_msg);
    p.insert(p.find('/'), "/msg");
    std::istringstream in(read_text(std::string(CRANEASSIST_ROS2_MSGDEFS) + "/" + p + ".msg"));
    std::string line, out;
    while (std::getline(in, line)) {
      const auto hash = line.find('#');
      if (hash != std::string::npos) line = line.substr(0, hash);
      while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
      if (!line.empty()) out += line + "\n";
    }
    return out;
  };
  EXPECT_EQ(definition("sensor_msgs/JointState"), foxglove::kJointStateSchema);
  EXPECT_EQ(definition("tf2_msgs/TFMessage"), foxglove::kTfMessageSchema);
  EXPECT_EQ(definition("geometry_msgs/TwistStamped"), foxglove::kTwistStampedSchema);
  EXPECT_EQ(definition("std_msgs/String"), foxglove::kStringSchema);
#else
  GTEST_SKIP() << "no ROS 2 msgdefs (the web page's npm packages) in this build";
#endif
}

TEST(Channels, TfTreeIsTheModelsKinematics) {
  const auto cfg = config::default_crane_config();
  const auto& model = cfg.model;
  ASSERT_TRUE(model.grapple.hangs());
  const auto frames = dynamics::urdf_frames(model);
  ASSERT_EQ(frames.size(), static_cast<std::size_t>(model.dof()) + 3);
  EXPECT_EQ(frames.front().parent, "base_link");
  EXPECT_EQ(frames[static_cast<std::size_t>(model.dof())].child, "tip_link");
  std::vector<Eigen::Isometry3d> t(frames.size());
  dynamics::KinematicsData kin;
  for (int trial = 0; trial < 20; ++trial) {
    dynamics::JointVector q(model.dof());
    for (int i = 0; i < model.dof(); ++i) {
      const auto& j = model.joints[static_cast<std::size_t>(i)];
      q[i] = j.q_min + (j.q_max - j.q_min) * ((trial * 7 + i * 3) % 11) / 10.0;
    }
    dynamics::urdf_transforms(model, dynamics::hanger_axes(model), q.data(), {0.1, -0.2}, t.data());
    Eigen::Isometry3d chain = Eigen::Isometry3d::Identity();
    for (int i = 0; i <= model.dof(); ++i) chain = chain * t[static_cast<std::size_t>(i)];
    dynamics::forward_kinematics(model, kin, q);
    const Eigen::Isometry3d& tip = kin.frames[static_cast<std::size_t>(model.dof())];
    EXPECT_LT((chain.translation() - tip.translation()).norm(), 1e-9);
    EXPECT_LT((chain.linear() - tip.linear()).norm(), 1e-9);
  }
}

TEST(Mcap, Crc32IsZlibs) {
  EXPECT_EQ(foxglove::crc32(0, "123456789", 9), 0xCBF43926U);
  // Continued in two parts: the same.
  EXPECT_EQ(foxglove::crc32(foxglove::crc32(0, "1234", 4), "56789", 5), 0xCBF43926U);
}

TEST(Mcap, FileIsFramedAndItsCrcsHold) {
  const auto path = std::filesystem::temp_directory_path() / "craneassist_test.mcap";
  const auto cfg = config::default_crane_config();
  {
    foxglove::McapOptions options;
    options.chunk_bytes = 4096;  // several chunks
    foxglove::McapWriter w(path, options);
    foxglove::ChannelSet channels(cfg.model, false);
    std::vector<std::uint16_t> ids;
    for (const auto& c : channels.channels()) ids.push_back(w.add_channel(c));
    std::vector<std::uint8_t> data;
    control::LogRow row;
    for (int k = 0; k < 200; ++k) {
      row.t = 0.01 * k;
      for (std::size_t c = 1; c < channels.size(); ++c) {
        channels.encode(c, row, k * 10'000'000, data);
        w.write(ids[c], static_cast<std::uint64_t>(k) * 10'000'000, data.data(), data.size());
      }
    }
    w.close();
    EXPECT_EQ(w.stats().messages, 200u * (channels.size() - 1));
    EXPECT_GT(w.stats().chunks, 3u);
  }
  const std::string f = read_text(path);
  const auto u64 = [&](std::size_t at) {
    std::uint64_t v = 0;
    std::memcpy(&v, f.data() + at, 8);
    return v;
  };
  const auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, f.data() + at, 4);
    return v;
  };
  const std::string magic("\x89MCAP0\r\n", 8);
  ASSERT_GT(f.size(), 100u);
  EXPECT_EQ(f.substr(0, 8), magic);
  EXPECT_EQ(f.substr(f.size() - 8), magic);
  const std::size_t footer = f.size() - 8 - 29;
  EXPECT_EQ(f[footer], 0x02);
  const std::uint64_t summary_start = u64(footer + 9);
  const std::uint64_t summary_offsets = u64(footer + 17);
  EXPECT_EQ(f[summary_start], 0x03);  // the summary begins with the schemas
  EXPECT_EQ(f[summary_offsets], 0x0E);
  // Data End just before the summary, with the CRC of everything before it.
  const std::size_t data_end = summary_start - 13;
  EXPECT_EQ(f[data_end], 0x0F);
  EXPECT_EQ(u32(data_end + 9), foxglove::crc32(0, f.data(), data_end));
  // The summary CRC: from the summary to the footer's summary_offset_start.
  EXPECT_EQ(u32(footer + 25),
            foxglove::crc32(0, f.data() + summary_start, footer + 25 - summary_start));
  std::filesystem::remove(path);
}

TEST(Mcap, UnwritableFileIsNamed) {
  try {
    foxglove::McapWriter w("/nonexistent-dir/x.mcap", {});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.mcap"), std::string::npos);
  }
}

TEST(Mcap, RecorderOnCycleDoesNotAllocate) {
  const auto cfg = config::default_crane_config();
  const auto path = std::filesystem::temp_directory_path() / "craneassist_test_rec.mcap";
  foxglove::McapRecorder recorder(path, cfg.model, false);
  Cycle cycle;
  EXPECT_EQ(allocations_of_cycles(recorder, cycle), 0);
  recorder.on_finish(cycle.time, cycle.state);
  EXPECT_GT(recorder.stats().messages, 0u);
  std::filesystem::remove(path);
}

#ifdef CRANEASSIST_FOXGLOVE_SERVER
TEST(FoxgloveServer, ParsesListenAddresses) {
  foxglove::ServerOptions o;
  std::string why;
  EXPECT_TRUE(foxglove::parse_listen_address("9000", o, why));
  EXPECT_EQ(o.address, "127.0.0.1");
  EXPECT_EQ(o.port, 9000);
  EXPECT_TRUE(foxglove::parse_listen_address("0.0.0.0:8765", o, why));
  EXPECT_EQ(o.address, "0.0.0.0");
  EXPECT_TRUE(foxglove::parse_listen_address("[::1]:1", o, why));
  EXPECT_EQ(o.address, "::1");
  for (const char* bad : {"", "x", "70000", "host:1", ":80", "1.2.3.4:", "1.2.3.4:-1", "123456"}) {
    EXPECT_FALSE(foxglove::parse_listen_address(bad, o, why)) << bad;
    EXPECT_FALSE(why.empty());
  }
}

TEST(FoxgloveServer, ObserverDoesNotAllocateAndBusyPortIsNamed) {
  const auto cfg = config::default_crane_config();
  foxglove::ServerOptions o;
  o.port = 0;
  foxglove::FoxgloveServer server(o, cfg.model);
  Cycle cycle;
  EXPECT_EQ(allocations_of_cycles(server.observer(), cycle), 0);
  foxglove::ServerOptions same = o;
  same.port = server.port();
  try {
    foxglove::FoxgloveServer second(same, cfg.model);
    FAIL() << "a second server on a busy port";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(server.port())), std::string::npos);
  }
  server.stop();
}
#endif
