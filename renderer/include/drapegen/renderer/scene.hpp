#pragma once
// What the depth camera sees: the draped cloth and the platform cylinder, as one triangle soup in world
// coordinates (metres, z up, platform top disk in z = 0, axis through the origin, as in drapegen::sim).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "drapegen/sim/expected.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::renderer {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<int, 3>> triangles;
  /// If >= 0: the triangles from this index on form closed surfaces wound counter-clockwise seen from outside (the
  /// platform). Seen from outside, their back faces are always behind their front faces, and SoftwareRenderer skips
  /// them, unless the near plane cuts the surfaces open (a camera inside them would not see them). -1: none.
  int closed_from = -1;

  [[nodiscard]] int vertex_count() const { return static_cast<int>(vertices.size()); }
  [[nodiscard]] int triangle_count() const { return static_cast<int>(triangles.size()); }
  /// Appends `other` (indices shifted). The closed triangles stay the last ones: those of `other` stay closed, this
  /// mesh's own become ordinary ones.
  void append(const TriangleMesh& other);
};

/// The platform: a closed cylinder of `radius` from z = -height to z = 0, its side split into `segments` facets, all
/// of it marked closed (TriangleMesh::closed_from = 0).
/// The polygon's vertices lie on the circle; its facets are at most radius * (1 - cos(pi / segments)) inside it
/// (27 um for the defaults).
struct CylinderSpec {
  double radius = 0.05;
  double height = 0.25;
  int segments = 96;
};
[[nodiscard]] TriangleMesh make_cylinder(const CylinderSpec& spec);

/// The cloth's current positions and triangles. Fails (naming the problem) on an empty mesh, a non-finite vertex or
/// an index out of range: a renderer never turns a bad mesh into a silently blank image.
[[nodiscard]] sim::Expected<TriangleMesh> cloth_triangles(const sim::ClothMesh& mesh);

/// Checks a triangle mesh as cloth_triangles does, and closed_from.
[[nodiscard]] sim::Status validate(const TriangleMesh& mesh);

}  // namespace drapegen::renderer
