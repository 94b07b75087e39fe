// The Newton system: assembled matrix products and the CHOLMOD solves (double, and the single-precision
// preconditioner solve) against dense linear algebra.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <atomic>
#include <random>
#include <thread>

#include "drapegen/sim/bending.hpp"
#include "drapegen/sim/gravity.hpp"
#include "drapegen/sim/hessian_assembler.hpp"
#include "drapegen/sim/membrane.hpp"
#include "drapegen/sim/sparse_cholesky.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sim {
namespace {

struct System {
  ClothMesh mesh;
  Topology topology;
  std::unique_ptr<CorotationalMembrane> membrane;
  std::unique_ptr<DihedralBending> bending;
  std::unique_ptr<HessianAssembler> assembler;
};

/// The projected Hessian of a crumpled n x n specimen with its centre row fixed: symmetric positive definite.
System make_system(int n) {
  System s;
  s.mesh = make_specimen(SpecimenSpec{0.1, 0.1, n, n, 0.2, Triangulation::kRandom, 3, 0.0});
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1e-3);
  for (int v = 0; v < s.mesh.vertex_count(); ++v) s.mesh.positions(2, v) += noise(rng);
  s.topology = build_topology(s.mesh);
  s.membrane = std::make_unique<CorotationalMembrane>(s.mesh, MembraneParameters{});
  s.bending = std::make_unique<DihedralBending>(s.mesh, s.topology, DihedralModuli{{1e-5, 1e-5, 1e-5}, {0, 0, 0}},
                                                AnisotropyRule::kEdge);
  std::vector<bool> fixed(s.mesh.vertex_count(), false);
  for (int i = 0; i < n; ++i) fixed[(n / 2) * n + i] = true;
  s.assembler = std::make_unique<HessianAssembler>(
      s.mesh.vertex_count(), fixed, std::vector<const EnergyTerm*>{s.membrane.get(), s.bending.get()});
  Eigen::Matrix3Xd gradient = Eigen::Matrix3Xd::Zero(3, s.mesh.vertex_count());
  s.assembler->assemble(s.mesh.positions, HessianMode::kProjected, gradient);
  return s;
}

Eigen::MatrixXd dense(const HessianAssembler& a) {
  const int n = a.dof_count();
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    for (int p = a.column_pointers()[j]; p < a.column_pointers()[j + 1]; ++p) {
      m(a.row_indices()[p], j) = a.values()[p];
      m(j, a.row_indices()[p]) = a.values()[p];
    }
  }
  return m;
}

TEST(LinearAlgebra, ProductsAndSolvesMatchDenseAlgebra) {
  for (int n : {8, 20}) {  // CHOLMOD picks a simplicial factor for the small one, a supernodal for the larger
    const System s = make_system(n);
    const HessianAssembler& a = *s.assembler;
    const Eigen::MatrixXd m = dense(a);
    Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(a.dof_count(), -1.0, 2.0).array().sin();
    Eigen::VectorXd y;
    a.multiply(x, y, 0.25);
    EXPECT_LE((y - (m * x + 0.25 * x)).norm(), 1e-12 * y.norm()) << n;

    SparseCholesky cholesky;
    ASSERT_EQ(cholesky.factorize(a), FactorStatus::kOk) << n;
    Eigen::VectorXd exact, approximate;
    ASSERT_TRUE(cholesky.solve(y, exact));
    ASSERT_TRUE(cholesky.solve_approximate(y, approximate));
    const Eigen::VectorXd reference = m.ldlt().solve(y);
    std::printf("[ linalg   ] %d x %d: %d DOF, solve error %.2e, single-precision solve %.2e\n", n, n, a.dof_count(),
                (exact - reference).norm() / reference.norm(), (approximate - reference).norm() / reference.norm());
    EXPECT_LE((exact - reference).norm(), 1e-8 * reference.norm()) << n;
    // Single precision (the condition numbers here are 1e4-1e5): a preconditioner needs no more.
    EXPECT_LE((approximate - reference).norm(), 1e-4 * reference.norm()) << n;
    if (n == 20) {
      EXPECT_GT((approximate - exact).norm(), 0.0) << "expected the supernodal single-precision path";
    }
  }
}

// A factorisation that fails part way (an indefinite matrix) leaves no factor to solve with: both solves say so,
// where they solved with the partial factor before; the next successful one solves again. (The supernodal LL'
// factor; CHOLMOD's simplicial LDL' of the small system factorises an indefinite matrix without complaint.)
TEST(LinearAlgebra, NoSolveAfterAFailedFactorisation) {
  for (int n : {20, 30}) {
    const System s = make_system(n);
    const HessianAssembler& a = *s.assembler;
    const double mean_diagonal = dense(a).diagonal().mean();
    SparseCholesky cholesky;
    ASSERT_EQ(cholesky.factorize(a, -10.0 * mean_diagonal), FactorStatus::kNotPositiveDefinite) << n;
    const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(a.dof_count());
    Eigen::VectorXd x;
    EXPECT_FALSE(cholesky.solve(rhs, x)) << n;
    EXPECT_FALSE(cholesky.solve_approximate(rhs, x)) << n;
    ASSERT_EQ(cholesky.factorize(a), FactorStatus::kOk) << n;
    EXPECT_TRUE(cholesky.solve(rhs, x)) << n;
    EXPECT_TRUE(cholesky.solve_approximate(rhs, x)) << n;
  }
}

TEST(LinearAlgebra, CompactSolveOfALargeFactorPreconditionsConjugateGradients) {
  // 100 x 100 vertices: a factor of several million values, whose rows below the supernodes' diagonal blocks the
  // approximate solve keeps in bfloat16 (sparse_cholesky.cpp). Its error is a few per mille; as a preconditioner it
  // must still take conjugate gradients to round-off in a handful of iterations.
  const System s = make_system(100);
  const HessianAssembler& a = *s.assembler;
  SparseCholesky cholesky;
  ASSERT_EQ(cholesky.factorize(a), FactorStatus::kOk);
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(a.dof_count(), -1.0, 2.0).array().sin();
  Eigen::VectorXd b, exact, approximate;
  a.multiply(x, b, 0.0);
  ASSERT_TRUE(cholesky.solve(b, exact));
  ASSERT_TRUE(cholesky.solve_approximate(b, approximate));
  const double error = (approximate - exact).norm() / exact.norm();
  Eigen::VectorXd solution = Eigen::VectorXd::Zero(b.size()), r = b, z, p, ap;
  ASSERT_TRUE(cholesky.solve_approximate(r, z));
  p = z;
  double rz = r.dot(z);
  int iterations = 0;
  while (r.norm() > 1e-10 * b.norm() && iterations < 50) {
    a.multiply(p, ap, 0.0);
    const double step = rz / p.dot(ap);
    solution += step * p;
    r -= step * ap;
    ASSERT_TRUE(cholesky.solve_approximate(r, z));
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
    ++iterations;
  }
  std::printf("[ linalg   ] 100 x 100: %d DOF, exact solve error %.2e, approximate solve %.2e, preconditioned CG to "
              "1e-10 in %d iterations\n", a.dof_count(), (exact - x).norm() / x.norm(), error, iterations);
  EXPECT_LE(error, 2e-2);
  EXPECT_LE(iterations, 10);
  EXPECT_LE((solution - x).norm(), 1e-7 * x.norm());
}

TEST(LinearAlgebra, ConcurrentFactorisationsGiveTheSequentialResult) {
  // Two threads factorising and solving at once (diagnose --jobs 2) must get exactly what one thread gets: CHOLMOD's
  // BLAS calls (Debian's serial OpenBLAS is not thread-safe) are serialised by SparseCholesky.
  const System s = make_system(40);
  const HessianAssembler& a = *s.assembler;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(a.dof_count(), -1.0, 2.0).array().cos();
  Eigen::VectorXd reference;
  {
    SparseCholesky cholesky;
    ASSERT_EQ(cholesky.factorize(a), FactorStatus::kOk);
    ASSERT_TRUE(cholesky.solve(b, reference));
  }
  std::atomic<int> mismatches{0};
  auto work = [&] {
    for (int k = 0; k < 20; ++k) {
      SparseCholesky cholesky;
      Eigen::VectorXd x;
      if (cholesky.factorize(a) != FactorStatus::kOk || !cholesky.solve(b, x) || x != reference) ++mismatches;
    }
  };
  std::thread t1(work), t2(work);
  t1.join();
  t2.join();
  EXPECT_EQ(mismatches.load(), 0);
}

}  // namespace
}  // namespace drapegen::sim
