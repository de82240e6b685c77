// The SDL2 game controller source on SDL's virtual joystick (no hardware, no window): the
// controller is found, its sticks and buttons are mapped, and unplugging and plugging it back
// (SDL_CONTROLLERDEVICEREMOVED/ADDED) report disconnected and connected.
#include <SDL.h>
#include <gtest/gtest.h>

#include <cstdlib>

#include "craneassist/input/sdl_source.hpp"

using namespace craneassist::input;

namespace {

class SdlSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    setenv("SDL_VIDEODRIVER", "dummy", 1);
    setenv("SDL_AUDIODRIVER", "dummy", 1);
    ASSERT_EQ(SDL_InitSubSystem(SDL_INIT_GAMECONTROLLER), 0) << SDL_GetError();
  }
  void TearDown() override { SDL_QuitSubSystem(SDL_INIT_GAMECONTROLLER); }

  // A virtual pad in the game controller layout; returns its opened joystick (for setting values).
  SDL_Joystick* attach() {
    const int index = SDL_JoystickAttachVirtual(
        SDL_JOYSTICK_TYPE_GAMECONTROLLER, SDL_CONTROLLER_AXIS_MAX, SDL_CONTROLLER_BUTTON_MAX, 0);
    EXPECT_GE(index, 0) << SDL_GetError();
    index_ = index;
    SDL_Joystick* j = SDL_JoystickOpen(index);
    EXPECT_NE(j, nullptr) << SDL_GetError();
    return j;
  }
  void detach(SDL_Joystick* j) {
    SDL_JoystickClose(j);
    SDL_JoystickDetachVirtual(index_);
  }
  int index_ = -1;
};

SourceState service_and_poll(SdlSource& s, OperatorCommand& c, int rounds = 3) {
  for (int i = 0; i < rounds; ++i) s.service();
  return s.poll(c);
}

}  // namespace

TEST_F(SdlSourceTest, VirtualPadMappingAndHotPlug) {
  SdlSource::Options o;
  o.own_thread = false;
  o.wait_ms = 1;
  SdlSource source(default_gamepad_mapping(), o);
  OperatorCommand c;
  EXPECT_EQ(service_and_poll(source, c), SourceState::kDisconnected);  // no controller yet

  SDL_Joystick* j = attach();
  ASSERT_EQ(service_and_poll(source, c), SourceState::kOk);
  EXPECT_FALSE(c.deadman);
  EXPECT_TRUE(c.v_m_s.isZero(1e-12));

  SDL_JoystickSetVirtualAxis(j, SDL_CONTROLLER_AXIS_RIGHTY, -32768);  // right stick away: up
  SDL_JoystickSetVirtualAxis(j, SDL_CONTROLLER_AXIS_LEFTX, 32767);    // left stick right
  SDL_JoystickSetVirtualButton(j, SDL_CONTROLLER_BUTTON_RIGHTSHOULDER, 1);
  source.begin_cycle(0.0, {5.0, 1.0, 0.0});
  ASSERT_EQ(service_and_poll(source, c), SourceState::kOk);
  EXPECT_TRUE(c.deadman);
  EXPECT_NEAR(c.v_m_s.y(), 0.4, 1e-9);
  EXPECT_NEAR(c.v_m_s.z(), 0.5, 1e-9);  // slew right, tip straight ahead: +z
  EXPECT_NEAR(c.v_m_s.x(), 0.0, 1e-9);

  detach(j);
  EXPECT_EQ(service_and_poll(source, c), SourceState::kDisconnected);

  j = attach();  // plugged back in: found again, state from scratch
  ASSERT_EQ(service_and_poll(source, c), SourceState::kOk);
  EXPECT_FALSE(c.deadman);
  detach(j);
}

TEST_F(SdlSourceTest, ReaderThreadStampsAdvance) {
  SDL_Joystick* j = attach();
  SdlSource::Options o;
  o.wait_ms = 5;
  SdlSource source(default_gamepad_mapping(), o);
  OperatorCommand c;
  const auto wait_ok = [&] {
    for (int i = 0; i < 200 && source.poll(c) != SourceState::kOk; ++i) SDL_Delay(5);
    return source.poll(c) == SourceState::kOk;
  };
  ASSERT_TRUE(wait_ok());
  const double first = c.stamp_s;
  SDL_Delay(50);
  source.poll(c);
  EXPECT_GT(c.stamp_s, first);
  detach(j);
}
