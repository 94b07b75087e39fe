#include "drapegen/sim/specimen.hpp"

#include <random>
#include <stdexcept>

namespace drapegen::sim {

ClothMesh make_specimen(const SpecimenSpec& spec) {
  if (spec.vertices_x < 2 || spec.vertices_y < 2) throw std::invalid_argument("specimen needs at least 2x2 vertices");
  if (!(spec.size_x > 0.0) || !(spec.size_y > 0.0)) throw std::invalid_argument("specimen size must be positive");
  if (!(spec.jitter >= 0.0 && spec.jitter <= 0.45)) throw std::invalid_argument("specimen jitter must be in [0, 0.45]");

  const int nx = spec.vertices_x, ny = spec.vertices_y;
  const double hx = spec.size_x / (nx - 1), hy = spec.size_y / (ny - 1);
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::bernoulli_distribution coin(0.5);

  ClothMesh mesh;
  mesh.material_angle = spec.material_angle;
  mesh.rest.resize(2, nx * ny);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      double x = -0.5 * spec.size_x + i * hx, y = -0.5 * spec.size_y + j * hy;
      const bool interior = i > 0 && j > 0 && i < nx - 1 && j < ny - 1;
      if (interior && spec.jitter > 0.0) {
        x += spec.jitter * hx * unit(rng);
        y += spec.jitter * hy * unit(rng);
      }
      mesh.rest.col(j * nx + i) = Eigen::Vector2d(x, y);
    }
  }
  mesh.triangles.resize(3, 2 * (nx - 1) * (ny - 1));
  int t = 0;
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      const bool main_diagonal = spec.random_diagonals ? coin(rng) : ((i + j) % 2 == 0);
      if (main_diagonal) {  // diagonal a-d
        mesh.triangles.col(t++) = Eigen::Vector3i(a, b, d);
        mesh.triangles.col(t++) = Eigen::Vector3i(a, d, c);
      } else {  // diagonal b-c
        mesh.triangles.col(t++) = Eigen::Vector3i(a, b, c);
        mesh.triangles.col(t++) = Eigen::Vector3i(b, d, c);
      }
    }
  }
  mesh.positions.resize(3, nx * ny);
  mesh.positions.topRows<2>() = mesh.rest;
  mesh.positions.row(2).setZero();
  return mesh;
}

}  // namespace drapegen::sim
