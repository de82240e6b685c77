// What the fuzz harnesses share: a check that stops the run (libFuzzer then keeps the input as a
// crash), for the properties a harness asserts beyond "no crash, no sanitizer report".
#pragma once

#include <cstdio>
#include <cstdlib>
#include <cstring>

// FUZZ_CHECK(condition, "what went wrong"): abort with the message when condition is false.
#define FUZZ_CHECK(condition, message)                                                         \
  do {                                                                                         \
    if (!(condition)) {                                                                        \
      std::fprintf(stderr, "%s:%d: fuzz check failed: %s (%s)\n", __FILE__, __LINE__, message, \
                   #condition);                                                                \
      std::abort();                                                                            \
    }                                                                                          \
  } while (false)

// The same double to the bit (a round trip must keep NaN payloads and the sign of zero).
inline bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}
