// The factorisations of engine/linear beyond KLU: the symmetric-part factorisation of
// cholmod_solver solves with (A + A^T)/2 where that is positive definite, and with A itself
// (UMFPACK) from the first matrix whose symmetric part is not; the dense LU of the smallest
// systems solves with A and reports a singular one; the LU of the large systems solves to
// round-off without iterative refinement.
#include "engine/linear/cholmod_solver.hpp"
#include "engine/linear/condensed_solver.hpp"
#include "engine/linear/dense_lu.hpp"
#include "engine/linear/sparse_lu.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <cstdio>
#include <memory>
#include <utility>

namespace mpx::test {
namespace {

// A non-symmetric banded matrix of size n: diagonal `diagonal`, A(i, i+1) = 1 + skew and
// A(i+1, i) = 1 - skew, A(i, i+3) = 0.3 without a transposed partner (a one-sided pattern entry).
Eigen::SparseMatrix<double> bandedMatrix(int n, double diagonal, double skew) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) {
    entries.emplace_back(i, i, diagonal + 0.01 * i);
    if (i + 1 < n) entries.emplace_back(i, i + 1, 1.0 + skew), entries.emplace_back(i + 1, i, 1.0 - skew);
    if (i + 3 < n) entries.emplace_back(i, i + 3, 0.3);
  }
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(entries.begin(), entries.end());
  a.makeCompressed();
  return a;
}

// Factorise `a` (expected to succeed) and solve with rhs.
Eigen::VectorXd factorizeAndSolve(CholmodSolver& solver, const Eigen::SparseMatrix<double>& a,
                                  const Eigen::VectorXd& rhs) {
  EXPECT_TRUE(solver.factorize(a, false));
  Eigen::VectorXd x = rhs;
  solver.solve(x);
  return x;
}

Eigen::MatrixXd symmetricPartOf(const Eigen::SparseMatrix<double>& a) {
  const Eigen::MatrixXd dense(a);
  return 0.5 * (dense + dense.transpose());
}

// The smallest systems (up to kSmallSystem unknowns) go to the dense LU; it solves a
// non-symmetric system that needs row exchanges (a zero on the diagonal) to round-off, with new
// values on the same pattern, and refuses a singular matrix.
TEST(DenseFactorisation, SolvesSmallSystemsAndRefusesSingularOnes) {
  const int n = kSmallSystem;
  EXPECT_STREQ(makeSparseLu(n)->name(), "a dense LU");
  EXPECT_STREQ(makeSparseLu(n + 1)->name(), "KLU");
  // every factorisation but the symmetric part's is of the matrix itself
  EXPECT_FALSE(makeSparseLu(n)->approximates());
  EXPECT_FALSE(makeSparseLu(n + 1)->approximates());
  EXPECT_FALSE(makeSparseLu(kLargeSystem)->approximates());
  EXPECT_TRUE(makeSparseLu(kLargeSystem, true)->approximates());
  DenseLu solver(n);
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  for (const double diagonal : {0.0, 3.0}) {
    const Eigen::SparseMatrix<double> a = bandedMatrix(n, diagonal, 0.5);
    ASSERT_TRUE(solver.factorize(a, false));
    Eigen::VectorXd x = rhs;
    solver.solve(x);
    // backward stable: the residual is round-off of |A| |x|
    EXPECT_LT((a * x - rhs).norm(), 1e-13 * a.norm() * x.norm()) << "diagonal " << diagonal;
  }
  // two equal rows: singular
  Eigen::MatrixXd dense = Eigen::MatrixXd(bandedMatrix(n, 3.0, 0.5));
  dense.row(1) = dense.row(0);
  const Eigen::SparseMatrix<double> singular = dense.sparseView();
  EXPECT_FALSE(solver.factorize(singular, false));
}

TEST(SymmetricFactorisation, SolvesWithTheSymmetricPart) {
  const int n = 40;
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  CholmodSolver solver(n);
  const Eigen::SparseMatrix<double> a = bandedMatrix(n, 4.0, 0.5);
  const Eigen::VectorXd x = factorizeAndSolve(solver, a, rhs);
  EXPECT_NE(std::string(solver.name()).find("CHOLMOD"), std::string::npos);
  EXPECT_TRUE(solver.approximates());
  EXPECT_LT((symmetricPartOf(a) * x - rhs).norm(), 1e-12 * rhs.norm());
  // and not with A: the skew part (0.5 off the diagonal) is not negligible
  EXPECT_GT((a * x - rhs).norm(), 1e-2 * rhs.norm());
  // new values on the same pattern are factorised afresh
  const Eigen::SparseMatrix<double> b = bandedMatrix(n, 6.0, -0.2);
  EXPECT_LT((symmetricPartOf(b) * factorizeAndSolve(solver, b, rhs) - rhs).norm(), 1e-12 * rhs.norm());
}

TEST(SymmetricFactorisation, FallsBackToTheLuOfTheMatrixWhereTheSymmetricPartIsIndefinite) {
  const int n = 40;
  const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(n);
  CholmodSolver solver(n);
  // diagonal 0.5 against off-diagonal sums up to 2.6: the symmetric part is indefinite, while
  // the matrix itself is regular
  const Eigen::SparseMatrix<double> a = bandedMatrix(n, 0.5, 0.0);
  EXPECT_LT((a * factorizeAndSolve(solver, a, rhs) - rhs).norm(), 1e-10 * rhs.norm());
  EXPECT_NE(std::string(solver.name()).find("UMFPACK"), std::string::npos);
  EXPECT_FALSE(solver.approximates());
  // and stays with the LU for later matrices, also positive definite ones
  const Eigen::SparseMatrix<double> b = bandedMatrix(n, 4.0, 0.5);
  EXPECT_LT((b * factorizeAndSolve(solver, b, rhs) - rhs).norm(), 1e-12 * rhs.norm());
}

// The large systems' LU (UMFPACK) solves without iterative refinement, so each solve is the
// factors' triangular solves alone: it must still solve a non-symmetric system to round-off
// (backward error), answer alike for every right-hand side it is handed after one factorisation
// (simplified Newton reuses it), and take new values on the same pattern.
TEST(LargeSystemLu, SolvesToRoundOffWithoutRefinement) {
  const int n = kLargeSystem;
  const std::unique_ptr<SparseLu> lu = makeSparseLu(n);
  EXPECT_STREQ(lu->name(), "UMFPACK");
  for (const auto& [diagonal, skew] : {std::pair{4.0, 0.5}, std::pair{2.5, -0.3}}) {
    const Eigen::SparseMatrix<double> a = bandedMatrix(n, diagonal, skew);
    ASSERT_TRUE(lu->factorize(a, false));
    for (int k = 0; k < 3; ++k) {
      const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0 + k).array().sin();
      Eigen::VectorXd x = rhs;
      lu->solve(x);
      const double backwardError = (a * x - rhs).norm() / (a.norm() * x.norm() + rhs.norm());
      std::printf("UMFPACK, diagonal %.1f, right-hand side %d: backward error %.2e\n", diagonal, k, backwardError);
      EXPECT_LT(backwardError, 1e-15) << "diagonal " << diagonal << ", right-hand side " << k;
    }
  }
}

// The condensed solver describes what factorised its last system, which run summaries read when
// the run ends: a large system whose symmetric part is indefinite is reported as the LU that took
// over, and solved with it.
TEST(SymmetricFactorisation, CondensedSolverReportsTheLuThatTookOver) {
  const int n = kLargeSystem;
  const Eigen::SparseMatrix<double> a = bandedMatrix(n, 0.5, 0.0);
  CondensedSolver solver(Layout({0, 0, n, 0, 0}), a, true);
  EXPECT_NE(solver.describe().find("CHOLMOD"), std::string::npos) << solver.describe();
  EXPECT_FALSE(solver.factorisesTheTangent());
  ASSERT_TRUE(solver.factorize(a, false));
  EXPECT_NE(solver.describe().find("UMFPACK"), std::string::npos) << solver.describe();
  EXPECT_TRUE(solver.factorisesTheTangent());
  const Eigen::VectorXd residual = Eigen::VectorXd::Ones(n);
  Eigen::VectorXd increment(n);
  solver.solve(residual, increment);
  EXPECT_LT((a * increment + residual).norm(), 1e-10 * residual.norm());
}

}  // namespace
}  // namespace mpx::test
