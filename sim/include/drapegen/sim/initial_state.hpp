#pragma once
// Initial states of a drape (paper Fig. 16): flat, random sine waves, a fold along a random direction, or a given
// mesh (e.g. another sample's drape), each rotated about the platform axis and shifted by a drift.

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "drapegen/sim/expected.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

enum class InitialShape { kFlat, kSine, kFold, kMesh };

struct InitialStateSpec {
  InitialShape shape = InitialShape::kFlat;
  std::uint64_t seed = 0;       // draws the waves or the fold line
  double rotation = 0.0;        // radians about the platform axis
  Eigen::Vector2d drift = Eigen::Vector2d::Zero();  // m, specimen centre relative to the axis
  std::string mesh_path;        // kMesh: a PLY file
  double lift = 0.001;          // m, height of the flat part above the top (the contact offset)
  double platform_radius = 0.05;
  /// Laid turned over, its back face up: the layout is mirrored across the specimen's u axis before the rotation. An
  /// elastic specimen without a rest shape drapes then as the mirror image of the same state laid face up; its own
  /// rest angles (edge curl, a plastic set) bend the other way in the world, as a turned-over specimen's creases do.
  /// Not for kMesh (the file's drape lies as it lies).
  bool face_down = false;
};

/// Parses "flat", "sine", "fold" or "mesh:FILE".
[[nodiscard]] Expected<InitialStateSpec> parse_initial_state(const std::string& text);

/// Places `mesh` (a flat specimen from make_specimen) in its initial state. The part of the specimen over the
/// platform top stays flat on it, so it can be held by the adhesive boundary condition. For kMesh the file replaces
/// the whole mesh (positions, rest coordinates, triangles): it must have the specimen's vertex and triangle counts
/// and rest coordinates (u, v) of the same total area (within 1%) with counter-clockwise triangles, as the PLY
/// files this library writes do; it is first moved level so that its centre point (the middle of its rest
/// coordinates' bounding box) lies on the axis, so that rotation and drift act on it as on the other shapes.
[[nodiscard]] Status apply_initial_state(const InitialStateSpec& spec, ClothMesh& mesh);

}  // namespace drapegen::sim
