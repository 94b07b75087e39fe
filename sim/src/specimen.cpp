#include "drapegen/sim/specimen.hpp"

#include <algorithm>
#include <cmath>
#include <vector>
#include <stdexcept>

#include "drapegen/sim/xoshiro.hpp"

namespace drapegen::sim {

namespace {

double uniform_jitter(Xoshiro256& rng, double amount) { return amount * (2.0 * rng.uniform() - 1.0); }

/// Rows of equilateral-like triangles; odd rows are offset by half a spacing and carry an extra vertex so that the
/// left and right borders stay straight.
ClothMesh equilateral_specimen(const SpecimenSpec& spec, Xoshiro256& rng) {
  const int nx = spec.vertices_x, ny = spec.vertices_y;
  const double hx = spec.size_x / (nx - 1), hy = spec.size_y / (ny - 1);
  std::vector<int> row_start(ny + 1, 0);
  for (int j = 0; j < ny; ++j) row_start[j + 1] = row_start[j] + (j % 2 == 0 ? nx : nx + 1);
  ClothMesh mesh;
  mesh.material_angle = spec.material_angle;
  mesh.rest.resize(2, row_start[ny]);
  for (int j = 0; j < ny; ++j) {
    const double y = -0.5 * spec.size_y + j * hy;
    const int count = row_start[j + 1] - row_start[j];
    for (int i = 0; i < count; ++i) {
      double x = -0.5 * spec.size_x + (j % 2 == 0 ? i * hx : std::clamp((i - 0.5) * hx, 0.0, spec.size_x));
      double yy = y;
      const bool interior = j > 0 && j < ny - 1 && i > 0 && i < count - 1;
      if (interior && spec.jitter > 0.0) {
        x += uniform_jitter(rng, spec.jitter * hx);
        yy += uniform_jitter(rng, spec.jitter * hy);
      }
      mesh.rest.col(row_start[j] + i) = Eigen::Vector2d(x, yy);
    }
  }
  std::vector<Eigen::Vector3i> tris;
  for (int j = 0; j + 1 < ny; ++j) {
    const int lo = row_start[j], hi = row_start[j + 1];
    if (j % 2 == 0) {  // lower row has nx vertices, upper row nx + 1
      for (int i = 0; i < nx; ++i) tris.emplace_back(lo + i, hi + i + 1, hi + i);
      for (int i = 0; i + 1 < nx; ++i) tris.emplace_back(lo + i, lo + i + 1, hi + i + 1);
    } else {  // lower row has nx + 1 vertices, upper row nx
      for (int i = 0; i < nx; ++i) tris.emplace_back(lo + i, lo + i + 1, hi + i);
      for (int i = 0; i + 1 < nx; ++i) tris.emplace_back(lo + i + 1, hi + i + 1, hi + i);
    }
  }
  mesh.triangles.resize(3, static_cast<Eigen::Index>(tris.size()));
  for (std::size_t t = 0; t < tris.size(); ++t) mesh.triangles.col(static_cast<Eigen::Index>(t)) = tris[t];
  return mesh;
}

/// A grid of quads, each split along one diagonal.
ClothMesh grid_specimen(const SpecimenSpec& spec, Xoshiro256& rng) {
  const int nx = spec.vertices_x, ny = spec.vertices_y;
  const double hx = spec.size_x / (nx - 1), hy = spec.size_y / (ny - 1);
  ClothMesh mesh;
  mesh.material_angle = spec.material_angle;
  mesh.rest.resize(2, nx * ny);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      double x = -0.5 * spec.size_x + i * hx, y = -0.5 * spec.size_y + j * hy;
      const bool interior = i > 0 && j > 0 && i < nx - 1 && j < ny - 1;
      if (interior && spec.jitter > 0.0) {
        x += uniform_jitter(rng, spec.jitter * hx);
        y += uniform_jitter(rng, spec.jitter * hy);
      }
      mesh.rest.col(j * nx + i) = Eigen::Vector2d(x, y);
    }
  }
  mesh.triangles.resize(3, 2 * (nx - 1) * (ny - 1));
  int t = 0;
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      const bool main_diagonal = spec.triangulation == Triangulation::kRandom    ? (rng.next() >> 63) != 0
                                 : spec.triangulation == Triangulation::kUniform ? true
                                                                                 : (i + j) % 2 == 0;
      if (main_diagonal) {  // diagonal a-d
        mesh.triangles.col(t++) = Eigen::Vector3i(a, b, d);
        mesh.triangles.col(t++) = Eigen::Vector3i(a, d, c);
      } else {  // diagonal b-c
        mesh.triangles.col(t++) = Eigen::Vector3i(a, b, c);
        mesh.triangles.col(t++) = Eigen::Vector3i(b, d, c);
      }
    }
  }
  return mesh;
}

}  // namespace

const std::map<std::string, Triangulation>& structured_triangulations() {
  static const std::map<std::string, Triangulation> names{{"union-jack", Triangulation::kAlternating},
                                                          {"uniform", Triangulation::kUniform},
                                                          {"equilateral", Triangulation::kEquilateral}};
  return names;
}

ClothMesh make_specimen(const SpecimenSpec& spec) {
  if (spec.vertices_x < 2 || spec.vertices_y < 2) throw std::invalid_argument("specimen needs at least 2x2 vertices");
  if (!(spec.size_x > 0.0) || !(spec.size_y > 0.0)) throw std::invalid_argument("specimen size must be positive");
  if (!(spec.jitter >= 0.0 && spec.jitter <= 0.3)) throw std::invalid_argument("specimen jitter must be in [0, 0.3]");
  // A NaN angle read as 0 downstream (every hinge the warp's): an anisotropic fabric draped as an isotropic one.
  if (!std::isfinite(spec.material_angle)) throw std::invalid_argument("specimen material angle must be finite");
  Xoshiro256 rng(spec.seed);
  ClothMesh mesh = spec.triangulation == Triangulation::kEquilateral ? equilateral_specimen(spec, rng)
                                                                     : grid_specimen(spec, rng);
  mesh.positions.resize(3, mesh.rest.cols());
  mesh.positions.topRows<2>() = mesh.rest;
  mesh.positions.row(2).setZero();
  return mesh;
}

}  // namespace drapegen::sim
