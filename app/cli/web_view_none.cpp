#include <spdlog/spdlog.h>

#include "exit_codes.hpp"
#include "web_view.hpp"

namespace craneassist::cli {

struct WebView::State {};

WebView::WebView() : state_(std::make_unique<State>()) {}
WebView::~WebView() = default;

void add_web_options(CLI::App& command, WebArgs& args) {
  command.add_flag("--web", args.on, "The web view (not in this build: CRANEASSIST_WEB=OFF)");
  command.add_option("--web-listen", args.listen, "The web view's address (not in this build)");
  command.add_flag("--web-remote-commands", args.remote_commands, "(not in this build)");
  command.add_option("--web-rate", args.frame_rate_hz, "(not in this build)");
}

int WebView::open(const WebArgs&, const config::CraneConfig&, bool,
                  const dynamics::MobileBaseModel*) {
  spdlog::error("web view: this craneassist was built without the web view (CRANEASSIST_WEB=OFF)");
  return kExitUsage;
}

control::CycleObserver* WebView::observer() {
  return nullptr;
}

void WebView::publish(const control::LogRow&) noexcept {}

std::unique_ptr<input::CommandSource> WebView::pad_source(const input::JoystickMapping&) {
  return nullptr;
}

std::string WebView::report() const {
  return "";
}

}  // namespace craneassist::cli
