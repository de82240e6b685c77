// A test of real-time behaviour runs its loop as a machine runs it: with a SCHED_FIFO priority
// where the test may have one (as root, as CI runs), so a busy host (`stress-ng --cpu 2`, a build
// beside it) cannot starve the loop while the test measures it. Threads started afterwards (a
// backend's watchdog) inherit the policy. Without the privilege the thread stays as it was and
// the test runs as before. The thread's old policy comes back at the end of the scope.
#pragma once

#include <pthread.h>
#include <sched.h>

namespace craneassist::test {

class RealtimeThread {
 public:
  explicit RealtimeThread(int priority = 20) {
    pthread_getschedparam(pthread_self(), &old_policy_, &old_param_);
    sched_param p{};
    p.sched_priority = priority;
    granted_ = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
  }
  ~RealtimeThread() {
    if (granted_) pthread_setschedparam(pthread_self(), old_policy_, &old_param_);
  }
  RealtimeThread(const RealtimeThread&) = delete;
  RealtimeThread& operator=(const RealtimeThread&) = delete;
  bool granted() const { return granted_; }

 private:
  int old_policy_ = SCHED_OTHER;
  sched_param old_param_{};
  bool granted_ = false;
};

}  // namespace craneassist::test
