// Publishes the synthetic telemetry of dds_test_frames.hpp on a DDS domain, paced at 100 Hz,
// for the tests of `craneassist echo` and `craneassist dashboard` (and the examples of
// docs/dashboard.md). SIGINT or SIGTERM end it early.
// Usage: dds_test_publisher DOMAIN SECONDS [default|udp|shm]
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <thread>

#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/telemetry_publisher.hpp"
#include "dds_test_frames.hpp"

namespace {

std::atomic<bool> g_stop{false};

extern "C" void on_stop_signal(int) {
  g_stop.store(true);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace craneassist;
  if (argc != 3 && argc != 4) {
    std::fprintf(stderr, "usage: dds_test_publisher DOMAIN SECONDS [default|udp|shm]\n");
    return 2;
  }
  const std::string transport = argc == 4 ? argv[3] : "default";
  const int domain = std::atoi(argv[1]);
  const double seconds = std::atof(argv[2]);
  struct sigaction sa = {};
  sa.sa_handler = on_stop_signal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  try {
    config::TelemetryConfig settings = config::default_telemetry_config();
    settings.domain_id = domain;
    settings.participant_name = "dds_test_publisher";
    settings.transport = transport == "udp"   ? config::DdsTransport::kUdp
                         : transport == "shm" ? config::DdsTransport::kShm
                                              : config::DdsTransport::kDefault;
    dds::TelemetryPublisher publisher(settings, test::test_telemetry_info());
    std::printf("dds_test_publisher: domain %d, %g s\n", domain, seconds);
    std::fflush(stdout);
    const auto start = std::chrono::steady_clock::now();
    const auto period = std::chrono::duration<double>(test::kTestDt);
    std::uint64_t cycle = 0;
    while (!g_stop.load() && static_cast<double>(cycle) * test::kTestDt < seconds) {
      publisher.push(test::test_frame(cycle));
      ++cycle;
      std::this_thread::sleep_until(start +
                                    std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                        period * static_cast<double>(cycle)));
    }
    publisher.close();
    std::printf("dds_test_publisher: %llu cycles\n", static_cast<unsigned long long>(cycle));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dds_test_publisher: %s\n", e.what());
    return 3;
  }
  return 0;
}
