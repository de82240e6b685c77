// Which joints of a JointState sample are prismatic (q in m) and which angular (q in rad), for
// the units echo and the dashboard print (internal to the dds module).
#pragma once

#include <cstddef>
#include <string>

#include "craneassist_msgs.h"

namespace craneassist::dds {

// The sample's own `prismatic` flags when it has one per joint (craneassist publishes them
// from the crane model). Otherwise the joint name decides: a name containing "extension",
// "telescope" or "prismatic" is a length (the K70M's `extension`), anything else an angle.
inline bool is_prismatic(const craneassist::msg::JointState& m, std::size_t joint) {
  if (m.prismatic().size() == m.q().size() && joint < m.prismatic().size()) {
    return m.prismatic()[joint];
  }
  if (joint >= m.names().size()) return false;
  const std::string& name = m.names()[joint];
  for (const char* word : {"extension", "telescope", "prismatic"}) {
    if (name.find(word) != std::string::npos) return true;
  }
  return false;
}

}  // namespace craneassist::dds
