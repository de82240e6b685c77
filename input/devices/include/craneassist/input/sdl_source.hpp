// Physical joysticks through SDL2's GameController API (any pad SDL has a mapping for, in the
// Xbox layout): SDL_INIT_GAMECONTROLLER, hot-plug by SDL_CONTROLLERDEVICEADDED/REMOVED. A reader
// thread (device_pad_source.hpp) pumps SDL's events (bounded waits) and publishes the
// controller's state; the loop's poll() takes it without waiting and maps it. Needs no window:
// SDL's video subsystem is not initialised.
#pragma once

#include "craneassist/input/device_pad_source.hpp"

struct _SDL_GameController;

namespace craneassist::input {

class SdlSource : public DevicePadSource {
 public:
  struct Options {
    int wait_ms = 20;        // bounded wait for SDL events per round
    bool own_thread = true;  // false: the owner calls service() on its thread (tests)
  };
  // Initialises SDL's game controller subsystem; throws std::runtime_error when SDL cannot.
  SdlSource(const JoystickMapping& mapping, const Options& options);
  ~SdlSource() override;

  const char* name() const noexcept override { return "sdl"; }

  // One round: handle SDL's events (device added/removed) and read the controller. A controller
  // is published with its state (SDL reads it whole), so poll() never says kNoData.
  void service() override;

 private:
  void open_first();

  Options options_;
  _SDL_GameController* controller_ = nullptr;
  int instance_id_ = -1;
  PadSnapshot published_;
};

}  // namespace craneassist::input
