// A measured valve characteristic for the valve-table and follower tests: curved and asymmetric,
// dead band -0.48 .. 0.55, progressive opening.
#pragma once

#include "craneassist/dynamics/valve_table.hpp"

namespace craneassist::test {

inline dynamics::ValveTable curved_table() {
  dynamics::ValveTable t;
  t.command = {-1.0, -0.8, -0.6, -0.48, 0.0, 0.55, 0.6, 0.7, 0.85, 1.0};
  t.velocity_m_s = {-0.12, -0.07, -0.02, 0.0, 0.0, 0.0, 0.01, 0.04, 0.1, 0.16};
  return t;
}

}  // namespace craneassist::test
