#include "foxglove_setup.hpp"

#include <spdlog/spdlog.h>

#include <exception>
#include <optional>

#include "craneassist/foxglove/mcap_recorder.hpp"
#include "exit_codes.hpp"
#include "foxglove_server_setup.hpp"

namespace craneassist::cli {

void add_foxglove_options(CLI::App& command, FoxgloveArgs& args) {
  command.add_option("--mcap", args.mcap_file,
                     "Record the run as an MCAP file for Foxglove and PlotJuggler: /joint_states, "
                     "/tf, /robot_description, the tip twists and every logged value as JSON "
                     "(docs/foxglove.md)");
  command.add_option("--mcap-compression", args.mcap_compression, "zstd or none")
      ->check(CLI::IsMember({"zstd", "none"}))
      ->capture_default_str();
  add_foxglove_server_option(command, args.foxglove);
  command
      .add_option("--foxglove-wait", args.foxglove_wait_s,
                  "Hold the run's start until a Foxglove client has subscribed (and its "
                  "subscriptions have settled: 0.2 s without a new one), at most this many seconds "
                  "(then start anyway)")
      ->check(CLI::Range(0.0, 3600.0))
      ->needs("--foxglove");
}

struct FoxgloveOutputs::Outputs {
  std::optional<foxglove::McapRecorder> mcap;
  FoxgloveServerHandle server;
};

FoxgloveOutputs::FoxgloveOutputs() : outputs_(std::make_unique<Outputs>()) {}
FoxgloveOutputs::~FoxgloveOutputs() = default;

int FoxgloveOutputs::open(const FoxgloveArgs& args, const config::CraneConfig& cfg, bool base,
                          bool realtime) {
  try {
    if (!args.mcap_file.empty()) {
      foxglove::McapRecorderOptions options;
      options.file.compression = args.mcap_compression == "none" ? foxglove::McapCompression::kNone
                                                                 : foxglove::McapCompression::kZstd;
      outputs_->mcap.emplace(args.mcap_file, cfg.model, base, options);
    }
    if (!args.foxglove.empty()) {
      if (const int rc = outputs_->server.open(args.foxglove, cfg, base, realtime); rc != kExitOk) {
        return rc;
      }
      if (args.foxglove_wait_s > 0.0) outputs_->server.wait_for_subscriber(args.foxglove_wait_s);
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

void FoxgloveOutputs::add_observers(std::vector<control::CycleObserver*>& observers) {
  if (outputs_->mcap) observers.push_back(&*outputs_->mcap);
  if (control::CycleObserver* o = outputs_->server.observer()) observers.push_back(o);
}

int FoxgloveOutputs::finish() {
  int rc = kExitOk;
  if (outputs_->mcap) {
    try {
      outputs_->mcap->on_finish({}, {});  // closes the file, if the loop has not
      std::printf("%s\n", outputs_->mcap->report().c_str());
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
      rc = kExitRuntime;
    }
  }
  outputs_->server.finish();
  return rc;
}

}  // namespace craneassist::cli
