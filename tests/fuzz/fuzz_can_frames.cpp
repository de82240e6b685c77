// Received CAN frames (valves/can/): any frame, one after another as they come off the bus,
// through every decoder that reads the bus:
//  - J1939 identifiers (can/j1939.hpp): decompose and compose are inverse, make_id of a
//    decomposed identifier's PGN gives that PGN back;
//  - the ISO 11783-7 auxiliary valve codec (can/iso11783_valve.hpp): the command, measured flow
//    and estimated flow decoders; a decoded command encodes to a frame that decodes the same;
//  - the J1939-71 joystick messages (can/j1939_joystick.hpp): every axis a position in -1..1 only
//    when it is valid, 0 otherwise; a decoded message encodes to a frame that decodes the same;
//  - J1939 network management and diagnostics (can/address_claim.hpp, can/dm1.hpp): Address
//    Claimed, Request, DM1 and its TP.CM announcement decode to what encodes the same frame; an
//    AddressClaimer fed every frame only ever sends claims of its address or Cannot Claim;
//  - the shipped signal mappings (config/can/*.yaml): every joint's position and pressure
//    signals, the valve command decoder of the machine emulator, the heartbeat and its monitor;
//  - the CAN backend itself (can::CanBackend) on an in-memory bus: what the control loop reads,
//    with the shipped mappings' address claim, valve replies and DM1 supervision.
// The input is a sequence of 14-byte records: identifier (4 bytes, little endian; bit 31: a
// 29-bit identifier), dlc, 8 data bytes, and a byte of flags for the backend (bit 0: call
// read(), bit 1: enable()).
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>

#include "craneassist/can/address_claim.hpp"
#include "craneassist/can/can_backend.hpp"
#include "craneassist/can/dm1.hpp"
#include "craneassist/can/heartbeat.hpp"
#include "craneassist/can/iso11783_valve.hpp"
#include "craneassist/can/j1939.hpp"
#include "craneassist/can/j1939_joystick.hpp"
#include "craneassist/can/mapping_config.hpp"
#include "craneassist/can/signal_map.hpp"
#include "craneassist/can/valve_frames.hpp"
#include "craneassist/config/crane_config.hpp"
#include "fake_can_bus.hpp"
#include "fuzz_check.hpp"

namespace can = craneassist::can;
namespace iso = craneassist::can::iso11783;
namespace j1939 = craneassist::can::j1939;

namespace {

constexpr std::size_t kRecord = 14;

void check_j1939(const can::CanFrame& frame) {
  const j1939::Identifier id = j1939::decompose(frame.id);
  FUZZ_CHECK(j1939::compose(id) == (frame.id & can::kMaxExtendedId), "compose(decompose(id))");
  const std::uint32_t pgn = j1939::pgn(id);
  FUZZ_CHECK(pgn <= j1939::kMaxPgn, "an 18-bit PGN");
  std::uint32_t raw = 0;
  const j1939::IdStatus status =
      j1939::make_id(id.priority, pgn, id.source_address, j1939::destination(id), raw);
  if (status == j1939::IdStatus::kOk) {
    FUZZ_CHECK(raw == j1939::compose(id), "make_id rebuilds the identifier");
  } else {
    FUZZ_CHECK(id.extended_data_page && id.data_page, "only the ISO 15765-3 page is refused");
  }
  (void)j1939::to_string(status);
}

bool same_value(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) || a == b;
}

void check_joystick(const can::CanFrame& frame) {
  namespace js = craneassist::can::j1939_joystick;
  js::JoystickMessage m;
  const js::DecodeStatus status = js::decode(frame, m);
  (void)js::to_string(status);
  if (status != js::DecodeStatus::kOk) return;
  for (const js::Axis& a : m.axes) {
    (void)js::to_string(a.status);
    FUZZ_CHECK(std::isfinite(a.value) && a.value >= -1.0 && a.value <= 1.0, "an axis in -1..1");
    FUZZ_CHECK(a.status == js::AxisStatus::kOk || a.value == 0.0, "no position unless valid");
    FUZZ_CHECK(!a.neutral || (a.status == js::AxisStatus::kOk && a.value == 0.0),
               "neutral only at 0");
  }
  can::CanFrame again;
  const j1939::Identifier id = j1939::decompose(frame.id);
  js::encode(m, id.source_address, again, id.priority);
  js::JoystickMessage back;
  FUZZ_CHECK(js::decode(again, back) == js::DecodeStatus::kOk, "an encoded message decodes");
  for (std::size_t i = 0; i < m.axes.size(); ++i) {
    FUZZ_CHECK(back.axes[i].status == m.axes[i].status && back.axes[i].value == m.axes[i].value,
               "an axis decodes the same after encoding");
  }
  FUZZ_CHECK(back.buttons == m.buttons && back.x_detent == m.x_detent, "buttons the same");
}

void check_iso11783(const can::CanFrame& frame) {
  iso::AuxValveCommand command;
  std::uint8_t source = 0;
  const iso::CodecStatus status = iso::decode(frame, command, source);
  (void)iso::to_string(status);
  if (status == iso::CodecStatus::kOk) {
    FUZZ_CHECK(command.valve < iso::kAuxValveCount, "valve 0..15");
    FUZZ_CHECK(command.flow >= 0.0 && command.flow <= 1.0, "flow 0..1");
    (void)iso::to_string(command.state);
    (void)iso::to_string(command.fail_safe);
    // What a valid command decodes to, encoded again, decodes the same.
    can::CanFrame again;
    const iso::CodecStatus encoded =
        iso::encode(command, source, j1939::decompose(frame.id).priority, again);
    if (encoded == iso::CodecStatus::kOk) {
      iso::AuxValveCommand back;
      std::uint8_t back_source = 0;
      FUZZ_CHECK(iso::decode(again, back, back_source) == iso::CodecStatus::kOk, "re-decodes");
      FUZZ_CHECK(back.valve == command.valve && back.state == command.state &&
                     back.fail_safe == command.fail_safe && back_source == source,
                 "a command survives encode and decode");
      FUZZ_CHECK(std::abs(back.flow - command.flow) <= iso::kStandardFlowPerBit / 2 + 1e-12,
                 "the flow survives within half a step");
    }
  }
  iso::AuxValveMeasuredFlow measured;
  if (iso::decode(frame, measured, source) == iso::CodecStatus::kOk) {
    for (double flow : {measured.extend_flow, measured.retract_flow}) {
      FUZZ_CHECK(std::isnan(flow) || std::abs(flow) <= 1.25, "measured flow -1.25..1.25 or NaN");
    }
    for (double p :
         {measured.extend_pressure_pa, measured.retract_pressure_pa, measured.return_pressure_pa}) {
      FUZZ_CHECK(std::isnan(p) || p >= 0.0, "pressure >= 0 or NaN");
    }
    // Encoding the decoded message gives a frame that decodes the same.
    can::CanFrame again;
    iso::AuxValveMeasuredFlow back;
    std::uint8_t back_source = 0;
    if (iso::encode(measured, source, 3, again) == iso::CodecStatus::kOk &&
        iso::decode(again, back, back_source) == iso::CodecStatus::kOk) {
      FUZZ_CHECK(same_value(back.extend_flow, measured.extend_flow) &&
                     same_value(back.retract_flow, measured.retract_flow) &&
                     same_value(back.extend_pressure_pa, measured.extend_pressure_pa) &&
                     same_value(back.retract_pressure_pa, measured.retract_pressure_pa) &&
                     same_value(back.return_pressure_pa, measured.return_pressure_pa),
                 "a measured flow message survives encode and decode");
    }
  }
  iso::AuxValveEstimatedFlow estimated;
  if (iso::decode(frame, estimated, source) == iso::CodecStatus::kOk) {
    for (double flow : {estimated.extend_flow, estimated.retract_flow}) {
      FUZZ_CHECK(std::isnan(flow) || std::abs(flow) <= 1.25, "estimated flow -1.25..1.25 or NaN");
    }
  }
}

void check_network(const can::CanFrame& frame, double t_s) {
  std::uint64_t name = 0;
  std::uint8_t source = 0;
  if (j1939::decode_address_claimed(frame, name, source)) {
    can::CanFrame again;
    j1939::encode_address_claimed(name, source, again);
    std::uint64_t back = 0;
    std::uint8_t back_source = 0;
    FUZZ_CHECK(j1939::decode_address_claimed(again, back, back_source) && back == name &&
                   back_source == source,
               "an Address Claimed survives encode and decode");
    FUZZ_CHECK(j1939::pack_name(j1939::unpack_name(name)) == (name & ~(std::uint64_t{1} << 48)),
               "the NAME's fields hold every bit but the reserved one");
  }
  std::uint32_t requested = 0;
  std::uint8_t destination = 0;
  if (j1939::decode_request(frame, requested, destination)) {
    FUZZ_CHECK(requested <= 0xFFFFFF && frame.dlc >= 3, "a request names a 3-byte PGN");
  }
  j1939::Dm1 dm1;
  const j1939::Dm1Status status = j1939::decode_dm1(frame, dm1, source);
  if (status == j1939::Dm1Status::kOk) {
    FUZZ_CHECK(dm1.spn <= 0x7FFFF && dm1.fmi < 32 && dm1.occurrence_count < 128,
               "DM1 fields within their bits");
    can::CanFrame again;
    j1939::encode_dm1(dm1, source, again);
    FUZZ_CHECK(std::memcmp(again.data.data(), frame.data.data(), 6) == 0,
               "a DM1's lamps and DTC survive encode");
    (void)j1939::dm1_requires_stop(dm1);
  } else {
    FUZZ_CHECK(status == j1939::Dm1Status::kNotDm1 || frame.dlc < 6, "only a short DM1 is short");
  }
  std::uint16_t size = 0;
  (void)j1939::decode_dm1_announcement(frame, source, size);
  // A claimer that sees every frame: whatever it answers is its claim or a Cannot Claim.
  static j1939::AddressClaimer claimer(0x80, 0x3000820000000C1Aull);
  const auto now_us = static_cast<std::int64_t>(t_s * 1e6);
  can::CanFrame out;
  if (claimer.state() == j1939::ClaimState::kIdle) claimer.start(now_us, out);
  for (const auto action : {claimer.on_frame(frame, now_us, out), claimer.poll(now_us, out)}) {
    if (action == j1939::AddressClaimer::Action::kNone) continue;
    FUZZ_CHECK(j1939::decode_address_claimed(out, name, source) && name == claimer.name() &&
                   (source == 0x80 || source == j1939::kNullAddress),
               "the claimer sends only its claim or Cannot Claim");
  }
  (void)j1939::to_string(claimer.state());
}

void check_signal(const can::SignalSpec& spec, const can::CanFrame& frame) {
  double value = 0.0;
  const can::SignalStatus status = can::decode(spec, frame, value);
  (void)can::to_string(status);
  if (status == can::SignalStatus::kOk) {
    FUZZ_CHECK(std::isfinite(value), "a decoded signal is finite");
  }
}

// One shipped mapping and the backend that reads it.
struct Machine {
  can::CanMapping mapping;
  std::unique_ptr<can::testing::FakeCanBus> bus;
  std::unique_ptr<can::testing::FakeCanTransport> backend_end, machine_end;
  std::unique_ptr<can::CanBackend> backend;
  std::unique_ptr<can::HeartbeatMonitor> heartbeat;
};

Machine make_machine(const char* file, const craneassist::config::CraneConfig& crane) {
  Machine m;
  m.mapping = can::load_can_mapping(std::string(CRANEASSIST_SOURCE_DIR) + "/config/can/" + file);
  m.bus = std::make_unique<can::testing::FakeCanBus>();
  m.backend_end = std::make_unique<can::testing::FakeCanTransport>(*m.bus);
  m.machine_end = std::make_unique<can::testing::FakeCanTransport>(*m.bus);
  m.bus->attach(m.backend_end.get());
  m.bus->attach(m.machine_end.get());
  can::CanBackendOptions options;
  options.loop_timeout_s = 1e6;  // the harness calls write() when it likes
  options.feedback_timeout_s = 1e6;
  m.backend = std::make_unique<can::CanBackend>(m.mapping, crane.model, *m.backend_end, options);
  if (m.mapping.heartbeat)
    m.heartbeat = std::make_unique<can::HeartbeatMonitor>(*m.mapping.heartbeat);
  return m;
}

void check_mapping(Machine& m, const can::CanFrame& frame, double t_s) {
  for (const can::JointMapping& joint : m.mapping.joints) {
    check_signal(joint.position, frame);
    if (joint.pressure_a) check_signal(*joint.pressure_a, frame);
    if (joint.pressure_b) check_signal(*joint.pressure_b, frame);
    if (can::is_valve_frame(joint.valve, frame)) {
      double spool = 0.0;
      bool block = false;
      if (can::decode_valve_command(joint.valve, frame, spool, block)) {
        FUZZ_CHECK(std::isfinite(spool) && std::abs(spool) <= 1.0 + 1e-9, "spool -1..1");
      }
    }
  }
  if (m.mapping.pump.pressure) check_signal(*m.mapping.pump.pressure, frame);
  if (m.mapping.pump.flow) check_signal(*m.mapping.pump.flow, frame);
  if (m.mapping.heartbeat) {
    can::Heartbeat hb;
    (void)can::decode_heartbeat(*m.mapping.heartbeat, frame, hb);
    m.heartbeat->on_frame(frame, t_s);
    (void)m.heartbeat->alive(t_s);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const craneassist::config::CraneConfig crane = craneassist::config::default_crane_config();
  static std::array<Machine, 2> machines = {make_machine("k70m_can.yaml", crane),
                                            make_machine("pvg32_isobus_example.yaml", crane)};
  static double t_s = 0.0;
  for (std::size_t at = 0; at + kRecord <= size; at += kRecord) {
    const std::uint8_t* r = data + at;
    can::CanFrame frame;
    const std::uint32_t raw =
        static_cast<std::uint32_t>(r[0]) | static_cast<std::uint32_t>(r[1]) << 8 |
        static_cast<std::uint32_t>(r[2]) << 16 | static_cast<std::uint32_t>(r[3]) << 24;
    frame.extended = (raw & 0x80000000u) != 0;
    frame.id = raw & (frame.extended ? can::kMaxExtendedId : can::kMaxStandardId);
    frame.dlc = static_cast<std::uint8_t>(r[4] % 9);
    std::memcpy(frame.data.data(), r + 5, 8);
    const std::uint8_t flags = r[13];
    FUZZ_CHECK(can::is_valid(frame) && can::same_frame(frame, frame), "a valid frame");
    t_s += 0.001;

    check_j1939(frame);
    check_joystick(frame);
    check_iso11783(frame);
    check_network(frame, t_s);
    for (Machine& m : machines) {
      check_mapping(m, frame, t_s);
      can::Received received;
      received.kind = can::ReceiveKind::kFrame;
      received.frame = frame;
      received.timestamp_us = can::realtime_now_us();
      m.backend_end->deliver(received);
      if ((flags & 1) != 0) {
        craneassist::valves::MachineState state;
        const auto status = m.backend->read(state);
        if (status == craneassist::valves::BackendStatus::kOk && state.valid) {
          FUZZ_CHECK(state.q.allFinite() && state.qdot.allFinite(), "a valid state is finite");
        }
        craneassist::valves::ValveCommand command;
        command.spool.setZero(static_cast<Eigen::Index>(m.mapping.joints.size()));
        (void)m.backend->write(command);
      }
      if ((flags & 2) != 0) m.backend->enable();
      // What the backend sent (valve commands, heartbeats) is not looked at: drop it, and the
      // bus's own record of the traffic.
      m.bus->clear_log();
      can::Received sent;
      do {
        m.machine_end->receive(sent);
      } while (sent.kind != can::ReceiveKind::kNone);
    }
  }
  return 0;
}
