#include "drapegen/sim/triangle_bending.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <stdexcept>

#include "drapegen/sim/dihedral.hpp"
#include "drapegen/sim/psd_projection.hpp"

namespace drapegen::sim {

TriangleCurvatureBending::TriangleCurvatureBending(const ClothMesh& mesh, const Topology& topology,
                                                   const DihedralModuli& moduli, AnisotropyRule rule)
    : mesh_(&mesh), topology_(&topology), moduli_(moduli), rule_(rule) {
  for (const DirectionalValues* v : {&moduli.alpha, &moduli.beta}) {
    for (double k : {v->warp, v->bias, v->weft}) {
      if (!std::isfinite(k)) throw std::invalid_argument("triangle bending: moduli must be finite");
    }
  }
  if (!(moduli.alpha.warp > 0.0 && moduli.alpha.bias > 0.0 && moduli.alpha.weft > 0.0)) {
    throw std::invalid_argument("triangle bending: alpha must be positive");
  }
  if (rule == AnisotropyRule::kEdge && !moduli.isotropic()) {
    throw std::invalid_argument("triangle bending: the edge rule belongs to the hinge model");
  }
  std::map<std::pair<int, int>, int> hinge_of;
  for (std::size_t h = 0; h < topology.hinges.size(); ++h) {
    const Hinge& g = topology.hinges[h];
    hinge_of[{std::min(g.v0, g.v1), std::max(g.v0, g.v1)}] = static_cast<int>(h);
  }
  const Eigen::Vector2d warp(std::cos(mesh.material_angle), std::sin(mesh.material_angle));
  for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) {
    const int tri[3] = {mesh.triangles(0, t), mesh.triangles(1, t), mesh.triangles(2, t)};
    Element e{};
    for (int i = 0; i < 3; ++i) e.vertices[i] = tri[i];
    for (int i = 3; i < 6; ++i) e.vertices[i] = -1;
    const Eigen::Vector2d centre = (mesh.rest.col(tri[0]) + mesh.rest.col(tri[1]) + mesh.rest.col(tri[2])) / 3.0;
    e.constraint.setZero();
    for (int edge = 0; edge < 3; ++edge) {
      const int a = tri[(edge + 1) % 3], b = tri[(edge + 2) % 3];
      const auto it = hinge_of.find({std::min(a, b), std::max(a, b)});
      if (it == hinge_of.end()) continue;  // a free edge
      const Hinge& g = topology.hinges[static_cast<std::size_t>(it->second)];
      // Around an interior vertex of valence 3 two hinges of a triangle have the same wing, so both angles are of the
      // same four vertices, whose heights have one bending mode: the second angle measures what the first does (the
      // system would be singular). It is left out, as a free edge is; the other triangles measure it all the same.
      const int wing = g.v2 == tri[edge] ? g.v3 : g.v2;
      bool measured = false;
      for (int j = 0; j < e.hinge_count; ++j) measured = measured || e.vertices[3 + j] == wing;
      if (measured) continue;
      const int i = e.hinge_count++;
      e.hinge[i] = g;
      const int* hv = &g.v0;
      for (int k = 0; k < 4; ++k) {
        int slot = 3 + i;  // the wing
        for (int s = 0; s < 3; ++s) slot = hv[k] == tri[s] ? s : slot;
        e.slot[i][k] = slot;
        if (slot == 3 + i) e.vertices[3 + i] = hv[k];
      }
      // The angles of the surface z = amplitude * q^T K q / 2 (q from the centroid) for the three unit tensors; at
      // this amplitude (angles ~1e-5) the map is linear to ~1e-10.
      const double amplitude = 1e-3;
      for (int j = 0; j < 3; ++j) {
        Eigen::Vector3d p[4];
        for (int k = 0; k < 4; ++k) {
          const Eigen::Vector2d q = mesh.rest.col(hv[k]) - centre;
          const double z = j == 0 ? 0.5 * q.x() * q.x() : j == 1 ? q.x() * q.y() : 0.5 * q.y() * q.y();
          p[k] = Eigen::Vector3d(q.x(), q.y(), amplitude * z);
        }
        e.constraint(i, j) = dihedral_angle(p[0], p[1], p[2], p[3]) / amplitude;
      }
    }
    if (e.hinge_count == 0) continue;  // a lone triangle: nothing to bend
    if (e.hinge_count == 3) {
      const Eigen::FullPivLU<Eigen::Matrix3d> lu(e.constraint);
      if (!lu.isInvertible() || !(lu.rcond() > 1e-8)) {
        throw std::invalid_argument("triangle bending: degenerate curvature system");
      }
      e.to_tensor = lu.inverse();
    }
    const Eigen::Vector2d u = mesh.rest.col(tri[1]) - mesh.rest.col(tri[0]),
                          w = mesh.rest.col(tri[2]) - mesh.rest.col(tri[0]);
    e.area = 0.5 * std::abs(u.x() * w.y() - u.y() * w.x());
    assign(e, warp);
    elements_.push_back(e);
  }
}

double TriangleCurvatureBending::assign(Element& e, const Eigen::Vector2d& d) const {
  const Eigen::Vector2d p(-d.y(), d.x());
  const TorqueLaw old = e.along;
  if (moduli_.isotropic()) {
    e.along = e.across = TorqueLaw{moduli_.alpha.warp, moduli_.beta.warp};
  } else {
    const double c = std::cos(mesh_->material_angle), s = std::sin(mesh_->material_angle);
    const double phi = std::atan2(d.y() * c - d.x() * s, d.x() * c + d.y() * s);  // from the warp direction
    const double floor = 1e-3 * std::min({moduli_.alpha.warp, moduli_.alpha.bias, moduli_.alpha.weft});
    auto law = [&](double angle) {
      return TorqueLaw{std::max(interpolate_directional(moduli_.alpha, angle), floor),
                       interpolate_directional(moduli_.beta, angle)};
    };
    e.along = law(phi);
    e.across = law(phi + 0.5 * std::acos(-1.0));
  }
  e.twist = 0.5 * (e.along.alpha + e.across.alpha);
  // kappa = a^T K a = (a_x^2, 2 a_x a_y, a_y^2) . (K_xx, K_xy, K_yy); twist d^T K p likewise.
  const Eigen::RowVector3d along(d.x() * d.x(), 2.0 * d.x() * d.y(), d.y() * d.y());
  const Eigen::RowVector3d across(p.x() * p.x(), 2.0 * p.x() * p.y(), p.y() * p.y());
  const Eigen::RowVector3d twist(d.x() * p.x(), d.x() * p.y() + d.y() * p.x(), d.y() * p.y());
  if (e.hinge_count < 3) {
    // A border triangle measures only some components of K: the rest takes the value of least linear bending
    // energy 1/2 k^T A k under the measured angles, B k = theta (the free edge's natural boundary condition, zero
    // moment across it, for the linear part of the laws): k = A^-1 B^T (B A^-1 B^T)^-1 theta.
    const Eigen::Matrix3d stiffness = e.along.alpha * along.transpose() * along +
                                      e.across.alpha * across.transpose() * across +
                                      2.0 * e.twist * twist.transpose() * twist;
    const int m = e.hinge_count;
    const Eigen::MatrixXd b = e.constraint.topRows(m);
    const Eigen::MatrixXd a_inv_bt = stiffness.ldlt().solve(b.transpose());  // 3 x m
    e.to_tensor.setZero();
    e.to_tensor.leftCols(m) = a_inv_bt * (b * a_inv_bt).inverse();
  }
  e.measure.row(0) = along * e.to_tensor;
  e.measure.row(1) = across * e.to_tensor;
  e.measure.row(2) = twist * e.to_tensor;
  if (!(old.alpha > 0.0)) return 0.0;
  return std::max(std::abs(e.along.alpha - old.alpha) / old.alpha,
                  std::abs(e.along.beta - old.beta) / std::max(std::abs(old.beta), old.alpha * std::sqrt(e.area)));
}

double TriangleCurvatureBending::update_lagged(const Eigen::Matrix3Xd& x) {
  if (moduli_.isotropic()) return 0.0;
  ClothMesh current = *mesh_;  // the curvature estimate reads positions from a mesh
  current.positions = x;
  principal_curvatures(current, *topology_, workspace_.curvature, workspace_.field);
  const CurvatureField& field = workspace_.field;
  double change = 0.0;
  for (Element& e : elements_) {
    // Mean of the vertices' greater principal directions, signs aligned, weighted by their anisotropy.
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    const Eigen::Vector2d first = field.direction.col(e.vertices[0]);
    for (int k = 0; k < 3; ++k) {
      const int v = e.vertices[k];
      const double weight = std::abs(field.max_curvature[v]) - std::abs(field.min_curvature[v]) + 1e-9;
      const Eigen::Vector2d dv = field.direction.col(v);
      sum += weight * (dv.dot(first) < 0.0 ? -dv : dv);
    }
    if (!(sum.norm() > 0.0) || !sum.allFinite()) continue;
    const double delta = assign(e, sum.normalized());
    change = std::max(change, std::min(delta, 1.0));
  }
  return change;
}

void TriangleCurvatureBending::element_vertices(int element, int* out) const {
  for (int k = 0; k < 6; ++k) out[k] = elements_[static_cast<std::size_t>(element)].vertices[k];
}

double TriangleCurvatureBending::evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient,
                                          HessianSink* hessian) const {
  using Matrix18d = Eigen::Matrix<double, 18, 18>;
  double total = 0.0;
  Vector12d g;
  Matrix12d h2[3];
  Eigen::Matrix<double, 18, 3> jacobian;  // d theta_i / d x
  Matrix18d element;
  const bool exact = hessian != nullptr && hessian->mode() == HessianMode::kExact;
  // The angles' own second derivatives (torque x Hessian of theta_i): exact, or per hinge projected to positive
  // semi-definite (kProjected); the Gauss-Newton mode leaves them out.
  const bool angle_hessians = hessian != nullptr && hessian->mode() != HessianMode::kGaussNewton;
  for (std::size_t t = 0; t < elements_.size(); ++t) {
    const Element& e = elements_[t];
    Eigen::Vector3d theta;
    jacobian.setZero();
    theta.setZero();
    for (int i = 0; i < e.hinge_count; ++i) {
      const Hinge& h = e.hinge[i];
      const bool need_gradient = gradient != nullptr || hessian != nullptr;
      theta(i) = angle_hessians ? dihedral_angle_hessian(x.col(h.v0), x.col(h.v1), x.col(h.v2), x.col(h.v3), g, h2[i])
                 : need_gradient ? dihedral_angle_gradient(x.col(h.v0), x.col(h.v1), x.col(h.v2), x.col(h.v3), g)
                                 : dihedral_angle(x.col(h.v0), x.col(h.v1), x.col(h.v2), x.col(h.v3));
      if (!need_gradient) continue;
      for (int k = 0; k < 4; ++k) jacobian.block<3, 1>(3 * e.slot[i][k], i) += g.segment<3>(3 * k);
    }
    const Eigen::Vector3d kappa = e.measure * theta;  // along, across, twist
    const double k0 = std::abs(kappa(0)), k1 = std::abs(kappa(1));
    total += e.area * (e.along.work(k0) + e.across.work(k1) + e.twist * kappa(2) * kappa(2));
    if (gradient == nullptr && hessian == nullptr) continue;
    const Eigen::Vector3d moment(std::copysign(e.along.torque(k0), kappa(0)),
                                 std::copysign(e.across.torque(k1), kappa(1)), 2.0 * e.twist * kappa(2));
    const Eigen::Vector3d torque = e.area * e.measure.transpose() * moment;  // dE / dtheta
    if (gradient != nullptr) {
      const Eigen::Matrix<double, 18, 1> ge = jacobian * torque;
      for (int k = 0; k < 6; ++k) {
        if (e.vertices[k] >= 0) gradient->col(e.vertices[k]) += ge.segment<3>(3 * k);
      }
    }
    if (hessian == nullptr) continue;
    const Eigen::Vector3d stiffness(e.along.stiffness(k0), e.across.stiffness(k1), 2.0 * e.twist);
    const Eigen::Matrix3d d2e = e.area * e.measure.transpose() * stiffness.asDiagonal() * e.measure;  // PSD
    element.noalias() = jacobian * d2e * jacobian.transpose();
    if (angle_hessians) {
      for (int i = 0; i < e.hinge_count; ++i) {
        Matrix12d term = torque(i) * h2[i];
        if (!exact) project_to_psd<12>(term);
        for (int a = 0; a < 4; ++a) {
          for (int c = 0; c < 4; ++c) {
            element.block<3, 3>(3 * e.slot[i][a], 3 * e.slot[i][c]) += term.block<3, 3>(3 * a, 3 * c);
          }
        }
      }
    }
    hessian->add(static_cast<int>(t), element.data());
  }
  return total;
}

}  // namespace drapegen::sim
