#include <spdlog/spdlog.h>

#include <charconv>
#include <cstdio>
#include <exception>

#include "craneassist/web/web_server.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"
#include "web_view.hpp"

namespace craneassist::cli {
namespace {

// "ADDR:PORT", "[V6ADDR]:PORT" or ":PORT" (127.0.0.1); false when it is neither.
bool parse_listen(const std::string& text, web::WebOptions& o) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) return false;
  std::string host = text.substr(0, colon);
  const std::string port = text.substr(colon + 1);
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (ec != std::errc() || end != port.data() + port.size() || value > 65535) return false;
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  o.address = host.empty() ? "127.0.0.1" : host;
  o.port = static_cast<unsigned short>(value);
  return true;
}

}  // namespace

struct WebView::State {
  std::unique_ptr<web::WebServer> server;
};

WebView::WebView() : state_(std::make_unique<State>()) {}
WebView::~WebView() = default;

void add_web_options(CLI::App& command, WebArgs& args) {
  command.add_flag("--web", args.on,
                   "Serve the web view (3-D crane, gauges, plots, virtual joystick; docs/web.md) "
                   "and print its address; the input is the page unless --input says otherwise");
  command
      .add_option("--web-listen", args.listen,
                  "Where the web view listens, ADDR:PORT (port 0: any free port)")
      ->capture_default_str();
  command.add_flag("--web-remote-commands", args.remote_commands,
                   "Take the virtual joystick from other hosts too (with the session token; "
                   "docs/web.md#security)");
  command.add_option("--web-rate", args.frame_rate_hz, "Frames per second streamed to each page")
      ->check(FiniteRange(1.0, 100.0))
      ->capture_default_str();
}

int WebView::open(const WebArgs& args, const config::CraneConfig& crane, bool commands,
                  const dynamics::MobileBaseModel* base) {
  web::WebOptions o;
  if (!parse_listen(args.listen, o)) {
    spdlog::error("--web-listen: '{}' is not ADDR:PORT (e.g. 127.0.0.1:8080, :0, [::1]:8080)",
                  args.listen);
    return kExitUsage;
  }
  o.commands = commands;
  o.remote_commands = args.remote_commands;
  o.frame_rate_hz = args.frame_rate_hz;
  o.base = base;
  try {
    state_->server = std::make_unique<web::WebServer>(o, crane);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  std::printf("web: open %s\n", state_->server->url().c_str());
  std::fflush(stdout);
  return kExitOk;
}

control::CycleObserver* WebView::observer() {
  return state_->server ? &state_->server->observer() : nullptr;
}

void WebView::publish(const control::LogRow& row) noexcept {
  if (state_->server) state_->server->publish(row);
}

std::unique_ptr<input::CommandSource> WebView::pad_source(const input::JoystickMapping& mapping) {
  return state_->server->make_pad_source(mapping);
}

std::string WebView::report() const {
  return state_->server ? state_->server->report() : "";
}

}  // namespace craneassist::cli
