// The rigid-body dynamics terms as plain data: what RigidBodyTerms (rigid_body_terms.hpp) fills
// and what the scaling reads. Kept apart from RigidBodyTerms so that code that only passes the
// terms around (scaling's headers) needs neither the probe nor ODE.
//
// Convention: tau = H(q) qddot + C(q,qdot) qdot + g(q) (+ tau_ext), docs/algorithms.md section 3.
#pragma once

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

struct DynamicsTerms {
  JointMatrix mass;      // H(q)
  JointVector coriolis;  // C(q, qdot) qdot
  JointVector gravity;   // g(q)
};

// The dynamics along a path q = f(s) (docs/algorithms.md section 3, corrected):
// tau = m sddot + b with m = H(q) f' and b = H(q) f'' sdot^2 + C(q, f' sdot) f' sdot + g(q).
struct PathTerms {
  JointVector m;
  JointVector b;
};

}  // namespace craneassist::dynamics
