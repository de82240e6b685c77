#include "craneassist/foxglove/cycle_hand_over.hpp"

#include <time.h>

#include <cmath>

namespace craneassist::foxglove {

std::uint64_t message_time_ns(std::int64_t epoch_ns, double t_s) noexcept {
  const double ns = static_cast<double>(epoch_ns) + std::round(t_s * 1e9);
  if (!(ns > 0.0)) return 0;
  if (ns >= 1.8e19) return 18'000'000'000'000'000'000ULL;
  return static_cast<std::uint64_t>(ns);
}

std::int64_t wall_clock_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

}  // namespace craneassist::foxglove
