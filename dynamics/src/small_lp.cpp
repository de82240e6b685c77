#include "craneassist/dynamics/small_lp.hpp"

#include <algorithm>
#include <cmath>

namespace craneassist::dynamics {
namespace {

// Pivot and reduced-cost tolerance on row-scaled coefficients (each row's largest magnitude 1).
constexpr double kTolerance = 1e-12;

}  // namespace

DenseSimplex::DenseSimplex(int max_rows, int max_cols)
    : max_rows_(max_rows),
      max_cols_(max_cols),
      tableau_(Eigen::MatrixXd::Zero(max_rows, max_cols + 1)),
      objective_(Eigen::VectorXd::Zero(max_cols)),
      basic_(static_cast<std::size_t>(max_rows)),
      nonbasic_(static_cast<std::size_t>(max_cols)) {}

void DenseSimplex::reset(int rows, int cols) noexcept {
  rows_ = std::clamp(rows, 0, max_rows_);
  cols_ = std::clamp(cols, 0, max_cols_);
  tableau_.topLeftCorner(rows_, cols_ + 1).setZero();
  objective_.head(cols_).setZero();
  value_ = 0.0;
  iterations_ = 0;
}

double DenseSimplex::x(int col) const noexcept {
  for (int i = 0; i < rows_; ++i) {
    if (basic_[static_cast<std::size_t>(i)] == col) return tableau_(i, cols_);
  }
  return 0.0;
}

void DenseSimplex::pivot(int row, int col) noexcept {
  const int rhs = cols_;
  const double inv = 1.0 / tableau_(row, col);
  // The pivot row solved for the entering variable.
  for (int j = 0; j <= rhs; ++j) {
    if (j != col) tableau_(row, j) *= inv;
  }
  tableau_(row, col) = inv;
  for (int i = 0; i < rows_; ++i) {
    if (i == row) continue;
    const double f = tableau_(i, col);
    if (f == 0.0) continue;
    for (int j = 0; j <= rhs; ++j) {
      if (j != col) tableau_(i, j) -= f * tableau_(row, j);
    }
    tableau_(i, col) = -f * inv;
  }
  const double f = objective_[col];
  for (int j = 0; j < cols_; ++j) {
    if (j != col) objective_[j] -= f * tableau_(row, j);
  }
  value_ += f * tableau_(row, rhs);
  objective_[col] = -f * inv;
  std::swap(basic_[static_cast<std::size_t>(row)], nonbasic_[static_cast<std::size_t>(col)]);
}

LpStatus DenseSimplex::solve() noexcept {
  const int rhs = cols_;
  for (int j = 0; j < cols_; ++j) nonbasic_[static_cast<std::size_t>(j)] = j;
  for (int i = 0; i < rows_; ++i) {
    basic_[static_cast<std::size_t>(i)] = cols_ + i;
    // Row scaling: the slack of row i is then in scaled units, which x() never reports.
    const double scale = tableau_.row(i).head(rhs + 1).cwiseAbs().maxCoeff();
    if (scale > 0.0) tableau_.row(i).head(rhs + 1) /= scale;
    tableau_(i, rhs) = std::max(tableau_(i, rhs), 0.0);
  }
  // Bland's rule terminates; this bound only guards against a bug (the number of bases is far
  // larger, but Bland's rule visits few of them on problems this small).
  const int max_iterations = 50 * (rows_ + cols_ + 1);
  for (iterations_ = 0; iterations_ < max_iterations; ++iterations_) {
    // Entering: the improving variable with the smallest label.
    int enter = -1;
    for (int j = 0; j < cols_; ++j) {
      if (objective_[j] > kTolerance &&
          (enter < 0 ||
           nonbasic_[static_cast<std::size_t>(j)] < nonbasic_[static_cast<std::size_t>(enter)])) {
        enter = j;
      }
    }
    if (enter < 0) return LpStatus::kOptimal;
    // Leaving: the smallest ratio, ties to the smallest label.
    int leave = -1;
    double best = 0.0;
    for (int i = 0; i < rows_; ++i) {
      const double a = tableau_(i, enter);
      if (a <= kTolerance) continue;
      const double ratio = tableau_(i, rhs) / a;
      if (leave < 0 || ratio < best ||
          (ratio == best &&
           basic_[static_cast<std::size_t>(i)] < basic_[static_cast<std::size_t>(leave)])) {
        leave = i;
        best = ratio;
      }
    }
    if (leave < 0) return LpStatus::kUnbounded;
    pivot(leave, enter);
    // Rounding may leave a basic value a hair below zero; it is zero.
    for (int i = 0; i < rows_; ++i) tableau_(i, rhs) = std::max(tableau_(i, rhs), 0.0);
  }
  return LpStatus::kIterationLimit;
}

}  // namespace craneassist::dynamics
