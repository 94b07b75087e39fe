// The specimen's triangulations: every one tiles the square with positively oriented triangles; each has the
// diagonal pattern its name promises.
#include "drapegen/sim/specimen.hpp"

#include "drapegen/sim/xoshiro.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace drapegen::sim {
namespace {

double signed_area(const ClothMesh& mesh, int t) {
  const Eigen::Vector2d a = mesh.rest.col(mesh.triangles(0, t)), b = mesh.rest.col(mesh.triangles(1, t)),
                        c = mesh.rest.col(mesh.triangles(2, t));
  return 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
}

TEST(Specimen, EveryTriangulationTilesTheSquare) {
  for (const Triangulation t : {Triangulation::kAlternating, Triangulation::kRandom, Triangulation::kEquilateral,
                                Triangulation::kUniform}) {
    for (const double jitter : {0.0, 0.2}) {
      const ClothMesh mesh = make_specimen(SpecimenSpec{0.3, 0.2, 13, 9, jitter, t, 4, 0.0});
      double area = 0.0, smallest = 1.0;
      for (int i = 0; i < mesh.triangle_count(); ++i) {
        area += signed_area(mesh, i);
        smallest = std::min(smallest, signed_area(mesh, i));
      }
      EXPECT_NEAR(area, 0.3 * 0.2, 1e-12) << static_cast<int>(t) << " jitter " << jitter;
      EXPECT_GT(smallest, 0.0) << static_cast<int>(t) << " jitter " << jitter;
    }
  }
}

/// Of each grid quad's two triangles, whether the shared edge is the diagonal from the lower left to the upper right.
std::vector<bool> main_diagonals(const ClothMesh& mesh, int n) {
  std::vector<bool> out;
  for (int t = 0; t + 1 < mesh.triangle_count(); t += 2) {
    int shared = 0;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) shared += mesh.triangles(i, t) == mesh.triangles(j, t + 1) ? 1 : 0;
    }
    EXPECT_EQ(shared, 2);
    const int lower_left = mesh.triangles(0, t);  // a grid quad's triangles both start at its lower left corner
    bool main = false;
    for (int i = 0; i < 3; ++i) main = main || mesh.triangles(i, t) == lower_left + n + 1;
    out.push_back(main);
  }
  return out;
}

TEST(Specimen, DiagonalPatterns) {
  const int n = 7;
  const auto pattern = [&](Triangulation t) {
    return main_diagonals(make_specimen(SpecimenSpec{0.1, 0.1, n, n, 0.0, t, 1, 0.0}), n);
  };
  const std::vector<bool> uniform = pattern(Triangulation::kUniform),
                          alternating = pattern(Triangulation::kAlternating), random = pattern(Triangulation::kRandom);
  ASSERT_EQ(uniform.size(), static_cast<std::size_t>((n - 1) * (n - 1)));
  int random_main = 0;
  for (std::size_t q = 0; q < uniform.size(); ++q) {
    const int i = static_cast<int>(q) % (n - 1), j = static_cast<int>(q) / (n - 1);
    EXPECT_TRUE(uniform[q]) << q;
    EXPECT_EQ(alternating[q], (i + j) % 2 == 0) << q;  // the union jack
    random_main += random[q] ? 1 : 0;
  }
  EXPECT_GT(random_main, 0);
  EXPECT_LT(random_main, (n - 1) * (n - 1));
}

TEST(Specimen, RejectsBadSpecs) {
  EXPECT_THROW(make_specimen(SpecimenSpec{0.1, 0.1, 1, 5, 0.0, Triangulation::kUniform, 0, 0.0}),
               std::invalid_argument);
  EXPECT_THROW(make_specimen(SpecimenSpec{0.1, 0.1, 5, 5, 0.5, Triangulation::kRandom, 0, 0.0}), std::invalid_argument);
  EXPECT_THROW(make_specimen(SpecimenSpec{-0.1, 0.1, 5, 5, 0.0, Triangulation::kRandom, 0, 0.0}),
               std::invalid_argument);
  EXPECT_THROW(make_specimen(SpecimenSpec{0.1, 0.1, 5, 5, 0.0, Triangulation::kUniform, 0, std::nan("")}),
               std::invalid_argument);
}

// A seed means the same specimen with every standard library: the jitter is drawn from the project's own
// generator (the std:: distributions differ between libraries), first x then y of each interior vertex in row order.
TEST(Specimen, JitterIsTheProjectGeneratorsDraws) {
  SpecimenSpec spec;
  spec.vertices_x = spec.vertices_y = 5;
  spec.triangulation = Triangulation::kRandom;
  spec.jitter = 0.2;
  spec.seed = 31;
  const ClothMesh mesh = make_specimen(spec);
  const double h = spec.size_x / 4.0;
  Xoshiro256 rng(31);
  for (const int v : {6, 7}) {  // the first interior vertices: (1, 1) and (2, 1)
    const double x = -0.5 * spec.size_x + (v % 5) * h, y = -0.5 * spec.size_y + h;
    const double dx = 0.2 * h * (2.0 * rng.uniform() - 1.0), dy = 0.2 * h * (2.0 * rng.uniform() - 1.0);
    EXPECT_DOUBLE_EQ(mesh.rest(0, v), x + dx);
    EXPECT_DOUBLE_EQ(mesh.rest(1, v), y + dy);
  }
  EXPECT_NE(mesh.rest(0, 6), -0.5 * spec.size_x + h);  // jittered at all
}

}  // namespace
}  // namespace drapegen::sim
