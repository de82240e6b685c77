// The web view of `craneassist sim --web` (docs/web.md) behind a seam: built from app/web
// (web_view_on.cpp), or in a build without it (CRANEASSIST_WEB=OFF) refused with a clear message
// (web_view_none.cpp).
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/control_loop.hpp"
#include "craneassist/dynamics/mobile_base.hpp"
#include "craneassist/input/command_source.hpp"
#include "craneassist/input/joystick_mapping.hpp"

namespace craneassist::cli {

struct WebArgs {
  bool on = false;                        // --web
  std::string listen = "127.0.0.1:8080";  // --web-listen ADDR:PORT
  bool remote_commands = false;           // --web-remote-commands
  double frame_rate_hz = 30.0;            // --web-rate
};

void add_web_options(CLI::App& command, WebArgs& args);

class WebView {
 public:
  WebView();
  ~WebView();
  WebView(const WebView&) = delete;
  WebView& operator=(const WebView&) = delete;

  // Starts the server and prints the page's address; returns kExitOk, kExitUsage (a bad
  // --web-listen, or a build without the web view) or kExitRuntime (cannot listen), logged.
  // commands false: the page is a view only.
  // base: the wheeled base the crane stands on (sim --drive; kept by reference), or nullptr.
  int open(const WebArgs& args, const config::CraneConfig& crane, bool commands = true,
           const dynamics::MobileBaseModel* base = nullptr);
  control::CycleObserver* observer();
  // A row from elsewhere (after open()): WebServer::publish.
  void publish(const control::LogRow& row) noexcept;
  // The page's virtual joystick (after open()).
  std::unique_ptr<input::CommandSource> pad_source(const input::JoystickMapping& mapping);
  // The summary line, or "" when not open.
  std::string report() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace craneassist::cli
