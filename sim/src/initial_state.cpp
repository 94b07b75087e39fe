#include "drapegen/sim/initial_state.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "drapegen/sim/mesh_transfer.hpp"
#include "drapegen/sim/ply.hpp"
#include "drapegen/sim/xoshiro.hpp"

namespace drapegen::sim {
namespace {

double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

/// Superposes three random sine waves on the overhang; the amplitude ramps up from the platform rim.
void add_sine_waves(std::uint64_t seed, double platform_radius, ClothMesh& mesh) {
  Xoshiro256 rng(seed);
  struct Wave { Eigen::Vector2d k; double phase, amplitude; };
  Wave waves[3];
  for (Wave& w : waves) {
    const double angle = 2.0 * M_PI * rng.uniform();
    const double wavelength = 0.04 + 0.11 * rng.uniform();
    w.k = (2.0 * M_PI / wavelength) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    w.phase = 2.0 * M_PI * rng.uniform();
    w.amplitude = 0.004 + 0.008 * rng.uniform();
  }
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const Eigen::Vector2d p = mesh.positions.col(v).head<2>();
    const double ramp = smoothstep((p.norm() - platform_radius) / 0.03);
    double z = 0.0;
    for (const Wave& w : waves) z += w.amplitude * std::sin(w.k.dot(p) + w.phase);
    mesh.positions(2, v) += ramp * z;
  }
}

/// Bends the specimen down (isometrically) over a line outside the platform: a cylindrical crease of radius
/// `bend_radius` followed by a straight flap, at an angle of 30 to 90 degrees.
void add_fold(std::uint64_t seed, double platform_radius, ClothMesh& mesh) {
  Xoshiro256 rng(seed);
  const double direction = 2.0 * M_PI * rng.uniform();
  const Eigen::Vector2d n(std::cos(direction), std::sin(direction));
  const double offset = platform_radius + 0.005 + 0.035 * rng.uniform();
  const double angle = M_PI / 6.0 + (M_PI / 3.0) * rng.uniform();
  const double bend_radius = 0.01;
  const double arc = angle * bend_radius;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    Eigen::Vector3d p = mesh.positions.col(v);
    const double s = p.head<2>().dot(n) - offset;  // distance beyond the fold line
    if (s <= 0.0) continue;
    const Eigen::Vector2d foot = p.head<2>() - s * n;  // on the fold line
    double along, down;
    if (s <= arc) {
      const double a = s / bend_radius;
      along = bend_radius * std::sin(a);
      down = bend_radius * (1.0 - std::cos(a));
    } else {
      along = bend_radius * std::sin(angle) + (s - arc) * std::cos(angle);
      down = bend_radius * (1.0 - std::cos(angle)) + (s - arc) * std::sin(angle);
    }
    p.head<2>() = foot + along * n;
    p.z() -= down;
    mesh.positions.col(v) = p;
  }
}

}  // namespace

Expected<InitialStateSpec> parse_initial_state(const std::string& text) {
  InitialStateSpec spec;
  if (text == "flat") {
    spec.shape = InitialShape::kFlat;
  } else if (text == "sine") {
    spec.shape = InitialShape::kSine;
  } else if (text == "fold") {
    spec.shape = InitialShape::kFold;
  } else if (text.rfind("mesh:", 0) == 0 && text.size() > 5) {
    spec.shape = InitialShape::kMesh;
    spec.mesh_path = text.substr(5);
  } else {
    return Error{"unknown initial state '" + text + "' (expected flat, sine, fold or mesh:FILE)"};
  }
  return spec;
}

Status apply_initial_state(const InitialStateSpec& spec, ClothMesh& mesh) {
  if (!spec.drift.allFinite() || !std::isfinite(spec.rotation)) return Error{"drift and rotation must be finite"};
  if (spec.shape == InitialShape::kMesh && spec.face_down) {
    return Error{"a mesh initial state lies as its file does: it cannot also be laid face down"};
  }
  if (spec.shape == InitialShape::kMesh) {
    Expected<ClothMesh> loaded = read_ply(spec.mesh_path);
    if (!loaded) return loaded.error();
    if (loaded->vertex_count() != mesh.vertex_count()) {
      return Error{"initial mesh '" + spec.mesh_path + "' has " + std::to_string(loaded->vertex_count()) +
                   " vertices; the specimen has " + std::to_string(mesh.vertex_count())};
    }
    const double area = rest_triangle_areas(mesh).sum(), loaded_area = rest_triangle_areas(*loaded).sum();
    if (loaded->triangle_count() != mesh.triangle_count() || !(std::abs(loaded_area - area) <= 0.01 * area) ||
        rest_triangle_areas(*loaded).minCoeff() <= 0.0) {
      return Error{"initial mesh '" + spec.mesh_path + "' is not this specimen: it needs the same triangle count, "
                   "rest coordinates (u, v) of the same area and counter-clockwise rest triangles"};
    }
    // The warp's direction is the specimen's: a drape of another cut (or a file without the comment, angle 0, for a
    // turned specimen) would drape the fabric along other directions.
    if (!(std::abs(loaded->material_angle - mesh.material_angle) <= 1e-9)) {
      return Error{"initial mesh '" + spec.mesh_path + "' has the material angle " +
                   std::to_string(loaded->material_angle) + " rad; the specimen's is " +
                   std::to_string(mesh.material_angle) + " rad"};
    }
    mesh = std::move(loaded).value();
    // The drape sits where its own drift and rotation put it: bring its centre point back onto the axis, so that
    // `drift` places the centre as it does for the other shapes instead of adding to the source's drift.
    const Eigen::Vector2d rest_centre = 0.5 * (mesh.rest.rowwise().minCoeff() + mesh.rest.rowwise().maxCoeff());
    const Eigen::Vector3d centre = transfer_positions(mesh, rest_centre).col(0);
    mesh.positions.topRows<2>().colwise() -= centre.head<2>();
  } else {
    mesh.positions.topRows<2>() = mesh.rest;
    mesh.positions.row(2).setConstant(spec.lift);
    if (spec.shape == InitialShape::kSine) add_sine_waves(spec.seed, spec.platform_radius, mesh);
    if (spec.shape == InitialShape::kFold) add_fold(spec.seed, spec.platform_radius, mesh);
    if (spec.face_down) mesh.positions.row(1) *= -1.0;
  }
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(spec.rotation, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  mesh.positions = rotation * mesh.positions;
  mesh.positions.topRows<2>().colwise() += spec.drift;
  return {};
}

}  // namespace drapegen::sim
