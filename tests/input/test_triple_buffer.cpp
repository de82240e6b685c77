// input::TripleBuffer: the newest value from one thread to another, whole, never lost.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

#include "craneassist/input/triple_buffer.hpp"

namespace {

using craneassist::input::TripleBuffer;

// A value that shows tearing: every word holds the same number.
struct Block {
  std::array<std::uint64_t, 32> words{};
  void fill(std::uint64_t n) { words.fill(n); }
  bool whole() const {
    for (auto w : words) {
      if (w != words[0]) return false;
    }
    return true;
  }
};

TEST(TripleBuffer, NothingBeforeTheFirstPublish) {
  TripleBuffer<int> b(7);
  EXPECT_FALSE(b.update());
  EXPECT_EQ(b.front(), 7);
}

TEST(TripleBuffer, TheConsumerGetsTheNewestOnlyOnce) {
  TripleBuffer<int> b;
  for (int v : {1, 2, 3}) {
    b.back() = v;
    b.publish();
  }
  ASSERT_TRUE(b.update());
  EXPECT_EQ(b.front(), 3);  // 1 and 2 were overwritten: the newest is what counts
  EXPECT_FALSE(b.update());
  EXPECT_EQ(b.front(), 3);
  b.back() = 4;
  b.publish();
  ASSERT_TRUE(b.update());
  EXPECT_EQ(b.front(), 4);
}

TEST(TripleBuffer, TheProducerNeverWritesTheConsumersSlot) {
  TripleBuffer<int> b;
  b.back() = 1;
  b.publish();
  ASSERT_TRUE(b.update());
  int& held = b.front();
  for (int v = 2; v < 10; ++v) {  // the consumer holds its slot while the producer goes on
    b.back() = v;
    b.publish();
    EXPECT_EQ(held, 1);
  }
  ASSERT_TRUE(b.update());
  EXPECT_EQ(b.front(), 9);
}

// Across threads: every value taken is whole and newer than the last, and the last published is
// always taken in the end (the end of a run must reach the consumer).
TEST(TripleBuffer, AcrossThreadsValuesAreWholeInOrderAndTheLastArrives) {
  constexpr std::uint64_t kValues = 200000;
  TripleBuffer<Block> b;
  std::atomic<bool> done{false};
  std::thread producer([&] {
    for (std::uint64_t n = 1; n <= kValues; ++n) {
      b.back().fill(n);
      b.publish();
    }
    done.store(true, std::memory_order_release);
  });
  std::uint64_t last = 0;
  std::uint64_t taken = 0;
  std::uint64_t torn = 0;
  std::uint64_t backwards = 0;
  while (true) {
    const bool finished = done.load(std::memory_order_acquire);
    if (b.update()) {
      ++taken;
      const Block& v = b.front();
      if (!v.whole()) ++torn;
      if (v.words[0] <= last) ++backwards;
      last = v.words[0];
    } else if (finished) {
      break;  // everything was published before `done`: nothing newer is left
    }
  }
  producer.join();
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_EQ(last, kValues);
  EXPECT_GT(taken, 0u);
}

}  // namespace
