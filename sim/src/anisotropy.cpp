#include "drapegen/sim/anisotropy.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace drapegen::sim {
namespace {

/// The 1-ring least-squares system of one vertex in the unknowns [B11, B12, B22, g1, g2]: the 15 entries of the
/// upper triangle of the symmetric 5x5 matrix (row by row) followed by the 5 entries of the right-hand side.
constexpr int kSystemSize = 20;
/// The system with the tilt eliminated: the upper triangle of a symmetric 3x3 matrix (6) and its right side (3).
constexpr int kReducedSize = 9;
using ReducedSystem = Eigen::Matrix<double, kReducedSize, 1>;

/// Relative ridge added to the pooled normal equations: pulls unobserved tensor components towards zero.
constexpr double kRidge = 1e-10;

/// Throws unless the mesh and its topology describe the same vertices.
void check_inputs(const ClothMesh& mesh, const Topology& topo, const char* caller) {
  const auto n = static_cast<std::size_t>(mesh.vertex_count());
  if (mesh.positions.cols() != mesh.rest.cols() || topo.vertex_triangles.size() != n ||
      topo.vertex_neighbours.size() != n) {
    throw std::invalid_argument(std::string(caller) + ": mesh positions, rest coordinates and topology disagree");
  }
}

/// Area-weighted vertex normals (sum of the unnormalised normals of the incident triangles), normalised.
void compute_vertex_normals(const ClothMesh& mesh, Eigen::Matrix3Xd& normals) {
  normals.setZero(3, mesh.vertex_count());
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    const int a = mesh.triangles(0, t), b = mesh.triangles(1, t), c = mesh.triangles(2, t);
    const Eigen::Vector3d xa = mesh.positions.col(a);
    const Eigen::Vector3d n = (mesh.positions.col(b) - xa).cross(mesh.positions.col(c) - xa);
    normals.col(a) += n;
    normals.col(b) += n;
    normals.col(c) += n;
  }
  for (int i = 0; i < normals.cols(); ++i) {
    const double norm = normals.col(i).norm();
    if (norm > 0.0) normals.col(i) /= norm;
  }
}

/// Rest area of the triangle (a, b, c).
double rest_area(const ClothMesh& mesh, int a, int b, int c) {
  const Eigen::Vector2d e1 = mesh.rest.col(b) - mesh.rest.col(a), e2 = mesh.rest.col(c) - mesh.rest.col(a);
  return 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
}

/// Adds the samples of edge (a, b) to the systems of both of its vertices. At vertex i with neighbour j the normal
/// curvature 2 (x_j - x_i).n_i / |x_j - x_i|^2 is modelled as D^T B D + 2 g.(X_j - X_i) / |x_j - x_i|^2, with D the
/// unit rest direction from i to j and g the unknown tilt of the estimated normal n_i (an error e of the normal
/// changes (x_j - x_i).n_i by e.F (X_j - X_i), linear in the rest edge: g = F^T e). Reversing the edge leaves the
/// row's tensor part unchanged and negates its tilt part.
void add_edge_samples(const ClothMesh& mesh, const Eigen::Matrix3Xd& normals, int a, int b, double weight,
                      Eigen::Matrix<double, kSystemSize, Eigen::Dynamic>& systems) {
  const Eigen::Vector2d rest_edge = mesh.rest.col(b) - mesh.rest.col(a);
  const Eigen::Vector3d edge = mesh.positions.col(b) - mesh.positions.col(a);
  const double rest_length = rest_edge.norm();
  const double length_sq = edge.squaredNorm();
  if (!(rest_length > 0.0) || !(length_sq > 0.0)) return;  // degenerate edge: no usable sample
  const Eigen::Vector2d d = rest_edge / rest_length;
  const double two_inv_length_sq = 2.0 / length_sq;
  const double row[5] = {d.x() * d.x(), 2.0 * d.x() * d.y(), d.y() * d.y(), two_inv_length_sq * rest_edge.x(),
                         two_inv_length_sq * rest_edge.y()};
  const double kappa_a = two_inv_length_sq * edge.dot(normals.col(a));
  const double kappa_b = -two_inv_length_sq * edge.dot(normals.col(b));
  double* sa = systems.col(a).data();
  double* sb = systems.col(b).data();
  int k = 0;
  for (int r = 0; r < 5; ++r) {
    for (int c = r; c < 5; ++c, ++k) {
      const double v = weight * row[r] * row[c];
      sa[k] += v;
      sb[k] += (r < 3 && c >= 3) ? -v : v;  // tensor-tilt coupling changes sign with D
    }
  }
  for (int r = 0; r < 5; ++r) {
    sa[15 + r] += weight * kappa_a * row[r];
    sb[15 + r] += weight * kappa_b * (r < 3 ? row[r] : -row[r]);
  }
}

/// Accumulates the 1-ring systems of all vertices in one pass over the edges. Each edge is weighted by half the
/// rest area of its adjacent triangles (the share of the vertex area it represents).
void accumulate_systems(const ClothMesh& mesh, const Topology& topo, const Eigen::Matrix3Xd& normals,
                        Eigen::Matrix<double, kSystemSize, Eigen::Dynamic>& systems) {
  systems.setZero(kSystemSize, mesh.vertex_count());
  for (const Hinge& h : topo.hinges) {
    const double weight = 0.5 * (rest_area(mesh, h.v0, h.v1, h.v2) + rest_area(mesh, h.v1, h.v0, h.v3));
    add_edge_samples(mesh, normals, h.v0, h.v1, weight, systems);
  }
  for (const Eigen::Vector2i& e : topo.boundary_edges) {
    double area = 0.0;
    for (const int t : topo.vertex_triangles[e[0]]) {  // the single triangle holding the boundary edge
      const int a = mesh.triangles(0, t), b = mesh.triangles(1, t), c = mesh.triangles(2, t);
      if (a == e[1] || b == e[1] || c == e[1]) {
        area = rest_area(mesh, a, b, c);
        break;
      }
    }
    add_edge_samples(mesh, normals, e[0], e[1], 0.5 * area, systems);
  }
}

/// Eliminates the tilt from a 1-ring system (Schur complement), keeping only the information about B that does
/// not depend on the vertex normal. A vertex with fewer than two independent edge directions contributes nothing.
ReducedSystem reduce_tilt(const double* s) {
  ReducedSystem reduced = ReducedSystem::Zero();
  // Upper-triangle layout: row 0 -> 0..4, row 1 -> 5..8, row 2 -> 9..11, row 3 -> 12..13, row 4 -> 14.
  const double t00 = s[12], t01 = s[13], t11 = s[14];
  const double det = t00 * t11 - t01 * t01;
  const double trace = t00 + t11;
  if (!(det > 1e-12 * trace * trace)) return reduced;
  Eigen::Matrix<double, 3, 2> coupling;
  coupling << s[3], s[4], s[7], s[8], s[10], s[11];
  Eigen::Matrix2d tilt_inv;
  tilt_inv << t11, -t01, -t01, t00;
  tilt_inv /= det;
  const Eigen::Matrix<double, 3, 2> k = coupling * tilt_inv;
  Eigen::Matrix3d m;
  m << s[0], s[1], s[2], s[1], s[5], s[6], s[2], s[6], s[9];
  m.noalias() -= k * coupling.transpose();
  const Eigen::Vector3d r = Eigen::Vector3d(s[15], s[16], s[17]) - k * Eigen::Vector2d(s[18], s[19]);
  reduced << m(0, 0), m(0, 1), m(0, 2), m(1, 1), m(1, 2), m(2, 2), r;
  return reduced;
}

/// Solves the pooled reduced normal equations for the tensor B = [[B11, B12], [B12, B22]] (closed-form 3x3 solve of
/// the ridge-regularised symmetric positive definite system).
Eigen::Matrix2d solve_tensor(const ReducedSystem& m) {
  const double ridge = kRidge * (m(0) + m(3) + m(5));
  if (!(ridge > 0.0)) return Eigen::Matrix2d::Zero();
  const double a = m(0) + ridge, b = m(1), c = m(2), d = m(3) + ridge, e = m(4), f = m(5) + ridge;
  const double c00 = d * f - e * e, c01 = c * e - b * f, c02 = b * e - c * d;
  const double c11 = a * f - c * c, c12 = b * c - a * e, c22 = a * d - b * b;
  const double det = a * c00 + b * c01 + c * c02;
  if (!(det > 0.0)) return Eigen::Matrix2d::Zero();
  const double r0 = m(6), r1 = m(7), r2 = m(8);
  const double b11 = (c00 * r0 + c01 * r1 + c02 * r2) / det;
  const double b12 = (c01 * r0 + c11 * r1 + c12 * r2) / det;
  const double b22 = (c02 * r0 + c12 * r1 + c22 * r2) / det;
  Eigen::Matrix2d tensor;
  tensor << b11, b12, b12, b22;
  return tensor;
}

/// Writes the principal curvatures of the symmetric tensor b (closed form, no trigonometry) into column i.
void store_principal(const Eigen::Matrix2d& b, int i, CurvatureField& field) {
  const double mean = 0.5 * (b(0, 0) + b(1, 1));
  const double p = 0.5 * (b(0, 0) - b(1, 1)), q = b(0, 1);
  const double radius = std::sqrt(p * p + q * q);
  // Eigenvector of the larger eigenvalue mean + radius at angle theta with (cos 2 theta, sin 2 theta) = (p, q)/radius.
  Eigen::Vector2d upper(1.0, 0.0);
  if (radius > 0.0) {
    const double cos2 = p / radius;
    upper = Eigen::Vector2d(std::sqrt(std::max(0.0, 0.5 * (1.0 + cos2))),
                            std::copysign(std::sqrt(std::max(0.0, 0.5 * (1.0 - cos2))), q));
  }
  if (mean >= 0.0) {  // mean + radius has the larger magnitude
    field.direction.col(i) = upper;
    field.max_curvature[i] = mean + radius;
    field.min_curvature[i] = mean - radius;
  } else {
    field.direction.col(i) = Eigen::Vector2d(-upper.y(), upper.x());
    field.max_curvature[i] = mean - radius;
    field.min_curvature[i] = mean + radius;
  }
}

/// Confidence in the greater principal direction of vertex i: the gap between the principal magnitudes (1/m).
double anisotropy(const CurvatureField& field, int i) {
  return std::abs(field.max_curvature[i]) - std::abs(field.min_curvature[i]);
}

/// C1 ramp from 0 (x <= 0) to 1 (x >= 1).
double smoothstep(double x) {
  const double s = std::clamp(x, 0.0, 1.0);
  return s * s * (3.0 - 2.0 * s);
}

/// Rest direction perpendicular to the hinge edge (not normalised): the bending direction of the edge rule.
Eigen::Vector2d edge_bending_direction(const ClothMesh& mesh, const Hinge& h) {
  const Eigen::Vector2d e = mesh.rest.col(h.v1) - mesh.rest.col(h.v0);
  return Eigen::Vector2d(-e.y(), e.x());
}

/// Curvature-rule direction of a hinge: anisotropy-weighted mean of the aligned greater principal directions at
/// v0 and v1, blended into the edge direction where the mean anisotropy is below flat_curvature.
Eigen::Vector2d curvature_bending_direction(const ClothMesh& mesh, const Hinge& h, const CurvatureField& field,
                                            double flat_curvature) {
  const double w0 = anisotropy(field, h.v0), w1 = anisotropy(field, h.v1);
  const Eigen::Vector2d d0 = field.direction.col(h.v0);
  Eigen::Vector2d d1 = field.direction.col(h.v1);
  if (d0.dot(d1) < 0.0) d1 = -d1;  // directions are axes
  const Eigen::Vector2d mean_dir = w0 * d0 + w1 * d1;
  const double mean_norm = mean_dir.norm();
  if (!(mean_norm > 0.0)) return edge_bending_direction(mesh, h);
  const Eigen::Vector2d curvature_dir = mean_dir / mean_norm;
  const double t = flat_curvature > 0.0 ? smoothstep(0.5 * (w0 + w1) / flat_curvature) : 1.0;
  if (t >= 1.0) return curvature_dir;
  Eigen::Vector2d edge_dir = edge_bending_direction(mesh, h).normalized();
  if (edge_dir.dot(curvature_dir) < 0.0) edge_dir = -edge_dir;
  return t * curvature_dir + (1.0 - t) * edge_dir;
}

/// Measures rest-frame directions from the warp direction.
class WarpFrame {
 public:
  explicit WarpFrame(double material_angle) : cos_(std::cos(material_angle)), sin_(std::sin(material_angle)) {}

  /// Angle of the axis of d (any length, nonzero) from the warp direction, in [0, pi).
  [[nodiscard]] double angle(const Eigen::Vector2d& d) const {
    double u = cos_ * d.x() + sin_ * d.y(), v = cos_ * d.y() - sin_ * d.x();
    if (v < 0.0 || (v == 0.0 && u < 0.0)) {  // d and -d are the same axis: take the one in the upper half plane
      u = -u;
      v = -v;
    }
    const double phi = std::atan2(v, u) + 0.0;  // + 0.0 turns -0.0 into 0.0
    return phi < std::numbers::pi ? phi : 0.0;   // atan2 rounds to pi for v -> +0 with u < 0
  }

 private:
  double cos_, sin_;
};

}  // namespace

double interpolate_directional(const DirectionalValues& k, double phi) {
  // Eq. 8 depends on phi only through c = cos^2 phi, which already has the symmetries k(phi) = k(-phi) =
  // k(pi - phi) = k(pi + phi); c >= 1/2 is the segment [0, pi/4] and c <= 1/2 the segment [pi/4, pi/2].
  const double c = 0.5 * (1.0 + std::cos(2.0 * phi));
  const double s = 1.0 - c;
  if (c >= 0.5) {
    // Samples warp (c = 1) and bias (c = 1/2): M^-1 = [[1, 0], [-1, 2]], so k = c warp + s (2 bias - warp).
    return (c - s) * k.warp + 2.0 * s * k.bias;
  }
  // Samples bias (c = 1/2) and weft (c = 0): M^-1 = [[2, -1], [0, 1]], so k = c (2 bias - weft) + s weft.
  return 2.0 * c * k.bias + (s - c) * k.weft;
}

void principal_curvatures(const ClothMesh& mesh, const Topology& topo, CurvatureWorkspace& workspace,
                          CurvatureField& field) {
  check_inputs(mesh, topo, "principal_curvatures");
  const int n = mesh.vertex_count();
  compute_vertex_normals(mesh, workspace.vertex_normals);
  accumulate_systems(mesh, topo, workspace.vertex_normals, workspace.systems);
  workspace.reduced.resize(kReducedSize, n);
  for (int i = 0; i < n; ++i) workspace.reduced.col(i) = reduce_tilt(workspace.systems.col(i).data());

  field.direction.resize(2, n);
  field.max_curvature.resize(n);
  field.min_curvature.resize(n);
  for (int i = 0; i < n; ++i) {
    ReducedSystem pooled = workspace.reduced.col(i);
    for (const int j : topo.vertex_neighbours[i]) pooled += workspace.reduced.col(j);
    store_principal(solve_tensor(pooled), i, field);
  }
}

CurvatureField principal_curvatures(const ClothMesh& mesh, const Topology& topo) {
  CurvatureWorkspace workspace;
  CurvatureField field;
  principal_curvatures(mesh, topo, workspace, field);
  return field;
}

void hinge_bending_angles(const ClothMesh& mesh, const Topology& topo, AnisotropyRule rule,
                          const AnisotropyOptions& options, AnisotropyWorkspace& workspace,
                          Eigen::VectorXd& phi_out) {
  check_inputs(mesh, topo, "hinge_bending_angles");
  const int count = static_cast<int>(topo.hinges.size());
  const WarpFrame warp(mesh.material_angle);
  phi_out.resize(count);
  if (rule == AnisotropyRule::kEdge) {
    for (int h = 0; h < count; ++h) phi_out[h] = warp.angle(edge_bending_direction(mesh, topo.hinges[h]));
    return;
  }
  principal_curvatures(mesh, topo, workspace.curvature, workspace.field);
  for (int h = 0; h < count; ++h) {
    phi_out[h] =
        warp.angle(curvature_bending_direction(mesh, topo.hinges[h], workspace.field, options.flat_curvature));
  }
}

void hinge_bending_angles(const ClothMesh& mesh, const Topology& topo, AnisotropyRule rule,
                          Eigen::VectorXd& phi_out) {
  AnisotropyWorkspace workspace;
  hinge_bending_angles(mesh, topo, rule, AnisotropyOptions{}, workspace, phi_out);
}

}  // namespace drapegen::sim
