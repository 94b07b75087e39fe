#include "drapegen/sim/bending.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "drapegen/sim/dihedral.hpp"
#include "drapegen/sim/fold_barrier.hpp"
#include "drapegen/sim/psd_projection.hpp"

namespace drapegen::sim {

double TorqueLaw::peak_curvature() const {
  return beta < 0.0 ? alpha / (-2.0 * beta) : std::numeric_limits<double>::infinity();
}

double TorqueLaw::torque(double kappa) const {
  const double k = std::min(kappa, peak_curvature());
  return alpha * k + beta * k * k;
}

double TorqueLaw::stiffness(double kappa) const {
  return kappa < peak_curvature() ? alpha + 2.0 * beta * kappa : 0.0;
}

double TorqueLaw::work(double kappa) const {
  const double peak = peak_curvature();
  const double k = std::min(kappa, peak);
  double w = 0.5 * alpha * k * k + beta * k * k * k / 3.0;
  if (kappa > peak) w += torque(peak) * (kappa - peak);
  return w;
}

std::vector<HingeRest> hinge_rest_geometry(const ClothMesh& mesh, const Topology& topology) {
  std::vector<HingeRest> rest;
  rest.reserve(topology.hinges.size());
  auto cross2 = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); };
  for (const Hinge& h : topology.hinges) {
    const Eigen::Vector2d e = mesh.rest.col(h.v1) - mesh.rest.col(h.v0);
    const double len = e.norm();
    const double ha = std::abs(cross2(e, mesh.rest.col(h.v2) - mesh.rest.col(h.v0))) / len;
    const double hb = std::abs(cross2(e, mesh.rest.col(h.v3) - mesh.rest.col(h.v0))) / len;
    if (!(len > 0.0 && ha > 0.0 && hb > 0.0)) throw std::invalid_argument("bending: degenerate rest hinge");
    rest.push_back(HingeRest{len, ha + hb});
  }
  return rest;
}

bool DihedralModuli::isotropic() const {
  return alpha.warp == alpha.bias && alpha.bias == alpha.weft && beta.warp == beta.bias && beta.bias == beta.weft;
}

namespace {

double hinge_angle(const Eigen::Matrix3Xd& x, const Hinge& h) {
  return dihedral_angle(x.col(h.v0), x.col(h.v1), x.col(h.v2), x.col(h.v3));
}

void validate_directional(const DirectionalValues& v, const char* what, bool positive) {
  for (double x : {v.warp, v.bias, v.weft}) {
    if (!std::isfinite(x) || (positive && !(x > 0.0))) {
      throw std::invalid_argument(std::string("bending: ") + what + (positive ? " must be positive and finite"
                                                                                : " must be finite"));
    }
  }
}

/// Eq. 8 can extrapolate a modulus below zero between sample directions for extreme anisotropy; keep a floor.
double floored(double value, const DirectionalValues& v) {
  const double floor = 1e-3 * std::min({v.warp, v.bias, v.weft});
  return std::max(value, floor);
}

}  // namespace

DihedralBending::DihedralBending(const ClothMesh& mesh, const Topology& topology, const DihedralModuli& moduli,
                                 AnisotropyRule rule)
    : mesh_(&mesh), topology_(&topology), hinges_(topology.hinges), rest_(hinge_rest_geometry(mesh, topology)),
      moduli_(moduli), rule_(rule) {
  validate_directional(moduli.alpha, "alpha", true);
  validate_directional(moduli.beta, "beta", false);
  phi_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(hinges_.size()));
  rest_angle_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(hinges_.size()));
  if (!moduli_.isotropic()) hinge_bending_angles(mesh, topology, AnisotropyRule::kEdge, phi_);
  assign_laws();
}

void DihedralBending::set_rest_angles(const Eigen::VectorXd& angles) {
  // Within (-pi, pi), where a hinge's angle lives: plastic flow can set a hinge folded against the fold barrier
  // (fold_barrier.hpp) close to pi, and that set is carried to the specimen's next drape.
  if (angles.size() != rest_angle_.size() || !angles.allFinite() ||
      (angles.size() > 0 && angles.cwiseAbs().maxCoeff() >= std::numbers::pi)) {
    throw std::invalid_argument("bending: one finite rest angle within (-pi, pi) per hinge expected");
  }
  rest_angle_ = angles;
}

void DihedralBending::set_yield_curvature(double yield_curvature) {
  if (!(yield_curvature > 0.0)) throw std::invalid_argument("bending: the yield curvature must be positive");
  yield_curvature_ = yield_curvature;
}

void DihedralBending::element_vertices(int element, int* out) const {
  const Hinge& h = hinges_[element];
  out[0] = h.v0;
  out[1] = h.v1;
  out[2] = h.v2;
  out[3] = h.v3;
}

double DihedralBending::assign_laws() {
  laws_.resize(hinges_.size());
  double change = 0.0;
  for (std::size_t i = 0; i < hinges_.size(); ++i) {
    TorqueLaw law{moduli_.alpha.warp, moduli_.beta.warp};
    if (!moduli_.isotropic()) {
      law = TorqueLaw{floored(interpolate_directional(moduli_.alpha, phi_[i]), moduli_.alpha),
                      interpolate_directional(moduli_.beta, phi_[i])};
    }
    const TorqueLaw& old = laws_[i];
    if (old.alpha > 0.0) {
      // beta relative to its effect at the hinge's own curvature scale 1/(H0+H1), compared with alpha.
      const double beta_scale = std::max(std::abs(old.beta), old.alpha * rest_[i].height_sum);
      change = std::max({change, std::abs(law.alpha - old.alpha) / old.alpha,
                         std::abs(law.beta - old.beta) / beta_scale});
    }
    laws_[i] = law;
  }
  return change;
}

double DihedralBending::update_lagged(const Eigen::Matrix3Xd& x) {
  double change = 0.0;
  if (!moduli_.isotropic() && rule_ == AnisotropyRule::kCurvature) {
    ClothMesh current = *mesh_;  // the anisotropy rule reads positions from a mesh
    current.positions = x;
    hinge_bending_angles(current, *topology_, rule_, phi_);
    change = assign_laws();
  }
  return change;
}

double DihedralBending::update_history(const Eigen::Matrix3Xd& x) {
  double change = 0.0;
  if (std::isfinite(yield_curvature_)) {
    // Return mapping: the elastic angle |theta - rest| may not exceed the one whose torque is the yield torque,
    // i.e. min(yield curvature, the law's peak) / c. The change is measured against the hinge's yield angle.
    for (std::size_t i = 0; i < hinges_.size(); ++i) {
      const Hinge& h = hinges_[i];
      const double c = 2.0 / rest_[i].height_sum;
      const double limit = std::min(yield_curvature_, laws_[i].peak_curvature()) / c;
      const double theta = hinge_angle(x, h);
      const double elastic = theta - rest_angle_[i];
      if (std::abs(elastic) <= limit) continue;
      const double flow = elastic - std::copysign(limit, elastic);
      rest_angle_[i] += flow;
      change = std::max(change, std::abs(flow) / limit);
    }
  }
  return change;
}

namespace {

/// Whether a hinge whose angle is `after` at the end of a step folded through the wrap at +-pi on the way from
/// `from`: its angle jumped by more than pi, the short way round being through the wrap (2.5 to -1.4, say),
/// wherever it lands relative to the barrier. Steps of less than pi are assumed, so a hinge that swings by more than
/// pi through flat (from -1.7 to 1.7, say) is ruled out as well: that only shortens the step.
bool wrapped(double after, const Eigen::Matrix3Xd& from, const Hinge& h) {
  return std::abs(after - hinge_angle(from, h)) > std::numbers::pi;
}

}  // namespace

bool DihedralBending::admissible_step(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) const {
  return std::none_of(hinges_.begin(), hinges_.end(),
                      [&](const Hinge& h) { return wrapped(hinge_angle(to, h), from, h); });
}

double DihedralBending::hinge_energy(std::size_t i, double angle) const {
  const double theta = angle - rest_angle_[i];
  const double c = 2.0 / rest_[i].height_sum;
  const double e = rest_[i].edge_length;
  return e / c * laws_[i].work(c * std::abs(theta)) + FoldBarrier::energy(angle, e * c * laws_[i].alpha);
}

double DihedralBending::energy(const Eigen::Matrix3Xd& x) const {
  double total = 0.0;
  for (std::size_t i = 0; i < hinges_.size(); ++i) total += hinge_energy(i, hinge_angle(x, hinges_[i]));
  return total;
}

double DihedralBending::step_energy(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) const {
  double total = 0.0;
  for (std::size_t i = 0; i < hinges_.size(); ++i) {
    const double angle = hinge_angle(to, hinges_[i]);
    if (wrapped(angle, from, hinges_[i])) return std::numeric_limits<double>::infinity();
    total += hinge_energy(i, angle);
  }
  return total;
}

double DihedralBending::evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient,
                                 HessianSink* hessian) const {
  double total = 0.0;
  Vector12d g;
  Matrix12d h2;
  Matrix12d element;
  const bool exact_second = hessian != nullptr && hessian->mode() != HessianMode::kGaussNewton;
  for (std::size_t i = 0; i < hinges_.size(); ++i) {
    const Hinge& h = hinges_[i];
    const double c = 2.0 / rest_[i].height_sum;
    const double e = rest_[i].edge_length;
    const double angle =
        exact_second ? dihedral_angle_hessian(x.col(h.v0), x.col(h.v1), x.col(h.v2), x.col(h.v3), g, h2)
                     : dihedral_angle_gradient(x.col(h.v0), x.col(h.v1), x.col(h.v2), x.col(h.v3), g);
    const double theta = angle - rest_angle_[i];
    const double kappa = c * std::abs(theta);
    const TorqueLaw& law = laws_[i];
    double barrier_first = 0.0, barrier_second = 0.0;
    total += e / c * law.work(kappa) + FoldBarrier::energy(angle, e * c * law.alpha, &barrier_first, &barrier_second);
    const double de = std::copysign(e * law.torque(kappa), theta) + barrier_first;  // dE / dtheta
    const double d2e = e * c * law.stiffness(kappa) + barrier_second;               // d^2E / dtheta^2
    if (gradient != nullptr) {
      for (int v = 0; v < 4; ++v) gradient->col((&h.v0)[v]) += de * g.segment<3>(3 * v);
    }
    if (hessian == nullptr) continue;
    element.noalias() = d2e * g * g.transpose();
    if (exact_second) {
      element.noalias() += de * h2;
      if (hessian->mode() != HessianMode::kExact) project_to_psd<12>(element);
    }
    hessian->add(static_cast<int>(i), element.data());
  }
  return total;
}

// ---------------------------------------------------------------------------------------------------------------

QuadraticBending::QuadraticBending(const ClothMesh& mesh, const Topology& topology, const DirectionalValues& gamma,
                                   AnisotropyRule rule)
    : mesh_(&mesh), topology_(&topology), hinges_(topology.hinges), gamma_dir_(gamma), rule_(rule) {
  validate_directional(gamma, "gamma", true);
  const std::vector<HingeRest> rest = hinge_rest_geometry(mesh, topology);
  weights_.reserve(hinges_.size());
  scale_.reserve(hinges_.size());
  for (std::size_t i = 0; i < hinges_.size(); ++i) {
    const Hinge& h = hinges_[i];
    const Eigen::Vector2d x0 = mesh.rest.col(h.v0), x1 = mesh.rest.col(h.v1);
    const Eigen::Vector2d e = x1 - x0;
    const double len2 = e.squaredNorm();
    const double a2 = (mesh.rest.col(h.v2) - x0).dot(e) / len2;
    const double a3 = (mesh.rest.col(h.v3) - x0).dot(e) / len2;
    auto height = [&](int v) {
      const Eigen::Vector2d d = mesh.rest.col(v) - x0;
      return std::abs(e.x() * d.y() - e.y() * d.x()) / std::sqrt(len2);
    };
    // |e| / h equals cot + cot of the wing's two angles at the edge (Bergou's cotangent weights).
    const double wa = std::sqrt(len2) / height(h.v2), wb = std::sqrt(len2) / height(h.v3);
    weights_.emplace_back(-((1.0 - a2) * wa + (1.0 - a3) * wb), -(a2 * wa + a3 * wb), wa, wb);
    scale_.push_back(3.0 / (rest[i].height_sum * rest[i].edge_length));
  }
  phi_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(hinges_.size()));
  hinge_bending_angles(mesh, topology, AnisotropyRule::kEdge, phi_);
  gamma_.resize(hinges_.size());
  for (std::size_t i = 0; i < hinges_.size(); ++i) gamma_[i] = floored(interpolate_directional(gamma, phi_[i]), gamma);
}

void QuadraticBending::element_vertices(int element, int* out) const {
  const Hinge& h = hinges_[element];
  out[0] = h.v0;
  out[1] = h.v1;
  out[2] = h.v2;
  out[3] = h.v3;
}

double QuadraticBending::update_lagged(const Eigen::Matrix3Xd& x) {
  const bool isotropic = gamma_dir_.warp == gamma_dir_.bias && gamma_dir_.bias == gamma_dir_.weft;
  if (isotropic || rule_ == AnisotropyRule::kEdge) return 0.0;
  ClothMesh current = *mesh_;
  current.positions = x;
  hinge_bending_angles(current, *topology_, rule_, phi_);
  double change = 0.0;
  for (std::size_t i = 0; i < hinges_.size(); ++i) {
    const double gamma = floored(interpolate_directional(gamma_dir_, phi_[i]), gamma_dir_);
    change = std::max(change, std::abs(gamma - gamma_[i]) / gamma_[i]);
    gamma_[i] = gamma;
  }
  return change;
}

double QuadraticBending::energy(const Eigen::Matrix3Xd& x) const { return evaluate(x, nullptr, nullptr); }

double QuadraticBending::evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient,
                                  HessianSink* hessian) const {
  double total = 0.0;
  Matrix12d element;
  for (std::size_t i = 0; i < hinges_.size(); ++i) {
    const Hinge& h = hinges_[i];
    const int v[4] = {h.v0, h.v1, h.v2, h.v3};
    const Eigen::Vector4d& w = weights_[i];
    Eigen::Vector3d kx = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) kx += w[a] * x.col(v[a]);
    const double k = gamma_[i] * scale_[i];
    total += k * kx.squaredNorm();
    if (gradient != nullptr) {
      for (int a = 0; a < 4; ++a) gradient->col(v[a]) += 2.0 * k * w[a] * kx;
    }
    if (hessian != nullptr) {
      element.setZero();
      for (int a = 0; a < 4; ++a) {
        for (int b = 0; b < 4; ++b) element.block<3, 3>(3 * a, 3 * b).diagonal().setConstant(2.0 * k * w[a] * w[b]);
      }
      hessian->add(static_cast<int>(i), element.data());
    }
  }
  return total;
}

}  // namespace drapegen::sim
