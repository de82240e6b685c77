#include "craneassist/input/sdl_source.hpp"

#include <SDL.h>

#include <stdexcept>
#include <string>

namespace craneassist::input {
SdlSource::SdlSource(const JoystickMapping& mapping, const Options& options)
    : DevicePadSource(mapping), options_(options) {
  SDL_SetHint(SDL_HINT_JOYSTICK_ALLOW_BACKGROUND_EVENTS, "1");
  if (SDL_InitSubSystem(SDL_INIT_GAMECONTROLLER) != 0) {
    throw std::runtime_error(std::string("SDL: cannot initialise game controllers: ") +
                             SDL_GetError());
  }
  if (options_.own_thread) start_reader();
}

SdlSource::~SdlSource() {
  stop_reader();
  if (controller_ != nullptr) SDL_GameControllerClose(controller_);
  SDL_QuitSubSystem(SDL_INIT_GAMECONTROLLER);
}

void SdlSource::open_first() {
  for (int i = 0; i < SDL_NumJoysticks(); ++i) {
    if (!SDL_IsGameController(i)) continue;
    controller_ = SDL_GameControllerOpen(i);
    if (controller_ != nullptr) {
      instance_id_ = SDL_JoystickInstanceID(SDL_GameControllerGetJoystick(controller_));
      return;
    }
  }
}

void SdlSource::service() {
  SDL_Event e;
  bool have_event = SDL_WaitEventTimeout(&e, options_.wait_ms) != 0;
  while (have_event) {
    if (e.type == SDL_CONTROLLERDEVICEREMOVED && controller_ != nullptr &&
        e.cdevice.which == instance_id_) {
      SDL_GameControllerClose(controller_);
      controller_ = nullptr;
      instance_id_ = -1;
    }
    have_event = SDL_PollEvent(&e) != 0;
  }
  if (controller_ == nullptr) open_first();  // at start and after SDL_CONTROLLERDEVICEADDED
  published_.connected = controller_ != nullptr;
  published_.has_state = controller_ != nullptr;
  if (controller_ != nullptr) {
    for (std::size_t a = 0; a < kGamepadAxisCount; ++a) {
      const double raw =
          SDL_GameControllerGetAxis(controller_, static_cast<SDL_GameControllerAxis>(a));
      // Sticks -32768..32767, triggers 0..32767.
      published_.pad.axes[a] = raw < 0.0 ? raw / 32768.0 : raw / 32767.0;
    }
    for (std::size_t b = 0; b < kGamepadButtonCount; ++b) {
      published_.pad.buttons[b] =
          SDL_GameControllerGetButton(controller_, static_cast<SDL_GameControllerButton>(b)) != 0;
    }
  } else {
    published_.pad = {};
  }
  published_.stamp_s = input::steady_now_s();
  latest_.publish(published_);
}

}  // namespace craneassist::input
