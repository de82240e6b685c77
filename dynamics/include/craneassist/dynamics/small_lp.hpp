// A small dense linear program, solved by the simplex method, for the control cycle:
//
//     maximise c^T x   subject to   A x <= b,  x >= 0,   with b >= 0.
//
// With b >= 0 the origin is feasible, so one phase suffices (every slack basic at the start).
// Bland's rule picks the entering and the leaving variable, so degenerate pivots (rows with
// b_i = 0, common here: a joint pinned at an end) cannot cycle. Each row is scaled to its
// largest magnitude before pivoting, so rows in different units (joint rates, pump flow) share
// one tolerance.
//
// Why not GLPK (libglpk-dev): the problems here have a handful of columns and a few dozen rows,
// and they are solved inside the control cycle, which must not allocate; GLPK allocates per
// problem and reports errors by aborting. This solver's storage is sized once, in the
// constructor; solve() allocates nothing and throws nothing.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace craneassist::dynamics {

enum class LpStatus {
  kOptimal,
  kUnbounded,       // the objective grows without bound
  kIterationLimit,  // not reached with Bland's rule; a guard against a bug
};

class DenseSimplex {
 public:
  // Storage for up to max_rows constraints and max_cols variables (allocates).
  DenseSimplex(int max_rows, int max_cols);

  // Starts a problem of this size with A, b and c all zero. rows <= max_rows, cols <= max_cols.
  void reset(int rows, int cols) noexcept;
  double& a(int row, int col) noexcept { return tableau_(row, col); }
  double& b(int row) noexcept { return tableau_(row, cols_); }
  double& c(int col) noexcept { return objective_[col]; }

  // Solves the problem as filled in (b must be >= 0). No allocation, no exception.
  LpStatus solve() noexcept;

  double value() const noexcept { return value_; }
  // Variable j at the optimum (0 unless basic).
  double x(int col) const noexcept;
  int rows() const noexcept { return rows_; }
  int cols() const noexcept { return cols_; }
  int iterations() const noexcept { return iterations_; }

 private:
  void pivot(int row, int col) noexcept;

  int max_rows_, max_cols_;
  int rows_ = 0, cols_ = 0;
  // rows_ x (cols_ + 1): the dictionary x_B = b - A x_N, b in the last used column.
  Eigen::MatrixXd tableau_;
  Eigen::VectorXd objective_;  // z = value_ + objective_^T x_N
  double value_ = 0.0;
  std::vector<int> basic_;     // label of the basic variable of each row (>= cols: a slack)
  std::vector<int> nonbasic_;  // label of the nonbasic variable of each column
  int iterations_ = 0;
};

}  // namespace craneassist::dynamics
