#pragma once
// Rectangular specimens: structured grids with seeded perturbation of the triangulation (paper Section 5.2.1).

#include <cstdint>

#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

struct SpecimenSpec {
  double size_x = 0.3;  // metres, along the rest x axis
  double size_y = 0.3;  // metres, along the rest y axis
  int vertices_x = 100;
  int vertices_y = 100;
  /// Interior vertices move by up to this fraction of the grid spacing (uniform in a square). 0 keeps the grid.
  double jitter = 0.0;
  /// Choose each quad's diagonal at random; false gives alternating diagonals (a symmetric "union jack" grid).
  bool random_diagonals = false;
  std::uint64_t seed = 0;
  /// Warp direction relative to the rest x axis, radians.
  double material_angle = 0.0;
};

/// A flat specimen centred on the origin in the plane z = 0 (positions equal the rest coordinates).
/// Vertex (i, j) has index j * vertices_x + i. Throws std::invalid_argument on fewer than 2 vertices per side,
/// non-positive sizes or a jitter outside [0, 0.45].
[[nodiscard]] ClothMesh make_specimen(const SpecimenSpec& spec);

}  // namespace drapegen::sim
