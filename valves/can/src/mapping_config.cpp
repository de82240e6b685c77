#include "craneassist/can/mapping_config.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <sstream>

#include "craneassist/can/address_claim.hpp"
#include "craneassist/can/dbc.hpp"
#include "craneassist/can/valve_frames.hpp"
#include "craneassist/config/config_error.hpp"
#include "craneassist/config/quantity.hpp"
#include "craneassist/config/yaml_reader.hpp"

namespace craneassist::can {
namespace {

using config::ConfigError;
using config::Dimension;

// What a signal measures or commands; decides which units its `unit` may name.
enum class SignalUse { kPosition, kPressure, kCommand, kFlow, kAngle };

class Reader : public config::YamlReader {
 public:
  using YamlReader::YamlReader;

  // The mapping's DBC file (top-level `dbc:`), when it has one: signals may name its signals.
  std::optional<Dbc> dbc;

  // The DBC message and signal a `{dbc: Message.Signal}` entry names (signal null for a message
  // reference `{dbc: Message}`); fails naming the entry when the DBC has no such thing.
  std::pair<const DbcMessage*, const DbcSignal*> dbc_entry(const YAML::Node& node,
                                                           const std::string& path,
                                                           bool signal_wanted) const {
    const YAML::Node ref = node["dbc"];
    const std::string field = join(path, "dbc");
    const std::string name = text(ref, field);
    if (!dbc) fail(ref, field, "names a DBC entry, but the mapping has no top-level 'dbc: FILE'");
    const auto dot = name.find('.');
    if (signal_wanted == (dot == std::string::npos)) {
      fail(ref, field,
           signal_wanted ? "expected MESSAGE.SIGNAL, got '" + name + "'"
                         : "expected a message name, got '" + name + "'");
    }
    const std::string message_name = name.substr(0, dot);
    const DbcMessage* m = dbc->message(message_name);
    if (m == nullptr) {
      std::string known;
      for (const auto& other : dbc->messages) {
        if (known.size() > 200) {
          known += ", ...";
          break;
        }
        known += (known.empty() ? "" : ", ") + other.name;
      }
      fail(ref, field,
           "no message '" + message_name + "' in " + dbc->source + " (it has " +
               (known.empty() ? std::string("none") : known) + ")");
    }
    if (!signal_wanted) return {m, nullptr};
    const std::string signal_name = name.substr(dot + 1);
    for (const auto& s : m->signals) {
      if (s.name != signal_name) continue;
      if (s.multiplexed) {
        fail(ref, field,
             dbc->source + ":" + std::to_string(s.line) + ": signal '" + name +
                 "' is multiplexed; multiplexed signals are not supported");
      }
      if (s.value_type != 0) {
        fail(ref, field,
             dbc->source + ":" + std::to_string(s.line) + ": signal '" + name +
                 "' is a floating-point value (SIG_VALTYPE_); not supported");
      }
      return {m, &s};
    }
    std::string known;
    for (const auto& s : m->signals) known += (known.empty() ? "" : ", ") + s.name;
    fail(ref, field,
         "message '" + message_name + "' in " + dbc->source + " has no signal '" + signal_name +
             "' (it has " + (known.empty() ? "none" : known) + ")");
  }

  std::string text(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) fail(node, field, "expected a single value");
    return node.Scalar();
  }

  // A non-negative integer, decimal or 0x-prefixed hex, at most max_value.
  std::uint64_t integer(const YAML::Node& map, const std::string& key, const std::string& path,
                        std::uint64_t max_value) const {
    return integer(child(map, key, path), join(path, key), max_value);
  }

  // The same for a node itself (a list entry).
  std::uint64_t integer(const YAML::Node& node, const std::string& field,
                        std::uint64_t max_value) const {
    const std::string s = text(node, field);
    std::uint64_t v = 0;
    const bool hex = s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
    const char* begin = s.data() + (hex ? 2 : 0);
    const char* end = s.data() + s.size();
    const auto [ptr, ec] = std::from_chars(begin, end, v, hex ? 16 : 10);
    if (ec != std::errc() || ptr != end || begin == end) {
      fail(node, field, "expected a non-negative integer (decimal or 0x hex), got '" + s + "'");
    }
    if (v > max_value) fail(node, field, "must be at most " + std::to_string(max_value));
    return v;
  }

  double number(const YAML::Node& node, const std::string& field) const {
    const std::string s = text(node, field);
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v)) {
      fail(node, field, "not a number: '" + s + "'");
    }
    return v;
  }

  // A time such as "20 ms", in [lo, hi] seconds.
  double time(const YAML::Node& map, const std::string& key, const std::string& path, double lo,
              double hi, const std::string& range_text) const {
    const YAML::Node node = child(map, key, path);
    const std::string field = join(path, key);
    std::string error;
    const auto q = config::parse_quantity(text(node, field), Dimension::kTime, error);
    if (!q) fail(node, field, error);
    if (q->si_values.size() != 1) fail(node, field, "expected one value");
    const double v = q->si_values[0];
    if (!(v >= lo && v <= hi)) fail(node, field, "must be " + range_text);
    return v;
  }
};

// SI factor of a unit as the mapping file writes it; false if the unit does not suit the use.
bool unit_factor(const std::string& unit, SignalUse use, double& factor, PositionKind& kind) {
  std::string error;
  switch (use) {
    case SignalUse::kPosition:
      if (auto q = config::parse_quantity("1 " + unit, Dimension::kAngle, error)) {
        factor = q->si_values[0];
        kind = PositionKind::kAngle;
        return true;
      }
      if (auto q = config::parse_quantity("1 " + unit, Dimension::kLength, error)) {
        factor = q->si_values[0];
        kind = PositionKind::kLength;
        return true;
      }
      return false;
    case SignalUse::kPressure:
      if (auto q = config::parse_quantity("1 " + unit, Dimension::kPressure, error)) {
        factor = q->si_values[0];
        return true;
      }
      return false;
    case SignalUse::kFlow:
      if (auto q = config::parse_quantity("1 " + unit, Dimension::kFlow, error)) {
        factor = q->si_values[0];
        return true;
      }
      return false;
    case SignalUse::kAngle:
      if (auto q = config::parse_quantity("1 " + unit, Dimension::kAngle, error)) {
        factor = q->si_values[0];
        kind = PositionKind::kAngle;
        return true;
      }
      return false;
    case SignalUse::kCommand:
      if (unit == "A")
        factor = 1.0;
      else if (unit == "mA")
        factor = 1e-3;
      else if (unit == "%")
        factor = 1e-2;
      else if (unit == "1")
        factor = 1.0;
      else
        return false;
      return true;
  }
  return false;
}

const char* units_text(SignalUse use) {
  switch (use) {
    case SignalUse::kPosition:
      return "an angle (rad, deg) or a length (m, mm, cm)";
    case SignalUse::kPressure:
      return "a pressure (Pa, kPa, MPa, bar)";
    case SignalUse::kCommand:
      return "a current (A, mA) or a ratio (%, 1)";
    case SignalUse::kFlow:
      return "a volume flow (L/min, m^3/s)";
    case SignalUse::kAngle:
      return "an angle (rad, deg)";
  }
  return "";
}

// A signal named in the mapping's DBC: `{dbc: Message.Signal}`, optionally with `unit:` when the
// DBC's unit is not one craneassist knows (a DBC may write "°" or nothing at all), and the keys
// of the entry that are not layout (a valve signal's `cycle`).
SignalSpec read_dbc_signal(const Reader& r, const YAML::Node& node, const std::string& path,
                           SignalUse use, std::initializer_list<const char*> keys,
                           PositionKind* kind_out) {
  const bool has_cycle = std::any_of(keys.begin(), keys.end(),
                                     [](const char* k) { return std::string(k) == "cycle"; });
  if (has_cycle) {
    r.check_keys(node, path, {"dbc", "unit", "cycle"});
  } else {
    r.check_keys(node, path, {"dbc", "unit"});
  }
  const auto [message, signal] = r.dbc_entry(node, path, true);
  SignalSpec s = signal->spec;
  std::string where = r.dbc->source + ":" + std::to_string(signal->line);
  if (node["unit"].IsDefined()) {
    s.unit = r.text(node["unit"], Reader::join(path, "unit"));
    where = "unit";
  }
  double factor = 1.0;
  PositionKind kind = PositionKind::kAngle;
  if (!unit_factor(s.unit, use, factor, kind)) {
    r.fail(node, path,
           "unit '" + s.unit + "' (" + where + ") is not " + units_text(use) +
               (node["unit"].IsDefined() ? "" : "; give 'unit:' to say what the DBC's unit is"));
  }
  if (kind_out) *kind_out = kind;
  s.scale *= factor;
  s.offset *= factor;
  if (s.minimum) *s.minimum *= factor;
  if (s.maximum) *s.maximum *= factor;
  s.unit_si = factor;
  (void)message;
  return s;
}

// Where a signal sits: id, extended, start_bit, length, byte_order, signed.
void read_layout(const Reader& r, const YAML::Node& node, const std::string& path, SignalSpec& s) {
  s.extended = r.flag(node, "extended", path, false);
  s.id = static_cast<std::uint32_t>(
      r.integer(node, "id", path, s.extended ? kMaxExtendedId : kMaxStandardId));
  s.start_bit = static_cast<std::uint16_t>(r.integer(node, "start_bit", path, 63));
  const YAML::Node length_node = r.child(node, "length", path);
  s.length = static_cast<std::uint16_t>(r.integer(node, "length", path, 64));
  if (s.length == 0) r.fail(length_node, Reader::join(path, "length"), "must be 1..64");
  const YAML::Node order_node = r.child(node, "byte_order", path);
  const std::string order = r.text(order_node, Reader::join(path, "byte_order"));
  if (order == "intel" || order == "little_endian") {
    s.byte_order = ByteOrder::kLittleEndian;
  } else if (order == "motorola" || order == "big_endian") {
    s.byte_order = ByteOrder::kBigEndian;
  } else {
    r.fail(order_node, Reader::join(path, "byte_order"),
           "expected intel, little_endian, motorola or big_endian, got '" + order + "'");
  }
  s.is_signed = r.flag(node, "signed", path, false);
  if (validate(s) == SpecError::kDoesNotFit) {
    r.fail(node["start_bit"], Reader::join(path, "start_bit"),
           "the signal (start bit " + std::to_string(s.start_bit) + ", " +
               std::to_string(s.length) + " bits, " + order + ") runs past the 8th data byte");
  }
}

SignalSpec read_signal(const Reader& r, const YAML::Node& node, const std::string& path,
                       SignalUse use, std::initializer_list<const char*> keys,
                       PositionKind* kind_out) {
  if (node.IsMap() && node["dbc"].IsDefined()) {
    return read_dbc_signal(r, node, path, use, keys, kind_out);
  }
  r.check_keys(node, path, keys);
  SignalSpec s;
  read_layout(r, node, path, s);

  const YAML::Node unit_node = r.child(node, "unit", path);
  s.unit = r.text(unit_node, Reader::join(path, "unit"));
  double factor = 1.0;
  PositionKind kind = PositionKind::kAngle;
  if (!unit_factor(s.unit, use, factor, kind)) {
    r.fail(unit_node, Reader::join(path, "unit"),
           "unit '" + s.unit + "' is not " + units_text(use));
  }
  if (kind_out) *kind_out = kind;

  const YAML::Node scale_node = r.child(node, "scale", path);
  const double scale = r.number(scale_node, Reader::join(path, "scale"));
  if (scale == 0.0) r.fail(scale_node, Reader::join(path, "scale"), "must be nonzero");
  s.scale = scale * factor;
  s.unit_si = factor;
  if (node["offset"].IsDefined()) {
    s.offset = r.number(node["offset"], Reader::join(path, "offset")) * factor;
  }
  if (node["min"].IsDefined())
    s.minimum = r.number(node["min"], Reader::join(path, "min")) * factor;
  if (node["max"].IsDefined())
    s.maximum = r.number(node["max"], Reader::join(path, "max")) * factor;
  if (s.minimum && s.maximum && *s.minimum > *s.maximum) {
    r.fail(node["min"], Reader::join(path, "min"), "must be at most max");
  }
  const SpecError e = validate(s);
  if (e != SpecError::kNone) r.fail(node, path, to_string(e));
  return s;
}

constexpr std::initializer_list<const char*> kSignalKeys = {
    "id",    "extended", "start_bit", "length", "byte_order", "signed",
    "scale", "offset",   "unit",      "min",    "max"};

ValveOutput read_valve(const Reader& r, const YAML::Node& node, const std::string& path) {
  r.check_keys(node, path, {"iso11783_avc", "signal", "reply"});
  const bool has_avc = node["iso11783_avc"].IsDefined();
  const bool has_signal = node["signal"].IsDefined();
  if (has_avc == has_signal) {
    r.fail(node, path, "expected exactly one of iso11783_avc or signal");
  }
  ValveOutput out;
  if (has_avc) {
    const std::string p = Reader::join(path, "iso11783_avc");
    const YAML::Node a = node["iso11783_avc"];
    r.check_keys(
        a, p, {"valve", "source_address", "cycle", "priority", "fail_safe", "extended_resolution"});
    out.kind = ValveOutputKind::kIso11783Avc;
    out.avc.valve =
        static_cast<std::uint8_t>(r.integer(a, "valve", p, iso11783::kAuxValveCount - 1));
    out.avc.source_address = static_cast<std::uint8_t>(r.integer(a, "source_address", p, 253));
    out.avc.cycle_s = r.time(a, "cycle", p, 0.001, 0.1, "between 1 ms and 100 ms");
    if (a["priority"].IsDefined()) {
      out.avc.priority = static_cast<std::uint8_t>(r.integer(a, "priority", p, 7));
    }
    if (a["fail_safe"].IsDefined()) {
      const std::string f = r.text(a["fail_safe"], Reader::join(p, "fail_safe"));
      if (f == "block") {
        out.avc.fail_safe = iso11783::FailSafeMode::kBlock;
      } else if (f == "float") {
        out.avc.fail_safe = iso11783::FailSafeMode::kFloat;
      } else {
        r.fail(a["fail_safe"], Reader::join(p, "fail_safe"),
               "expected block or float, got '" + f + "'");
      }
    }
    out.avc.extended_resolution = r.flag(a, "extended_resolution", p, true);
  } else {
    const std::string p = Reader::join(path, "signal");
    const YAML::Node s = node["signal"];
    std::initializer_list<const char*> keys = {"id",         "extended", "start_bit", "length",
                                               "byte_order", "signed",   "scale",     "offset",
                                               "unit",       "min",      "max",       "cycle"};
    out.kind = ValveOutputKind::kSignal;
    out.signal.signal = read_signal(r, s, p, SignalUse::kCommand, keys, nullptr);
    if (s.IsMap() && s["dbc"].IsDefined() && !s["cycle"].IsDefined()) {
      // The DBC's GenMsgCycleTime, when it gives one.
      const DbcMessage* m = r.dbc_entry(s, p, true).first;
      if (!m->cycle_s) {
        r.fail(s, Reader::join(p, "cycle"),
               "missing, and " + r.dbc->source + " gives no cycle time (GenMsgCycleTime) for " +
                   m->name);
      }
      out.signal.cycle_s = *m->cycle_s;
      if (!(out.signal.cycle_s >= 0.001 && out.signal.cycle_s <= 0.1)) {
        r.fail(s["dbc"], Reader::join(p, "dbc"),
               "the DBC's cycle time of " + m->name + " must be between 1 ms and 100 ms");
      }
    } else {
      out.signal.cycle_s = r.time(s, "cycle", p, 0.001, 0.1, "between 1 ms and 100 ms");
    }
  }
  return out;
}

std::string hex_address(std::uint8_t a) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", static_cast<unsigned>(a));
  return buf;
}

// A J1939 source address of another node, 0..253, written like `source_address: 0x20`.
std::uint8_t node_address(const Reader& r, const YAML::Node& map, const std::string& key,
                          const std::string& path) {
  return static_cast<std::uint8_t>(r.integer(map, key, path, 253));
}

// `valve.reply`: the valve's Estimated Flow (ISO 11783-7 valves) or the driver's status signal
// (signal valves), and how long it may stay away.
ValveReply read_reply(const Reader& r, const YAML::Node& node, const std::string& path,
                      const ValveOutput& valve) {
  ValveReply reply;
  if (valve.kind == ValveOutputKind::kIso11783Avc) {
    r.check_keys(node, path, {"source_address", "timeout"});
    reply.source_address = node_address(r, node, "source_address", path);
    if (reply.source_address == valve.avc.source_address) {
      r.fail(node["source_address"], Reader::join(path, "source_address"),
             "is the command's source address (craneassist's own): the reply comes from the "
             "valve's address");
    }
  } else {
    r.check_keys(node, path, {"status", "timeout"});
    const std::string p = Reader::join(path, "status");
    const YAML::Node st = r.child(node, "status", path);
    r.check_keys(st, p, {"id", "extended", "start_bit", "length", "byte_order", "ok"});
    read_layout(r, st, p, reply.status);
    reply.status.unit = "1";
    const std::uint64_t max_raw = reply.status.length >= 64
                                      ? ~std::uint64_t{0}
                                      : (std::uint64_t{1} << reply.status.length) - 1;
    const YAML::Node ok = r.child(st, "ok", p);
    const std::string okp = Reader::join(p, "ok");
    if (ok.IsSequence()) {
      if (ok.size() == 0) r.fail(ok, okp, "expected at least one value");
      for (std::size_t i = 0; i < ok.size(); ++i) {
        reply.ok_values.push_back(r.integer(ok[i], okp + "[" + std::to_string(i) + "]", max_raw));
      }
    } else {
      reply.ok_values.push_back(r.integer(st, "ok", p, max_raw));
    }
  }
  reply.timeout_s = r.time(node, "timeout", path, 0.02, 5.0, "between 20 ms and 5 s");
  return reply;
}

// `address_claim: {address, name, timeout}`; name is the 64-bit NAME or its fields.
AddressClaimSpec read_address_claim(const Reader& r, const YAML::Node& node) {
  const std::string path = "address_claim";
  r.check_keys(node, path, {"address", "name", "timeout"});
  AddressClaimSpec spec;
  spec.address = node_address(r, node, "address", path);
  const YAML::Node name = r.child(node, "name", path);
  if (name.IsMap()) {
    const std::string p = "address_claim.name";
    r.check_keys(name, p,
                 {"identity_number", "manufacturer_code", "ecu_instance", "function_instance",
                  "function", "vehicle_system", "vehicle_system_instance", "industry_group",
                  "arbitrary_address_capable"});
    auto field = [&](const char* key, std::uint64_t max_value, bool required) -> std::uint64_t {
      if (!required && !name[key].IsDefined()) return 0;
      return r.integer(name, key, p, max_value);
    };
    j1939::Name n;
    n.identity_number = static_cast<std::uint32_t>(field("identity_number", 0x1FFFFF, true));
    n.manufacturer_code = static_cast<std::uint16_t>(field("manufacturer_code", 0x7FF, true));
    n.ecu_instance = static_cast<std::uint8_t>(field("ecu_instance", 7, false));
    n.function_instance = static_cast<std::uint8_t>(field("function_instance", 31, false));
    n.function = static_cast<std::uint8_t>(field("function", 255, true));
    n.vehicle_system = static_cast<std::uint8_t>(field("vehicle_system", 127, false));
    n.vehicle_system_instance =
        static_cast<std::uint8_t>(field("vehicle_system_instance", 15, false));
    n.industry_group = static_cast<std::uint8_t>(field("industry_group", 7, true));
    n.arbitrary_address_capable = r.flag(name, "arbitrary_address_capable", p, false);
    if (n.arbitrary_address_capable) {
      r.fail(name["arbitrary_address_capable"], Reader::join(p, "arbitrary_address_capable"),
             "must be false: craneassist keeps its one configured address (valves accept "
             "commands from that address only) and does not move to another one");
    }
    spec.name = j1939::pack_name(n);
  } else {
    spec.name = r.integer(node, "name", path, ~std::uint64_t{0});
    if (j1939::unpack_name(spec.name).arbitrary_address_capable) {
      r.fail(name, "address_claim.name",
             "has the arbitrary address capable bit (63) set: craneassist keeps its one "
             "configured address (valves accept commands from that address only)");
    }
  }
  if (node["timeout"].IsDefined()) {
    spec.timeout_s = r.time(node, "timeout", path, 0.25, 2.0, "between 250 ms and 2 s");
  }
  return spec;
}

// `diagnostics: {dm1: {source_addresses: [0x20, ...]}}`.
Dm1Supervision read_diagnostics(const Reader& r, const YAML::Node& node) {
  r.check_keys(node, "diagnostics", {"dm1"});
  const YAML::Node dm1 = r.child(node, "dm1", "diagnostics");
  r.check_keys(dm1, "diagnostics.dm1", {"source_addresses"});
  const std::string p = "diagnostics.dm1.source_addresses";
  const YAML::Node list = r.child(dm1, "source_addresses", "diagnostics.dm1");
  if (!list.IsSequence() || list.size() == 0) r.fail(list, p, "expected a list of addresses");
  Dm1Supervision out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string field = p + "[" + std::to_string(i) + "]";
    const auto a = static_cast<std::uint8_t>(r.integer(list[i], field, 253));
    for (std::uint8_t b : out.source_addresses) {
      if (a == b) r.fail(list[i], field, "address " + hex_address(a) + " is listed twice");
    }
    out.source_addresses.push_back(a);
  }
  return out;
}

// Bits a signal occupies, for the overlap check.
struct Occupancy {
  std::uint32_t id;
  bool extended;
  std::uint64_t bits;
  std::string field;
  YAML::Node node;
  bool sent;
};

std::uint64_t occupied_bits(const SignalSpec& spec) {
  CanFrame probe;
  probe.id = spec.id;
  probe.extended = spec.extended;
  probe.dlc = 8;
  insert_raw(spec, ~std::uint64_t{0}, probe);
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < 8; ++i) bits |= static_cast<std::uint64_t>(probe.data[i]) << (8 * i);
  return bits;
}

// With an address claim, craneassist sends from the claimed address only: every AVC command and
// a J1939 heartbeat come from it, and no node it supervises may have it (a valve's reply address
// differs from its command's source address: read_reply).
void check_claimed_address(const Reader& r, const YAML::Node& root, const CanMapping& mapping) {
  const std::uint8_t address = mapping.address_claim->address;
  const std::string claimed = "the address_claim address is " + hex_address(address);
  for (std::size_t i = 0; i < mapping.joints.size(); ++i) {
    const JointMapping& jm = mapping.joints[i];
    const YAML::Node valve = root["joints"][i]["valve"];
    const std::string path = "joints[" + std::to_string(i) + "].valve";
    if (jm.valve.kind == ValveOutputKind::kIso11783Avc && jm.valve.avc.source_address != address) {
      r.fail(valve["iso11783_avc"]["source_address"], path + ".iso11783_avc.source_address",
             "is " + hex_address(jm.valve.avc.source_address) + ", " + claimed +
                 ": craneassist sends commands only from the address it claimed");
    }
  }
  if (mapping.heartbeat && mapping.heartbeat->extended &&
      (mapping.heartbeat->id & 0xFFu) != address) {
    r.fail(root["heartbeat"]["id"].IsDefined() ? root["heartbeat"]["id"] : root["heartbeat"],
           "heartbeat.id",
           "has source address " + hex_address(static_cast<std::uint8_t>(mapping.heartbeat->id)) +
               " (its low byte), " + claimed +
               ": a J1939 (29-bit) heartbeat must come from the claimed address");
  }
  if (mapping.dm1) {
    const auto& list = mapping.dm1->source_addresses;
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (list[i] == address) {
        r.fail(root["diagnostics"]["dm1"]["source_addresses"][i],
               "diagnostics.dm1.source_addresses[" + std::to_string(i) + "]",
               "is craneassist's own (" + claimed + ")");
      }
    }
  }
}

CanMapping read_mapping(Reader& r, const YAML::Node& root) {
  r.check_keys(root, "",
               {"format", "note", "dbc", "joints", "heartbeat", "pump", "grapple", "address_claim",
                "diagnostics"});
  const YAML::Node format = r.child(root, "format", "");
  if (r.text(format, "format") != kMappingFormat) {
    r.fail(format, "format", std::string("expected ") + kMappingFormat);
  }
  if (root["dbc"].IsDefined()) {
    // Relative to the mapping file, like the crane config's paths.
    const std::filesystem::path file = r.text(root["dbc"], "dbc");
    const std::filesystem::path path =
        file.is_absolute() ? file : std::filesystem::path(r.file()).parent_path() / file;
    try {
      r.dbc = load_dbc(path);
    } catch (const ConfigError& e) {
      if (e.line() > 0) throw;  // an error inside the DBC names the DBC's own line
      r.fail(root["dbc"], "dbc", "cannot read " + path.string() + ": " + e.reason());
    }
  }
  const YAML::Node joints = r.child(root, "joints", "");
  if (!joints.IsSequence() || joints.size() == 0) {
    r.fail(joints, "joints", "expected a list of joints");
  }
  CanMapping mapping;
  mapping.source = r.file();
  for (const auto& kv : root) {  // the line of the key (a block list's mark is its first entry)
    if (kv.first.Scalar() == "joints") mapping.joints_line = kv.first.Mark().line + 1;
  }
  std::vector<Occupancy> occupancy;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const YAML::Node j = joints[i];
    const std::string path = "joints[" + std::to_string(i) + "]";
    r.check_keys(j, path, {"name", "valve", "position", "pressure_a", "pressure_b"});
    JointMapping jm;
    const YAML::Node name = r.child(j, "name", path);
    jm.name = r.text(name, path + ".name");
    jm.name_line = name.Mark().line + 1;
    for (const auto& other : mapping.joints) {
      if (other.name == jm.name) r.fail(name, path + ".name", "duplicate joint '" + jm.name + "'");
    }
    jm.valve = read_valve(r, r.child(j, "valve", path), path + ".valve");
    jm.valve_line = j["valve"].Mark().line + 1;
    if (jm.valve.kind == ValveOutputKind::kIso11783Avc) {
      for (const auto& other : mapping.joints) {
        if (other.valve.kind == ValveOutputKind::kIso11783Avc &&
            other.valve.avc.valve == jm.valve.avc.valve &&
            other.valve.avc.source_address == jm.valve.avc.source_address) {
          r.fail(j["valve"]["iso11783_avc"]["valve"], path + ".valve.iso11783_avc.valve",
                 "valve " + std::to_string(jm.valve.avc.valve) + " is already used by joint '" +
                     other.name + "'");
        }
      }
    } else {
      occupancy.push_back({jm.valve.signal.signal.id, jm.valve.signal.signal.extended,
                           occupied_bits(jm.valve.signal.signal), path + ".valve.signal",
                           j["valve"]["signal"], true});
    }
    if (j["valve"]["reply"].IsDefined()) {
      jm.reply = read_reply(r, j["valve"]["reply"], path + ".valve.reply", jm.valve);
      if (jm.valve.kind == ValveOutputKind::kSignal) {
        const SignalSpec& st = jm.reply->status;
        occupancy.push_back({st.id, st.extended, occupied_bits(st), path + ".valve.reply.status",
                             j["valve"]["reply"]["status"], false});
      }
    }
    jm.position = read_signal(r, r.child(j, "position", path), path + ".position",
                              SignalUse::kPosition, kSignalKeys, &jm.position_kind);
    jm.position_line = j["position"].Mark().line + 1;
    occupancy.push_back({jm.position.id, jm.position.extended, occupied_bits(jm.position),
                         path + ".position", j["position"], false});
    for (const char* key : {"pressure_a", "pressure_b"}) {
      if (!j[key].IsDefined()) continue;
      const std::string p = path + "." + key;
      SignalSpec s = read_signal(r, j[key], p, SignalUse::kPressure, kSignalKeys, nullptr);
      occupancy.push_back({s.id, s.extended, occupied_bits(s), p, j[key], false});
      (std::string(key) == "pressure_a" ? jm.pressure_a : jm.pressure_b) = s;
    }
    mapping.joints.push_back(std::move(jm));
  }
  if (root["pump"].IsDefined()) {
    const YAML::Node pump = root["pump"];
    r.check_keys(pump, "pump", {"pressure", "flow"});
    if (pump["pressure"].IsDefined()) {
      mapping.pump.pressure = read_signal(r, pump["pressure"], "pump.pressure",
                                          SignalUse::kPressure, kSignalKeys, nullptr);
      const auto& sp = *mapping.pump.pressure;
      occupancy.push_back(
          {sp.id, sp.extended, occupied_bits(sp), "pump.pressure", pump["pressure"], false});
    }
    if (pump["flow"].IsDefined()) {
      mapping.pump.flow =
          read_signal(r, pump["flow"], "pump.flow", SignalUse::kFlow, kSignalKeys, nullptr);
      const auto& sp = *mapping.pump.flow;
      occupancy.push_back(
          {sp.id, sp.extended, occupied_bits(sp), "pump.flow", pump["flow"], false});
    }
  }
  if (root["grapple"].IsDefined()) {
    // A two-axis swing sensor on the grapple's link: both components or none.
    const YAML::Node grapple = root["grapple"];
    r.check_keys(grapple, "grapple", {"swing_radial", "swing_tangential"});
    for (const char* key : {"swing_radial", "swing_tangential"}) {
      const std::string p = std::string("grapple.") + key;
      const SignalSpec sp = read_signal(r, r.child(grapple, key, "grapple"), p, SignalUse::kAngle,
                                        kSignalKeys, nullptr);
      occupancy.push_back({sp.id, sp.extended, occupied_bits(sp), p, grapple[key], false});
      (std::string(key) == "swing_radial" ? mapping.grapple.swing_radial
                                          : mapping.grapple.swing_tangential) = sp;
    }
  }
  if (root["heartbeat"].IsDefined()) {
    const YAML::Node h = root["heartbeat"];
    HeartbeatSpec hb;
    if (h.IsMap() && h["dbc"].IsDefined()) {
      // {dbc: Message, timeout: 100 ms[, cycle: 20 ms]}: identifier and cycle from the DBC.
      r.check_keys(h, "heartbeat", {"dbc", "cycle", "timeout"});
      const DbcMessage* m = r.dbc_entry(h, "heartbeat", false).first;
      hb.id = m->id;
      hb.extended = m->extended;
      if (h["cycle"].IsDefined()) {
        hb.cycle_s = r.time(h, "cycle", "heartbeat", 0.001, 0.1, "between 1 ms and 100 ms");
      } else if (m->cycle_s && *m->cycle_s >= 0.001 && *m->cycle_s <= 0.1) {
        hb.cycle_s = *m->cycle_s;
      } else {
        r.fail(
            h, "heartbeat.cycle",
            "missing, and " + r.dbc->source + " gives no cycle time of 1..100 ms for " + m->name);
      }
    } else {
      r.check_keys(h, "heartbeat", {"id", "extended", "cycle", "timeout"});
      hb.extended = r.flag(h, "extended", "heartbeat", true);
      hb.id = static_cast<std::uint32_t>(
          r.integer(h, "id", "heartbeat", hb.extended ? kMaxExtendedId : kMaxStandardId));
      hb.cycle_s = r.time(h, "cycle", "heartbeat", 0.001, 0.1, "between 1 ms and 100 ms");
    }
    hb.timeout_s = r.time(h, "timeout", "heartbeat", 0.01, 1.0, "between 10 ms and 1 s");
    if (hb.timeout_s < 2.0 * hb.cycle_s) {
      r.fail(h["timeout"], "heartbeat.timeout", "must be at least two cycles");
    }
    for (const auto& jm : mapping.joints) {
      CanFrame avc;
      if (jm.valve.kind == ValveOutputKind::kIso11783Avc && encode_valve_block(jm.valve, avc) &&
          avc.id == hb.id && avc.extended == hb.extended) {
        r.fail(h["id"].IsDefined() ? h["id"] : h, "heartbeat.id",
               "is the valve command identifier of joint '" + jm.name + "'");
      }
    }
    // The whole frame is the heartbeat's: no signal may use its identifier.
    occupancy.push_back({hb.id, hb.extended, ~std::uint64_t{0}, "heartbeat", h, true});
    mapping.heartbeat = hb;
  }
  if (root["diagnostics"].IsDefined()) mapping.dm1 = read_diagnostics(r, root["diagnostics"]);
  if (root["address_claim"].IsDefined()) {
    mapping.address_claim = read_address_claim(r, root["address_claim"]);
    check_claimed_address(r, root, mapping);
  }
  // Signals sharing a frame must not share bits; a frame is either sent or received.
  for (std::size_t a = 0; a < occupancy.size(); ++a) {
    for (std::size_t b = 0; b < a; ++b) {
      const Occupancy& x = occupancy[a];
      const Occupancy& y = occupancy[b];
      if (x.id != y.id || x.extended != y.extended) continue;
      if (x.sent != y.sent) {
        r.fail(
            x.node, x.field,
            "identifier is also used by " + y.field + " in the other direction (sent vs received)");
      }
      if ((x.bits & y.bits) != 0) r.fail(x.node, x.field, "overlaps the bits of " + y.field);
    }
  }
  return mapping;
}

}  // namespace

CanMapping parse_can_mapping(std::string_view yaml_text, std::string_view source_name) {
  Reader reader{std::string(source_name)};
  return config::read_yaml(yaml_text, source_name,
                           [&](const YAML::Node& root) { return read_mapping(reader, root); });
}

CanMapping load_can_mapping(const std::filesystem::path& path) {
  return parse_can_mapping(config::read_yaml_file(path, "CAN mapping"), path.string());
}

void check_mapping_fits(const CanMapping& mapping, const dynamics::CraneModel& model) {
  const auto fail = [&](int line, const std::string& field, const std::string& reason) {
    throw ConfigError(mapping.source, line, field, reason);
  };
  if (static_cast<int>(mapping.joints.size()) != model.dof()) {
    fail(mapping.joints_line, "joints",
         "the mapping has " + std::to_string(mapping.joints.size()) + " joints, the crane " +
             std::to_string(model.dof()) + " (" + model.name + ")");
  }
  for (int i = 0; i < model.dof(); ++i) {
    const auto s = static_cast<std::size_t>(i);
    const JointMapping& jm = mapping.joints[s];
    const auto& joint = model.joints[s];
    const std::string path = "joints[" + std::to_string(i) + "]";
    if (!joint.name.empty() && jm.name != joint.name) {
      fail(jm.name_line, path + ".name",
           "joint " + std::to_string(i + 1) + " is '" + jm.name + "', the crane's is '" +
               joint.name + "'");
    }
    const bool revolute = joint.type == dynamics::JointType::kRevolute;
    if (revolute != (jm.position_kind == PositionKind::kAngle)) {
      fail(jm.position_line, path + ".position",
           "joint '" + jm.name + "': the crane's joint is " +
               (revolute ? "revolute" : "prismatic") + ", its position signal's unit is " +
               (revolute ? "a length" : "an angle"));
    }
    if ((jm.position.minimum && *jm.position.minimum > joint.q_min + 1e-9) ||
        (jm.position.maximum && *jm.position.maximum < joint.q_max - 1e-9)) {
      std::ostringstream why;
      why << "joint '" << jm.name
          << "': the position signal's min/max do not cover the joint range [" << joint.q_min
          << ", " << joint.q_max << "] " << (revolute ? "rad" : "m");
      fail(jm.position_line, path + ".position", why.str());
    }
    CanFrame block;
    if (!encode_valve_block(jm.valve, block)) {
      fail(jm.valve_line, path + ".valve",
           "joint '" + jm.name + "': its valve command cannot be encoded");
    }
  }
}

}  // namespace craneassist::can
