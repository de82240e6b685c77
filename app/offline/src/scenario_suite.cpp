#include "craneassist/offline/scenario_suite.hpp"

#include <cmath>
#include <cstdio>
#include <optional>

#include "craneassist/config/quantity.hpp"
#include "craneassist/config/yaml_reader.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

namespace craneassist::offline {
namespace {

constexpr const char* kFormat = "craneassist-suite/1";

class SuiteReader : public config::YamlReader {
 public:
  using YamlReader::YamlReader;

  double quantity(const YAML::Node& map, const std::string& key, const std::string& path,
                  config::Dimension dimension, double lo, double hi) const {
    const YAML::Node node = child(map, key, path);
    const std::string field = join(path, key);
    if (!node.IsScalar()) fail(node, field, "expected a single value");
    std::string error;
    const auto q = config::parse_quantity(node.Scalar(), dimension, error);
    if (!q || q->si_values.size() != 1) fail(node, field, error.empty() ? "one value" : error);
    const double v = q->si_values[0];
    if (!(v >= lo && v <= hi)) fail(node, field, "out of range");
    return v;
  }

  std::optional<int> count(const YAML::Node& node, const std::string& key,
                           const std::string& path) const {
    if (!node[key].IsDefined()) return std::nullopt;
    const YAML::Node n = node[key];
    int v = -1;
    if (!n.IsScalar() || !YAML::convert<int>::decode(n, v) || v < 0) {
      fail(n, join(path, key), "expected a count (0, 1, ...)");
    }
    return v;
  }

  void targets(const YAML::Node& node, const std::string& path, SuiteTargets& t) const {
    check_keys(
        node, path,
        {"stall_events", "lateral_speed", "peak_power", "direction_error", "direction_error_p95",
         "stop_timeouts", "residual_swing", "cycle_time", "timed_out_waits", "overload_cycles"});
    if (auto v = count(node, "stall_events", path)) t.stall_events = v;
    if (auto v = count(node, "stop_timeouts", path)) t.stop_timeouts = v;
    if (node["direction_error_p95"].IsDefined()) {
      t.direction_error_p95_rad =
          quantity(node, "direction_error_p95", path, config::Dimension::kAngle, 0.0, M_PI);
    }
    if (auto v = count(node, "timed_out_waits", path)) t.timed_out_waits = v;
    if (auto v = count(node, "overload_cycles", path)) t.overload_cycles = v;
    if (node["residual_swing"].IsDefined()) {
      t.residual_swing_rad =
          quantity(node, "residual_swing", path, config::Dimension::kAngle, 0.0, M_PI);
    }
    if (node["cycle_time"].IsDefined()) {
      t.cycle_time_s = quantity(node, "cycle_time", path, config::Dimension::kTime, 0.0, 1e6);
    }
    if (node["lateral_speed"].IsDefined()) {
      t.lateral_speed_m_s =
          quantity(node, "lateral_speed", path, config::Dimension::kVelocity, 0.0, 100.0);
    }
    if (node["peak_power"].IsDefined()) {
      t.peak_power_share =
          quantity(node, "peak_power", path, config::Dimension::kDimensionless, 0.0, 10.0);
    }
    if (node["direction_error"].IsDefined()) {
      t.direction_error_rad =
          quantity(node, "direction_error", path, config::Dimension::kAngle, 0.0, M_PI);
    }
  }
};

void merge(const SuiteTargets& over, SuiteTargets& t) {
  if (over.stall_events) t.stall_events = over.stall_events;
  if (over.lateral_speed_m_s) t.lateral_speed_m_s = over.lateral_speed_m_s;
  if (over.peak_power_share) t.peak_power_share = over.peak_power_share;
  if (over.direction_error_rad) t.direction_error_rad = over.direction_error_rad;
  if (over.direction_error_p95_rad) t.direction_error_p95_rad = over.direction_error_p95_rad;
  if (over.stop_timeouts) t.stop_timeouts = over.stop_timeouts;
  if (over.residual_swing_rad) t.residual_swing_rad = over.residual_swing_rad;
  if (over.cycle_time_s) t.cycle_time_s = over.cycle_time_s;
  if (over.timed_out_waits) t.timed_out_waits = over.timed_out_waits;
  if (over.overload_cycles) t.overload_cycles = over.overload_cycles;
}

std::string figure(const char* format, double value) {
  char text[96];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace

std::string SuiteRun::name() const {
  std::string n = replay_text + " @" + pose;
  const bool undamped = sway_damping.has_value() && !*sway_damping;
  if (scaling != control::ScalingMode::kFull || undamped) {
    n += " (";
    if (scaling != control::ScalingMode::kFull) {
      n += std::string("scaling ") + control::to_string(scaling) + (undamped ? ", " : "");
    }
    if (undamped) n += "no sway damping";
    n += ")";
  }
  return n;
}

Suite parse_suite(std::string_view yaml_text, std::string_view source_name,
                  const std::filesystem::path& base_dir) {
  return config::read_yaml(yaml_text, source_name, [&](const YAML::Node& root) {
    const SuiteReader r{std::string(source_name)};
    Suite suite;
    suite.source = std::string(source_name);
    r.check_keys(root, "", {"format", "poses", "targets", "runs"});
    const std::string format = r.text(root, "format", "");
    if (format != kFormat) {
      r.fail(root["format"], "format",
             "unsupported format '" + format + "' (expected " + kFormat + ")");
    }
    // Poses: name -> text and line (check_suite checks them against the crane that runs them).
    struct Pose {
      std::string name, text;
      int line;
    };
    std::vector<Pose> poses;
    if (root["poses"].IsDefined()) {
      const YAML::Node p = root["poses"];
      if (!p.IsMap()) r.fail(p, "poses", "expected name: pose pairs");
      for (const auto& kv : p) {
        const std::string name = kv.first.Scalar();
        if (name == "default") r.fail(kv.first, "poses.default", "default is the config's pose");
        if (!kv.second.IsScalar()) {
          r.fail(kv.second, "poses." + name, "expected NAME=VALUE UNIT, ...");
        }
        poses.push_back({name, kv.second.Scalar(), kv.second.Mark().line + 1});
      }
    }
    SuiteTargets defaults;
    if (root["targets"].IsDefined()) r.targets(root["targets"], "targets", defaults);

    const YAML::Node runs = r.child(root, "runs", "");
    if (!runs.IsSequence() || runs.size() == 0) r.fail(runs, "runs", "expected a list of runs");
    for (std::size_t k = 0; k < runs.size(); ++k) {
      const YAML::Node node = runs[k];
      const std::string path = "runs[" + std::to_string(k) + "]";
      r.check_keys(node, path,
                   {"replay", "poses", "payload", "payload_known", "scaling", "sway_damping",
                    "wait_swing", "targets"});
      SuiteRun run;
      run.line = node.Mark().line + 1;
      run.replay_text = r.text(node, "replay", path);
      run.replay = base_dir / run.replay_text;
      // The error_code form: a name the file system refuses (too long, say) is a bad entry of
      // the manifest, not an exception from the file system.
      std::error_code ec;
      const auto status = std::filesystem::status(run.replay, ec);
      if (status.type() != std::filesystem::file_type::regular) {
        const bool missing = status.type() == std::filesystem::file_type::not_found || !ec;
        r.fail(node["replay"], path + ".replay",
               missing ? "no such file: " + run.replay.string()
                       : "cannot use " + run.replay.string() + ": " + ec.message());
      }
      if (node["payload"].IsDefined()) {
        run.payload_kg = r.quantity(node, "payload", path, config::Dimension::kMass, 0.0, 1e5);
      }
      run.payload_known = r.flag(node, "payload_known", path, false);
      if (node["sway_damping"].IsDefined()) {
        run.sway_damping = r.flag(node, "sway_damping", path, true);
      }
      if (node["scaling"].IsDefined()) {
        run.scaling = r.one_of(node, "scaling", path, control::kScalingModes);
      }
      if (node["wait_swing"].IsDefined()) {
        run.wait_swing_rad =
            r.quantity(node, "wait_swing", path, config::Dimension::kAngle, 1e-4, M_PI / 2.0);
      }
      run.targets = defaults;
      if (node["targets"].IsDefined()) {
        SuiteTargets own;
        r.targets(node["targets"], path + ".targets", own);
        merge(own, run.targets);
      }
      std::vector<std::string> names{"default"};
      if (node["poses"].IsDefined()) {
        const YAML::Node list = node["poses"];
        if (!list.IsSequence() || list.size() == 0) {
          r.fail(list, path + ".poses", "expected a list of pose names");
        }
        names.clear();
        for (const auto& n : list) names.push_back(n.Scalar());
      }
      for (const auto& name : names) {
        SuiteRun entry = run;
        entry.pose = name;
        if (name != "default") {
          bool found = false;
          for (const auto& pose : poses) {
            if (pose.name == name) {
              entry.pose_text = pose.text;
              entry.pose_line = pose.line;
              found = true;
            }
          }
          if (!found) r.fail(node["poses"], path + ".poses", "no pose named '" + name + "'");
        }
        suite.runs.push_back(entry);
      }
    }
    return suite;
  });
}

void check_suite(const Suite& suite, const config::CraneConfig& cfg) {
  for (const auto& run : suite.runs) {
    if (run.pose_text.empty()) continue;
    try {
      config::parse_joint_pose(cfg.model, run.pose_text, cfg.simulation.q_initial);
    } catch (const std::invalid_argument& e) {
      throw config::ConfigError(suite.source, run.pose_line, "poses." + run.pose,
                                std::string(e.what()) + " (crane " + cfg.model.name + ")");
    }
  }
}

Suite load_suite(const std::filesystem::path& path) {
  return parse_suite(config::read_yaml_file(path, "suite manifest"), path.string(),
                     path.parent_path());
}

config::CraneConfig SuiteVariant::apply(const config::CraneConfig& cfg) const {
  config::CraneConfig out = cfg;
  out.simulation.valves = valves;
  out.simulation.joints = joints;
  return out;
}

std::vector<SuiteVariant> parse_variants(std::string_view yaml_text, std::string_view source_name,
                                         const config::CraneConfig& cfg) {
  return config::read_yaml(yaml_text, source_name, [&](const YAML::Node& root) {
    constexpr const char* kVariantsFormat = "craneassist-variants/1";
    const SuiteReader r{std::string(source_name)};
    r.check_keys(root, "", {"format", "targets", "variants"});
    const std::string format = r.text(root, "format", "");
    if (format != kVariantsFormat) {
      r.fail(root["format"], "format",
             "unsupported format '" + format + "' (expected " + kVariantsFormat + ")");
    }
    SuiteTargets defaults;
    if (root["targets"].IsDefined()) r.targets(root["targets"], "targets", defaults);
    const YAML::Node list = r.child(root, "variants", "");
    if (!list.IsSequence() || list.size() == 0) {
      r.fail(list, "variants", "expected a list of variants");
    }
    std::vector<SuiteVariant> out;
    for (std::size_t k = 0; k < list.size(); ++k) {
      const YAML::Node node = list[k];
      const std::string path = "variants[" + std::to_string(k) + "]";
      r.check_keys(node, path, {"name", "simulation", "targets"});
      SuiteVariant v;
      v.line = node.Mark().line + 1;
      v.name = r.text(node, "name", path);
      for (const auto& other : out) {
        if (other.name == v.name) r.fail(node["name"], path + ".name", "a second '" + v.name + "'");
      }
      config::CraneConfig machine = cfg;
      if (node["simulation"].IsDefined()) {
        config::apply_simulated_machine(node["simulation"], std::string(source_name),
                                        path + ".simulation", machine);
      }
      v.valves = machine.simulation.valves;
      v.joints = machine.simulation.joints;
      v.targets = defaults;
      if (node["targets"].IsDefined()) {
        SuiteTargets own;
        r.targets(node["targets"], path + ".targets", own);
        merge(own, v.targets);
      }
      out.push_back(std::move(v));
    }
    return out;
  });
}

std::vector<SuiteVariant> load_variants(const std::filesystem::path& path,
                                        const config::CraneConfig& cfg) {
  return parse_variants(config::read_yaml_file(path, "variants file"), path.string(), cfg);
}

SuiteOutcome run_suite_run(const config::CraneConfig& base, const SuiteRun& run,
                           const std::string& resolution, const std::filesystem::path& log_file) {
  return run_suite_run(base, run, SuiteTargets{}, resolution, log_file);
}

SuiteOutcome run_suite_run(const config::CraneConfig& base, const SuiteRun& run,
                           const SuiteTargets& over, const std::string& resolution,
                           const std::filesystem::path& log_file) {
  config::CraneConfig cfg = base;
  config::set_payload_mass(cfg.model, run.payload_kg);
  if (!run.pose_text.empty()) {
    cfg.simulation.q_initial =
        config::parse_joint_pose(cfg.model, run.pose_text, cfg.simulation.q_initial);
  }
  if (!resolution.empty()) config::set_resolution(cfg, resolution);
  if (run.sway_damping) cfg.scaling.sway_damping = *run.sway_damping;
  const auto replay = input::Replay::load_file(run.replay);
  sim_backend::SimBackend machine(cfg.model, sim_settings(cfg));
  std::optional<control::CsvLog> log;
  if (!log_file.empty()) log.emplace(log_file, cfg.model.dof());
  control::RunOptions options;
  options.controller.payload_known = run.payload_known;
  options.controller.mode = run.scaling;
  options.waits = control::wait_settings(cfg, run.wait_swing_rad);
  SuiteOutcome out;
  out.summary = control::run_replay(cfg, replay, machine, options, log ? &*log : nullptr);
  out.p_max_w = cfg.model.pump.prime_mover_power_w;

  const auto& s = out.summary;
  SuiteTargets t = run.targets;
  merge(over, t);
  if (t.stall_events && s.feel.stall_events > *t.stall_events) {
    out.missed.push_back("stall events " + std::to_string(s.feel.stall_events) + " > " +
                         std::to_string(*t.stall_events));
  }
  if (t.lateral_speed_m_s && s.feel.one_line && s.feel.lateral_peak_m_s > *t.lateral_speed_m_s) {
    out.missed.push_back(figure("lateral speed %.3f m/s", s.feel.lateral_peak_m_s) +
                         figure(" > %.3f", *t.lateral_speed_m_s));
  }
  if (t.peak_power_share && s.peak_power_w > *t.peak_power_share * out.p_max_w) {
    out.missed.push_back(figure("peak power %.3f of P_max", s.peak_power_w / out.p_max_w) +
                         figure(" > %.3f", *t.peak_power_share));
  }
  if (t.direction_error_rad && s.max_direction_error_deg * M_PI / 180.0 > *t.direction_error_rad) {
    out.missed.push_back(figure("direction error %.2f deg", s.max_direction_error_deg) +
                         figure(" > %.2f", *t.direction_error_rad * 180.0 / M_PI));
  }
  if (t.direction_error_p95_rad &&
      s.p95_direction_error_deg * M_PI / 180.0 > *t.direction_error_p95_rad) {
    out.missed.push_back(figure("direction error p95 %.2f deg", s.p95_direction_error_deg) +
                         figure(" > %.2f", *t.direction_error_p95_rad * 180.0 / M_PI));
  }
  if (t.stop_timeouts && s.stop.timeouts > *t.stop_timeouts) {
    out.missed.push_back("stops still moving at neutral " + std::to_string(s.stop.timeouts) +
                         " > " + std::to_string(*t.stop_timeouts));
  }
  const double residual = s.waits.residual_swing_deg;
  if (t.residual_swing_rad && std::isfinite(residual) &&
      residual * M_PI / 180.0 > *t.residual_swing_rad) {
    out.missed.push_back(figure("residual swing %.2f deg", residual) +
                         figure(" > %.2f", *t.residual_swing_rad * 180.0 / M_PI));
  }
  if (t.cycle_time_s && s.waits.waits > 0 && s.cycle_time_s > *t.cycle_time_s) {
    out.missed.push_back(figure("cycle time %.2f s", s.cycle_time_s) +
                         figure(" > %.2f", *t.cycle_time_s));
  }
  if (t.timed_out_waits && s.waits.timed_out > *t.timed_out_waits) {
    out.missed.push_back("timed-out waits " + std::to_string(s.waits.timed_out) + " > " +
                         std::to_string(*t.timed_out_waits));
  }
  if (t.overload_cycles && s.load.overload_cycles > *t.overload_cycles) {
    out.missed.push_back("overload cycles " + std::to_string(s.load.overload_cycles) + " > " +
                         std::to_string(*t.overload_cycles));
  }
  return out;
}

}  // namespace craneassist::offline
