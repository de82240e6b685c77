// Physical joysticks through SDL2's GameController API (any pad SDL has a mapping for, in the
// Xbox layout): SDL_INIT_GAMECONTROLLER, hot-plug by SDL_CONTROLLERDEVICEADDED/REMOVED. A reader
// thread pumps SDL's events (bounded waits) and publishes the controller's state; the loop's
// poll() takes it without waiting and maps it (joystick_mapping.hpp). Needs no window: SDL's
// video subsystem is not initialised.
#pragma once

#include <atomic>
#include <thread>

#include "craneassist/input/command_source.hpp"
#include "craneassist/input/joystick_mapping.hpp"
#include "craneassist/input/latest_pad.hpp"

struct _SDL_GameController;

namespace craneassist::input {

class SdlSource : public CommandSource {
 public:
  struct Options {
    int wait_ms = 20;        // bounded wait for SDL events per round
    bool own_thread = true;  // false: the owner calls service() on its thread (tests)
  };
  // Initialises SDL's game controller subsystem; throws std::runtime_error when SDL cannot.
  SdlSource(const JoystickMapping& mapping, const Options& options);
  ~SdlSource() override;
  SdlSource(const SdlSource&) = delete;
  SdlSource& operator=(const SdlSource&) = delete;

  void begin_cycle(double now_s, const Eigen::Vector3d& tip_m) noexcept override;
  SourceState poll(OperatorCommand& out) noexcept override;
  const char* name() const noexcept override { return "sdl"; }

  // One round: handle SDL's events (device added/removed) and read the controller.
  void service();

 private:
  void open_first();

  JoystickMapper mapper_;
  Options options_;
  _SDL_GameController* controller_ = nullptr;
  int instance_id_ = -1;
  PadSnapshot published_;
  LatestPad latest_;
  PadSnapshot taken_;
  Eigen::Vector3d tip_ = Eigen::Vector3d::UnitX();
  std::atomic<bool> running_{true};
  std::thread thread_;
};

}  // namespace craneassist::input
