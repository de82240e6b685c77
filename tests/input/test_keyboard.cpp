// The virtual joystick's logic: terminal bytes to keys, and keys to held axes with the hold
// timeout that stands in for the key-up events terminals do not send.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "craneassist/input/keyboard.hpp"

using namespace craneassist::input;

namespace {

std::vector<Key> decode(const std::string& bytes) {
  KeyDecoder d;
  std::vector<Key> keys;
  for (char c : bytes) {
    const Key k = d.feed(static_cast<std::uint8_t>(c));
    if (k != Key::kNone) keys.push_back(k);
  }
  return keys;
}

}  // namespace

TEST(KeyDecoder, LettersArrowsAndPageKeys) {
  EXPECT_EQ(decode("wasdrf q+-lx"),
            (std::vector<Key>{Key::kForward, Key::kLeft, Key::kBack, Key::kRight, Key::kUp,
                              Key::kDown, Key::kDeadman, Key::kQuit, Key::kFaster, Key::kSlower,
                              Key::kLatch, Key::kStopAll}));
  EXPECT_EQ(decode("\x1b[A\x1b[B\x1b[C\x1b[D"),
            (std::vector<Key>{Key::kForward, Key::kBack, Key::kRight, Key::kLeft}));
  EXPECT_EQ(decode("\x1bOA"), (std::vector<Key>{Key::kForward}));  // application cursor mode
  EXPECT_EQ(decode("\x1b[5~\x1b[6~"), (std::vector<Key>{Key::kUp, Key::kDown}));
  EXPECT_EQ(decode("\x1b[3~w"), (std::vector<Key>{Key::kForward}));    // Delete: ignored
  EXPECT_EQ(decode("\x1b[1;5Cw"), (std::vector<Key>{Key::kForward}));  // Ctrl-Right: ignored
  EXPECT_EQ(decode("\x1bxw"), (std::vector<Key>{Key::kForward}));      // Alt-x: dropped
}

TEST(KeyDecoder, SequenceSplitAcrossReads) {
  KeyDecoder d;
  EXPECT_EQ(d.feed(0x1b), Key::kNone);
  EXPECT_EQ(d.feed('['), Key::kNone);
  EXPECT_EQ(d.feed('6'), Key::kNone);
  EXPECT_EQ(d.feed('~'), Key::kDown);
  EXPECT_EQ(d.feed('d'), Key::kRight);
}

TEST(KeyboardState, APressHoldsForFirstHoldAndRepeatsExtendIt) {
  KeyboardState k({0.5, 0.15});
  k.on_key(Key::kForward, 1.0);
  const double step = 2.0 / KeyboardState::kSteps;  // default speed step 2 of 4
  EXPECT_DOUBLE_EQ(k.axes(1.0)[1], step);
  EXPECT_DOUBLE_EQ(k.axes(1.49)[1], step);
  EXPECT_DOUBLE_EQ(k.axes(1.51)[1], 0.0);  // released: no repeat came
  // Held: auto-repeat starts after 0.45 s, then every 33 ms.
  k.on_key(Key::kForward, 2.0);
  for (double t = 2.45; t < 3.0; t += 0.033) {
    k.on_key(Key::kForward, t);
    EXPECT_DOUBLE_EQ(k.axes(t + 0.03)[1], step) << t;
  }
  // The last repeat at about 2.96 s: the axis drops 150 ms later, not 500 ms.
  EXPECT_DOUBLE_EQ(k.axes(3.08)[1], step);
  EXPECT_DOUBLE_EQ(k.axes(3.13)[1], 0.0);
}

TEST(KeyboardState, OppositeKeyTakesOverAndAxesAreIndependent) {
  KeyboardState k({0.5, 0.15});
  k.on_key(Key::kLeft, 0.0);
  k.on_key(Key::kUp, 0.0);
  Eigen::Vector3d v = k.axes(0.1);
  EXPECT_LT(v[0], 0.0);
  EXPECT_EQ(v[1], 0.0);
  EXPECT_GT(v[2], 0.0);
  k.on_key(Key::kRight, 0.2);
  EXPECT_GT(k.axes(0.3)[0], 0.0);
}

TEST(KeyboardState, SpeedStepsDeadmanToggleLatchAndQuit) {
  KeyboardState k({0.5, 0.15});
  EXPECT_FALSE(k.deadman());
  k.on_key(Key::kDeadman, 0.0);
  EXPECT_TRUE(k.deadman());
  k.on_key(Key::kDeadman, 0.0);
  EXPECT_FALSE(k.deadman());
  for (int i = 0; i < 6; ++i) k.on_key(Key::kFaster, 0.0);
  EXPECT_EQ(k.speed_step(), KeyboardState::kSteps);
  for (int i = 0; i < 6; ++i) k.on_key(Key::kSlower, 0.0);
  EXPECT_EQ(k.speed_step(), 1);
  k.on_key(Key::kLatch, 0.0);
  EXPECT_TRUE(k.latched());
  k.on_key(Key::kDown, 1.0);
  EXPECT_DOUBLE_EQ(k.axes(100.0)[2], -1.0 / KeyboardState::kSteps);  // held until cancelled
  k.on_key(Key::kUp, 2.0);                                           // the opposite cancels
  EXPECT_EQ(k.axes(2.0)[2], 0.0);
  k.on_key(Key::kForward, 3.0);
  k.on_key(Key::kStopAll, 4.0);
  EXPECT_TRUE(k.axes(4.0).isZero());
  k.on_key(Key::kForward, 5.0);
  k.on_key(Key::kQuit, 5.0);
  EXPECT_TRUE(k.quit());
  EXPECT_TRUE(k.axes(5.0).isZero());
}

TEST(KeyboardState, DriveKeysHoldTheDriveAxesApartFromTheTip) {
  EXPECT_EQ(decode("ikuo"), (std::vector<Key>{Key::kDriveForward, Key::kDriveBack, Key::kSteerLeft,
                                              Key::kSteerRight}));
  KeyboardState k({0.5, 0.15});
  const double step = 2.0 / KeyboardState::kSteps;
  k.on_key(Key::kDriveForward, 0.0);
  k.on_key(Key::kSteerLeft, 0.0);
  EXPECT_DOUBLE_EQ(k.drive(0.1)[0], step);
  EXPECT_DOUBLE_EQ(k.drive(0.1)[1], step);  // left is positive curvature
  EXPECT_TRUE(k.axes(0.1).isZero());        // the tip does not move
  k.on_key(Key::kSteerRight, 0.2);
  EXPECT_DOUBLE_EQ(k.drive(0.3)[1], -step);
  EXPECT_DOUBLE_EQ(k.drive(0.6)[0], 0.0);  // released: no repeat came
  k.on_key(Key::kDriveBack, 1.0);
  k.on_key(Key::kStopAll, 1.1);
  EXPECT_TRUE(k.drive(1.2).isZero());
}
