// Cubic Hermite interpolation between two samples of a position and its rate: position and rate
// both continuous from one interval to the next. Used where a sampled plan is followed between its
// samples (input::GoalSource's tip plan, studies::simulate_ptp's joint plan).
#pragma once

namespace craneassist::input {

// Samples (p0, v0) and (p1, v1) h > 0 apart; u = (t - t0) / h in [0, 1]. p, v: position and rate
// at t. V: any vector type with scalar products and sums (Eigen vectors). No allocation for
// fixed-size or bounded vectors.
template <typename V>
void cubic_hermite(const V& p0, const V& v0, const V& p1, const V& v1, double h, double u, V& p,
                   V& v) {
  const double u2 = u * u, u3 = u2 * u;
  p = (2 * u3 - 3 * u2 + 1) * p0 + ((u3 - 2 * u2 + u) * h) * v0 + (-2 * u3 + 3 * u2) * p1 +
      ((u3 - u2) * h) * v1;
  v = ((6 * u2 - 6 * u) / h) * p0 + (3 * u2 - 4 * u + 1) * v0 + ((-6 * u2 + 6 * u) / h) * p1 +
      (3 * u2 - 2 * u) * v1;
}

}  // namespace craneassist::input
