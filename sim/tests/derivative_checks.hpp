#pragma once
// Finite-difference checks shared by the derivative tests: a dense Hessian sink, gradient and Hessian against
// central differences, and PSD-ness of the projected Hessian.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

#include <random>

#include "drapegen/sim/energy.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sim {

class DenseSink final : public HessianSink {
 public:
  DenseSink(const EnergyTerm& term, int vertex_count, HessianMode mode)
      : term_(term), mode_(mode), h_(Eigen::MatrixXd::Zero(3 * vertex_count, 3 * vertex_count)) {}
  [[nodiscard]] HessianMode mode() const override { return mode_; }
  void add(int element, const double* local) override {
    const int n = term_.arity();
    std::vector<int> v(n);
    term_.element_vertices(element, v.data());
    const Eigen::Map<const Eigen::MatrixXd> m(local, 3 * n, 3 * n);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        if (v[a] >= 0 && v[b] >= 0) h_.block<3, 3>(3 * v[a], 3 * v[b]) += m.block<3, 3>(3 * a, 3 * b);
      }
  }
  [[nodiscard]] const Eigen::MatrixXd& matrix() const { return h_; }

 private:
  const EnergyTerm& term_;
  HessianMode mode_;
  Eigen::MatrixXd h_;
};

inline Eigen::VectorXd flat(const Eigen::Matrix3Xd& x) { return Eigen::Map<const Eigen::VectorXd>(x.data(), x.size()); }

/// Compares the analytic gradient with central differences of the energy, and the exact Hessian with central
/// differences of the gradient. Returns the Hessian for further checks.
inline Eigen::MatrixXd check_derivatives(const EnergyTerm& term, const Eigen::Matrix3Xd& x, double h, double tol) {
  const int nv = static_cast<int>(x.cols());
  Eigen::Matrix3Xd grad = Eigen::Matrix3Xd::Zero(3, nv);
  DenseSink sink(term, nv, HessianMode::kExact);
  const double e = term.evaluate(x, &grad, &sink);
  EXPECT_NEAR(e, term.energy(x), 1e-12 * std::max(1.0, std::abs(e)));
  const Eigen::VectorXd g = flat(grad);
  Eigen::VectorXd g_fd(g.size());
  Eigen::MatrixXd h_fd(g.size(), g.size());
  for (int i = 0; i < g.size(); ++i) {
    Eigen::Matrix3Xd xp = x, xm = x;
    xp.data()[i] += h;
    xm.data()[i] -= h;
    g_fd[i] = (term.energy(xp) - term.energy(xm)) / (2 * h);
    Eigen::Matrix3Xd gp = Eigen::Matrix3Xd::Zero(3, nv), gm = Eigen::Matrix3Xd::Zero(3, nv);
    term.evaluate(xp, &gp, nullptr);
    term.evaluate(xm, &gm, nullptr);
    h_fd.col(i) = (flat(gp) - flat(gm)) / (2 * h);
  }
  EXPECT_GT(g.norm(), 0.0) << term.name() << ": the configuration should be loaded";
  EXPECT_LE((g - g_fd).norm(), tol * g.norm()) << term.name() << " gradient";
  const Eigen::MatrixXd& hess = sink.matrix();
  EXPECT_GT(hess.norm(), 0.0);
  EXPECT_LE((hess - h_fd).norm(), tol * hess.norm()) << term.name() << " Hessian";
  EXPECT_LE((hess - hess.transpose()).norm(), 1e-12 * hess.norm());
  return hess;
}

inline void expect_projected_psd(const EnergyTerm& term, const Eigen::Matrix3Xd& x) {
  const int nv = static_cast<int>(x.cols());
  DenseSink sink(term, nv, HessianMode::kProjected);
  term.evaluate(x, nullptr, &sink);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(sink.matrix());
  EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-9 * std::max(1.0, eig.eigenvalues().maxCoeff())) << term.name();
}

/// A 20 mm specimen of 5 x 5 vertices, stretched (1.02 along x, 0.97 along y), bent into a saddle and jittered.
inline ClothMesh crumpled_mesh(std::uint64_t seed, double amplitude) {
  SpecimenSpec spec{0.02, 0.02, 5, 5, 0.25, Triangulation::kRandom, seed, 0.3};
  ClothMesh mesh = make_specimen(spec);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, amplitude);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const Eigen::Vector2d r = mesh.rest.col(v);
    mesh.positions.col(v) = Eigen::Vector3d(r.x() * 1.02, r.y() * 0.97, 30.0 * r.x() * r.x() - 20.0 * r.x() * r.y());
    for (int c = 0; c < 3; ++c) mesh.positions(c, v) += noise(rng);
  }
  return mesh;
}

}  // namespace drapegen::sim
