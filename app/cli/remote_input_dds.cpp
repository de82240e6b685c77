#include <cstdio>

#include "craneassist/dds/command_source.hpp"
#include "remote_input.hpp"

namespace craneassist::cli {

bool remote_input_available() {
  return true;
}

void check_remote_input_settings(const config::TelemetryConfig& settings) {
  dds::check_command_input_settings(settings);
}

RemoteInput open_remote_input(const config::TelemetryConfig& settings, double stale_timeout_s) {
  auto source = std::make_unique<dds::DdsCommandSource>(settings, stale_timeout_s);
  const dds::DdsCommandSource* dds_source = source.get();
  RemoteInput remote;
  remote.source = std::move(source);
  remote.sender = [dds_source] { return dds_source->stats().sender; };
  remote.events = [dds_source] {
    const dds::CommandInputStats d = dds_source->stats();
    RemoteInputEvents e;
    e.malformed = d.malformed;
    e.replayed = d.replayed;
    e.operator_changes = d.owner_changes;
    return e;
  };
  remote.report = [dds_source] {
    const dds::CommandInputStats d = dds_source->stats();
    std::string from = " (no operator)";
    if (d.first_sample_s >= 0.0) {
      char first[32];
      std::snprintf(first, sizeof first, "%.2f", d.first_sample_s);
      from = " from '" + d.sender + "' (first " + first + " s after start)";
    }
    char line[512];
    std::snprintf(
        line, sizeof line,
        "  dds input: %llu samples%s, %llu lost, %llu non-finite, %llu malformed, %llu "
        "replayed, %llu from other senders; writers matched %d (peak %d)",
        static_cast<unsigned long long>(d.samples), from.c_str(),
        static_cast<unsigned long long>(d.lost), static_cast<unsigned long long>(d.non_finite),
        static_cast<unsigned long long>(d.malformed), static_cast<unsigned long long>(d.replayed),
        static_cast<unsigned long long>(d.other_senders), d.writer_matches, d.peak_matched_writers);
    return std::string(line);
  };
  return remote;
}

}  // namespace craneassist::cli
