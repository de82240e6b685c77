// A remote operator that turns malformed in mid-motion, for tests/cli/remote_commands.sh: with
// the operator's DDS Security identity (the settings file's commands.security) it waits for the
// crane's reader, sends the deadman released for 0.5 s, moves the tip at 0.3 m/s along x with
// the deadman held for 1.5 s, then sends only malformed samples (a bool byte of 2, a bad
// encapsulation, a cut-off body; each says "deadman held, 0.3 m/s") at 50 Hz for 2 s, and ends.
// Usage: dds_malformed_operator DOMAIN SETTINGS_YAML
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <thread>

#include "craneassist/config/telemetry_config.hpp"
#include "dds_raw_writer.hpp"

int main(int argc, char** argv) {
  using namespace craneassist;
  if (argc != 3) {
    std::fprintf(stderr, "usage: dds_malformed_operator DOMAIN SETTINGS_YAML\n");
    return 2;
  }
  try {
    const config::TelemetryConfig settings = config::load_telemetry_config(argv[2]);
    test::RawWriterOptions o;
    o.domain_id = std::atoi(argv[1]);
    o.security = settings.commands.security;
    o.participant_name = "dds_malformed_operator";
    test::RawWriter writer(o);
    const auto period = std::chrono::milliseconds(20);
    for (int i = 0; i < 500 && writer.matched_readers() == 0; ++i) {
      std::this_thread::sleep_for(period);
    }
    if (writer.matched_readers() == 0) {
      std::fprintf(stderr, "dds_malformed_operator: no crane reader within 10 s\n");
      return 3;
    }
    std::uint64_t seq = 0;
    int good = 0, bad = 0;
    for (int i = 0; i < 25; ++i, ++good) {
      writer.write(test::operator_command_payload(++seq, "malformed-operator", {0, 0, 0}, false));
      std::this_thread::sleep_for(period);
    }
    for (int i = 0; i < 75; ++i, ++good) {
      writer.write(test::operator_command_payload(++seq, "malformed-operator", {0.3, 0, 0}, true));
      std::this_thread::sleep_for(period);
    }
    const test::Malformation kinds[] = {test::Malformation::kBadBool,
                                        test::Malformation::kBadEncapsulation,
                                        test::Malformation::kTruncated};
    for (int i = 0; i < 100; ++i, ++bad) {
      writer.write(test::malformed_payload(dds::Topic::kOperatorCommand, kinds[i % 3]));
      std::this_thread::sleep_for(period);
    }
    std::printf("dds_malformed_operator: %d well-formed samples, then %d malformed\n", good, bad);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dds_malformed_operator: %s\n", e.what());
    return 3;
  }
  return 0;
}
