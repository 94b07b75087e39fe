#pragma once
// Rectangular specimens: structured grids with seeded perturbation of the triangulation (paper Section 5.2.1).

#include <cstdint>
#include <map>
#include <string>

#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

/// How the specimen is triangulated.
enum class Triangulation {
  kAlternating,  // grid quads split by alternating diagonals ("union jack")
  kRandom,       // grid quads split by random diagonals (the paper's perturbed triangulation, with jitter)
  kEquilateral,  // rows of (nearly) equilateral triangles, odd rows offset by half a spacing; straight borders
  kUniform,      // grid quads all split along the same diagonal (lower left to upper right)
};

struct SpecimenSpec {
  double size_x = 0.3;  // metres, along the rest x axis
  double size_y = 0.3;  // metres, along the rest y axis
  int vertices_x = 100;
  int vertices_y = 100;
  /// Interior vertices move by up to this fraction of the spacing (uniform in a square), at most 0.3 (beyond it
  /// rest triangles can flip). 0 keeps the lattice.
  double jitter = 0.0;
  Triangulation triangulation = Triangulation::kAlternating;
  std::uint64_t seed = 0;
  /// Warp direction relative to the rest x axis, radians.
  double material_angle = 0.0;
};

/// The structured triangulations by their command-line names: "union-jack" (kAlternating), "uniform" and
/// "equilateral" (no jitter).
[[nodiscard]] const std::map<std::string, Triangulation>& structured_triangulations();

/// A flat specimen centred on the origin in the plane z = 0 (positions equal the rest coordinates).
/// Grid triangulations: vertex (i, j) has index j * vertices_x + i. kEquilateral: `vertices_y` rows, even rows with
/// `vertices_x` vertices, odd rows with one more (their end vertices sit on the borders), row by row.
/// Throws std::invalid_argument on fewer than 2 vertices per side, non-positive sizes or a jitter outside [0, 0.3].
[[nodiscard]] ClothMesh make_specimen(const SpecimenSpec& spec);

}  // namespace drapegen::sim
