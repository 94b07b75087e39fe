#include "drapegen/proto/simulation.hpp"

#include <cmath>
#include <fmt/format.h>

namespace drapegen::proto {
namespace {

v1::Simulation::Directional directional(const sim::DirectionalValues& d) {
  v1::Simulation::Directional out;
  out.set_warp(d.warp);
  out.set_bias(d.bias);
  out.set_weft(d.weft);
  return out;
}

sim::DirectionalValues directional(const v1::Simulation::Directional& d) { return {d.warp(), d.bias(), d.weft()}; }

/// The solver options the wire form does not carry (all but max_iterations and tolerance) are DrapeConfig's defaults.
bool default_solver_beyond_limits(sim::SolverOptions s) {
  const sim::SolverOptions d = sim::DrapeConfig{}.solver;
  s.max_iterations = d.max_iterations;
  s.tolerance = d.tolerance;
  return s == d;
}

template <typename Enum>
sim::Expected<Enum> enum_value(int value, Enum last, const char* what) {
  if (value < 0 || value > static_cast<int>(last)) {
    return sim::Error{fmt::format("simulation: unknown {} {}", what, value)};
  }
  return static_cast<Enum>(value);
}

}  // namespace

sim::Expected<v1::Simulation> to_proto(const sim::DrapeConfig& c) {
  if (c.initial.shape == sim::InitialShape::kMesh) return sim::Error{"simulation: a mesh initial state is not sent"};
  if (!default_solver_beyond_limits(c.solver)) {
    return sim::Error{"simulation: solver options other than max_iterations and tolerance are not sent"};
  }
  if (c.load_steps != 1) return sim::Error{"simulation: a ramped load (load_steps) is not sent"};
  v1::Simulation s;
  *s.mutable_alpha() = directional(c.fabric.alpha);
  *s.mutable_beta() = directional(c.fabric.beta);
  *s.mutable_gamma() = directional(c.fabric.gamma);
  s.set_density(c.fabric.density);
  s.set_bending_model(static_cast<int>(c.bending_model));
  s.set_anisotropy(static_cast<int>(c.anisotropy));
  s.set_membrane_stiffness(c.membrane.stiffness);
  s.set_membrane_band_low(c.membrane.band_low);
  s.set_membrane_band_high(c.membrane.band_high);
  s.set_membrane_band_stiffness_ratio(c.membrane.band_stiffness_ratio);
  s.set_platform_radius(c.platform.radius);
  s.set_platform_height(c.platform.height);
  s.set_platform_fillet(c.platform.fillet);
  s.set_platform_contact_offset(c.platform.contact_offset);
  s.set_platform_contact_stiffness(c.platform.contact_stiffness);
  s.set_specimen_size_x(c.specimen.size_x);
  s.set_specimen_size_y(c.specimen.size_y);
  s.set_specimen_vertices_x(c.specimen.vertices_x);
  s.set_specimen_vertices_y(c.specimen.vertices_y);
  s.set_specimen_jitter(c.specimen.jitter);
  s.set_specimen_triangulation(static_cast<int>(c.specimen.triangulation));
  s.set_specimen_seed(c.specimen.seed);
  s.set_specimen_material_angle(c.specimen.material_angle);
  s.set_initial_shape(static_cast<int>(c.initial.shape));
  s.set_initial_seed(c.initial.seed);
  s.set_initial_rotation(c.initial.rotation);
  s.set_initial_drift_x(c.initial.drift.x());
  s.set_initial_drift_y(c.initial.drift.y());
  s.set_initial_lift(c.initial.lift);
  s.set_initial_platform_radius(c.initial.platform_radius);
  s.set_max_iterations(c.solver.max_iterations);
  s.set_tolerance(c.solver.tolerance);
  s.set_gravity(c.gravity);
  s.set_adhesion(c.adhesion);
  s.set_coarse_start_resolution(c.coarse_start_resolution);
  s.mutable_rest_angles()->Add(c.rest_angles.data(), c.rest_angles.data() + c.rest_angles.size());
  const sim::PhysicalEffects& e = c.effects;
  if (e.edge_curl) {
    s.mutable_edge_curl()->set_curvature(e.edge_curl->curvature);
    s.mutable_edge_curl()->set_width(e.edge_curl->width);
  }
  if (e.bending_yield_curvature) s.set_bending_yield_curvature(*e.bending_yield_curvature);
  if (e.shear_stiffness) s.set_shear_stiffness(*e.shear_stiffness);
  if (e.friction) {
    s.mutable_friction()->set_coefficient(e.friction->coefficient);
    s.mutable_friction()->set_stick_distance(e.friction->stick_distance);
  }
  return s;
}

sim::Expected<sim::DrapeConfig> from_proto(const v1::Simulation& s) {
  sim::DrapeConfig c;
  auto model = enum_value(s.bending_model(), sim::BendingModel::kNonlinearTriangle, "bending model");
  if (!model) return model.error();
  auto anisotropy = enum_value(s.anisotropy(), sim::AnisotropyRule::kEdge, "anisotropy rule");
  if (!anisotropy) return anisotropy.error();
  auto triangulation = enum_value(s.specimen_triangulation(), sim::Triangulation::kUniform, "triangulation");
  if (!triangulation) return triangulation.error();
  auto shape = enum_value(s.initial_shape(), sim::InitialShape::kFold, "initial shape");
  if (!shape) return shape.error();
  for (double size : {s.specimen_size_x(), s.specimen_size_y(), s.platform_radius()}) {
    if (!(size > 0) || !std::isfinite(size)) return sim::Error{"simulation: specimen and platform sizes must be > 0"};
  }
  for (int n : {s.specimen_vertices_x(), s.specimen_vertices_y()}) {
    if (n < 2 || n > 1000) return sim::Error{fmt::format("simulation: {} vertices per side (2..1000)", n)};
  }
  if (s.max_iterations() < 1) return sim::Error{"simulation: max_iterations must be >= 1"};
  if (!(s.tolerance() > 0) || !std::isfinite(s.tolerance())) return sim::Error{"simulation: tolerance must be > 0"};
  if (s.coarse_start_resolution() < 0) return sim::Error{"simulation: coarse_start_resolution must be >= 0"};
  c.fabric.alpha = directional(s.alpha());
  c.fabric.beta = directional(s.beta());
  c.fabric.gamma = directional(s.gamma());
  c.fabric.density = s.density();
  c.bending_model = *model;
  c.anisotropy = *anisotropy;
  c.membrane = {s.membrane_stiffness(), s.membrane_band_low(), s.membrane_band_high(),
                s.membrane_band_stiffness_ratio()};
  c.platform = {s.platform_radius(), s.platform_height(), s.platform_fillet(), s.platform_contact_offset(),
                s.platform_contact_stiffness()};
  c.specimen = {s.specimen_size_x(), s.specimen_size_y(), s.specimen_vertices_x(), s.specimen_vertices_y(),
                s.specimen_jitter(), *triangulation, s.specimen_seed(), s.specimen_material_angle()};
  c.initial.shape = *shape;
  c.initial.seed = s.initial_seed();
  c.initial.rotation = s.initial_rotation();
  c.initial.drift = {s.initial_drift_x(), s.initial_drift_y()};
  c.initial.lift = s.initial_lift();
  c.initial.platform_radius = s.initial_platform_radius();
  c.solver.max_iterations = s.max_iterations();
  c.solver.tolerance = s.tolerance();
  c.gravity = s.gravity();
  c.adhesion = s.adhesion();
  c.coarse_start_resolution = s.coarse_start_resolution();
  c.rest_angles = Eigen::Map<const Eigen::VectorXd>(s.rest_angles().data(), s.rest_angles_size());
  if (s.has_edge_curl()) c.effects.edge_curl = sim::EdgeCurl{s.edge_curl().curvature(), s.edge_curl().width()};
  if (s.has_bending_yield_curvature()) c.effects.bending_yield_curvature = s.bending_yield_curvature();
  if (s.has_shear_stiffness()) c.effects.shear_stiffness = s.shear_stiffness();
  if (s.has_friction()) {
    c.effects.friction = sim::FrictionParameters{s.friction().coefficient(), s.friction().stick_distance()};
  }
  return c;
}

v1::SimulatedDrape to_proto(const sim::DrapeResult& r) {
  v1::SimulatedDrape d;
  const sim::ClothMesh& m = r.mesh;
  d.mutable_rest()->Add(m.rest.data(), m.rest.data() + m.rest.size());
  d.mutable_triangles()->Add(m.triangles.data(), m.triangles.data() + m.triangles.size());
  d.mutable_positions()->Add(m.positions.data(), m.positions.data() + m.positions.size());
  d.set_material_angle(m.material_angle);
  d.set_outcome(static_cast<int>(r.report.outcome));
  d.set_iterations(r.report.iterations);
  d.set_residual(r.report.residual);
  d.set_energy(r.report.energy);
  d.set_message(r.report.message);
  d.mutable_rest_angles()->Add(r.rest_angles.data(), r.rest_angles.data() + r.rest_angles.size());
  return d;
}

sim::Expected<sim::DrapeResult> from_proto(const v1::SimulatedDrape& d) {
  const int vertices = d.rest_size() / 2;
  if (d.rest_size() % 2 != 0 || d.positions_size() != 3 * vertices || vertices < 3) {
    return sim::Error{fmt::format("simulated drape: {} rest and {} position values make no mesh", d.rest_size(),
                                  d.positions_size())};
  }
  if (d.triangles_size() % 3 != 0 || d.triangles_size() == 0) {
    return sim::Error{fmt::format("simulated drape: {} triangle indices", d.triangles_size())};
  }
  for (int v : d.triangles()) {
    if (v < 0 || v >= vertices) return sim::Error{fmt::format("simulated drape: vertex index {} of {}", v, vertices)};
  }
  auto outcome = enum_value(d.outcome(), sim::SolveOutcome::kFactorizationFailed, "solve outcome");
  if (!outcome) return outcome.error();
  sim::DrapeResult r;
  r.mesh.rest = Eigen::Map<const Eigen::Matrix2Xd>(d.rest().data(), 2, vertices);
  r.mesh.triangles = Eigen::Map<const Eigen::Matrix3Xi>(d.triangles().data(), 3, d.triangles_size() / 3);
  r.mesh.positions = Eigen::Map<const Eigen::Matrix3Xd>(d.positions().data(), 3, vertices);
  r.mesh.material_angle = d.material_angle();
  r.report.outcome = *outcome;
  r.report.iterations = d.iterations();
  r.report.residual = d.residual();
  r.report.energy = d.energy();
  r.report.message = d.message();
  r.rest_angles = Eigen::Map<const Eigen::VectorXd>(d.rest_angles().data(), d.rest_angles_size());
  return r;
}

}  // namespace drapegen::proto
