#include "craneassist/control/cycle_timing.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace craneassist::control {
namespace {

void add_reason(std::string& out, const std::string& reason) {
  if (!out.empty()) out += "; ";
  out += reason;
}

}  // namespace

RealtimeResult apply_realtime_setup(const RealtimeSetup& setup) {
  RealtimeResult r;
  if (setup.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      r.memory_locked = true;
    } else {
      add_reason(r.refused, std::string("memory lock refused: ") + std::strerror(errno) +
                                " (raise `ulimit -l` or grant CAP_IPC_LOCK)");
    }
  }
  if (setup.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<unsigned>(setup.cpu), &set);
    const int rc =
        setup.cpu < CPU_SETSIZE ? pthread_setaffinity_np(pthread_self(), sizeof set, &set) : EINVAL;
    if (rc == 0) {
      r.cpu = setup.cpu;
    } else {
      add_reason(r.refused,
                 "pinning to core " + std::to_string(setup.cpu) + " refused: " + std::strerror(rc));
    }
  }
  if (setup.priority > 0) {
    sched_param previous{};
    pthread_getschedparam(pthread_self(), &r.previous_policy, &previous);
    r.previous_priority = previous.sched_priority;
    sched_param param{};
    param.sched_priority = std::clamp(setup.priority, sched_get_priority_min(SCHED_FIFO),
                                      sched_get_priority_max(SCHED_FIFO));
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    if (rc == 0) {
      r.priority = param.sched_priority;
    } else {
      add_reason(r.refused, "SCHED_FIFO priority " + std::to_string(param.sched_priority) +
                                " refused: " + std::strerror(rc) +
                                " (needs CAP_SYS_NICE, or an rtprio limit in "
                                "/etc/security/limits.conf, e.g. `@realtime - rtprio 90`)");
    }
  }
  return r;
}

void undo_realtime_setup(const RealtimeResult& result) {
  if (result.priority > 0) {
    sched_param previous{};
    previous.sched_priority = result.previous_priority;
    pthread_setschedparam(pthread_self(), result.previous_policy, &previous);
  }
  if (result.memory_locked) munlockall();
}

void DurationHistogram::add(double d_s) noexcept {
  if (!(d_s >= 0.0)) d_s = 0.0;  // a clock read out of order, or NaN
  if (count_ == 0 || d_s < min_s_) min_s_ = d_s;
  max_s_ = std::max(max_s_, d_s);
  sum_s_ += d_s;
  ++count_;
  const double bin = std::floor(d_s / kBinS);
  if (bin < static_cast<double>(kBins)) {
    ++bins_[static_cast<std::size_t>(bin)];
  } else {
    ++beyond_;
  }
}

double DurationHistogram::quantile_s(double p) const noexcept {
  if (count_ == 0) return 0.0;
  const double wanted = std::clamp(p, 0.0, 1.0) * static_cast<double>(count_);
  double seen = 0.0;
  for (int b = 0; b < kBins; ++b) {
    seen += bins_[static_cast<std::size_t>(b)];
    if (seen >= wanted) return std::min(max_s_, (b + 1) * kBinS);
  }
  return max_s_;
}

std::string describe(const CycleTiming& t) {
  char buf[256];
  const auto us = [](double s) { return s * 1e6; };
  if (t.start_latency.count() > 0) {
    std::snprintf(buf, sizeof buf,
                  "start latency max %.0f us (p99 %.0f, mean %.0f), compute max %.0f us (p99 "
                  "%.0f, mean %.0f), %ld overruns in %ld cycles",
                  us(t.start_latency.max_s()), us(t.start_latency.quantile_s(0.99)),
                  us(t.start_latency.mean_s()), us(t.compute.max_s()),
                  us(t.compute.quantile_s(0.99)), us(t.compute.mean_s()), t.overruns,
                  t.compute.count());
  } else {
    std::snprintf(buf, sizeof buf, "compute max %.0f us (p99 %.0f, mean %.0f) in %ld cycles",
                  us(t.compute.max_s()), us(t.compute.quantile_s(0.99)), us(t.compute.mean_s()),
                  t.compute.count());
  }
  return buf;
}

}  // namespace craneassist::control
