// Physics acceptance tests of the drape simulator (Feng et al. 2022) on coarse meshes: k/rho invariance (Section
// 5.1.2, Fig. 14), rotation invariance about the platform axis, in-plane stiffness and locking (Section 4.1, Figs.
// 5-7, 9), mesh dependence of anisotropic bending (Section 4.4, Fig. 12) and the initial states (Fig. 16).
// bench/drape_physics.cpp runs the same checks on finer meshes (docs/BENCHMARKS.md).
//
// A drape that starts flat passes through buckling bifurcations (the hem chooses where to fold), so its final
// state is one of many nearby local minima, selected by details of the Newton path: a 1% change of k and rho (with
// sigma fixed) or a different random triangulation moves folds by millimetres and the drape coefficient by up to
// ~10% at these resolutions. The bounds below are therefore asserted only where the simulator must be exact (a
// problem that is a scaled or rotated copy of another) or where the effect is far above that noise; the rest is
// printed for the record.
#include "drapegen/sim/drape.hpp"
#include "drapegen/sim/ply.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <filesystem>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "drapegen/sim/measures.hpp"

namespace drapegen::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kMm = 1e3;  // m -> mm

/// The median fabric of the paper's data set (paper units: alpha g*mm^2/s^2, beta g*mm^3/s^2).
constexpr DirectionalValues kMedianAlpha{13923, 11455, 8821};
constexpr DirectionalValues kMedianBeta{-35390, -29660, -22042};

DirectionalValues scaled(const DirectionalValues& v, double s) { return {v.warp * s, v.bias * s, v.weft * s}; }

/// A 300 mm specimen of n x n vertices with the median fabric: the paper's perturbed triangulation, or a structured
/// "union jack" grid (symmetric under 90-degree rotations when n is odd).
DrapeConfig config(int n, bool structured) {
  DrapeConfig c;
  c.fabric = fabric_from_paper_units(kMedianAlpha, kMedianBeta, 300.0);
  c.specimen = SpecimenSpec{0.3, 0.3, n, n, structured ? 0.0 : 0.2,
                            structured ? Triangulation::kAlternating : Triangulation::kRandom, 0, 0.0};
  return c;
}

/// Solves and checks that the solve converged.
DrapeResult drape(const DrapeConfig& c, const std::string& label) {
  Expected<DrapeResult> r = simulate_drape(c);
  if (!r) {
    ADD_FAILURE() << label << ": " << r.error().message;
    return {};
  }
  const SolveReport& s = r->report;
  EXPECT_EQ(s.outcome, SolveOutcome::kConverged) << label << ": residual " << s.residual << " after " << s.iterations
                                                 << " iterations";
  std::printf("[ drape    ] %-34s %3d it %5.1f s  DC %.4f  folds %d  self-intersections %d\n", label.c_str(),
              s.iterations, s.seconds, r->measures.drape_coefficient, r->measures.folds,
              r->measures.self_intersections);
  return std::move(r).value();
}

double max_distance_mm(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return a.cols() == b.cols() && a.cols() > 0 ? (a - b).colwise().norm().maxCoeff() * kMm : 1e9;
}
double mean_distance_mm(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return a.cols() == b.cols() && a.cols() > 0 ? (a - b).colwise().norm().mean() * kMm : 1e9;
}

TEST(DrapePhysics, AWeightlessDrapeIsAnInputError) {
  for (const double g : {0.0, -9.81, std::numeric_limits<double>::quiet_NaN()}) {
    DrapeConfig c;
    c.specimen.vertices_x = c.specimen.vertices_y = 10;
    c.gravity = g;
    const Expected<DrapeResult> r = simulate_drape(c);
    ASSERT_FALSE(r.has_value()) << g;
    EXPECT_NE(r.error().message.find("gravity must be positive"), std::string::npos) << r.error().message;
  }
}

// A mesh too coarse to put a vertex on the top says so (a 2 m specimen at 10 vertices per side: 222 mm apart, none
// within the 50 mm radius); the message named only the drift and the initial mesh before.
TEST(DrapePhysics, AMeshTooCoarseForThePlatformTopSaysSo) {
  DrapeConfig c;
  c.specimen.size_x = c.specimen.size_y = 2.0;
  c.specimen.vertices_x = c.specimen.vertices_y = 10;
  const Expected<DrapeResult> r = simulate_drape(c);
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.error().message.find("the mesh's 222 mm spacing too coarse for the top's 50 mm radius: more vertices "
                                   "per side"),
            std::string::npos)
      << r.error().message;
}

// Solver options a solve cannot run with are refused up front, each by name (a zero max_step crept at t = 0 into
// "stalled"; a NaN tolerance never converged).
TEST(DrapePhysics, SolverOptionsItCannotRunWithAreInputErrors) {
  const std::vector<std::pair<std::function<void(SolverOptions&)>, std::string>> cases{
      {[](SolverOptions& o) { o.max_step = 0.0; }, "max_step"},
      {[](SolverOptions& o) { o.tolerance = std::numeric_limits<double>::quiet_NaN(); }, "tolerance"},
      {[](SolverOptions& o) { o.max_iterations = 0; }, "max_iterations"},
      {[](SolverOptions& o) { o.armijo = 1.5; }, "armijo"},
      {[](SolverOptions& o) { o.lagged_outer_below = -1.0; }, "thresholds"}};
  for (const auto& [spoil, name] : cases) {
    DrapeConfig c;
    c.specimen.vertices_x = c.specimen.vertices_y = 10;
    spoil(c.solver);
    const Expected<DrapeResult> r = simulate_drape(c);
    ASSERT_FALSE(r.has_value()) << name;
    EXPECT_NE(r.error().message.find(name), std::string::npos) << r.error().message;
  }
  EXPECT_TRUE(validate(DrapeConfig{}.solver));
  EXPECT_TRUE(validate(SolverOptions{}));
}

// (a) Section 5.1.2, Fig. 14. Scaling alpha, beta and rho by s scales bending and gravity by s; the paper argues that
// the stretching force may be scaled arbitrarily "as long as it remains sufficiently large", so x depends on k/rho
// only, and it normalises every fabric to the standard density. The simulator does the same (normalized()): sigma
// and the contact penalty are stiffnesses at the standard density. So (1) a fabric with k and rho scaled together
// must drape like the original from the same start (the normalised moduli differ in the last bit, so the inexact
// solver path differs at round-off level); (2) the physical claim behind it: with sigma and the contact penalty
// held in absolute units instead (equivalently, both divided by s at the standard density), the equilibrium moves
// less than the same factor on the bending alone moves it (on this coarse mesh not by much less: below; it
// compresses beyond the 1% band in its folds, where sigma acts; bench/drape_physics.cpp, check a, at finer meshes).
// (2) continues from the base drape: from a flat start, tiny differences can select another of the drape's many
// local minima, which measures the path, not k/rho. Three triangulations: the margins depend on the draw.
TEST(DrapePhysics, DrapeDependsOnBendingOverDensity) {
  for (const std::uint64_t seed : {0, 1, 2}) {
    SCOPED_TRACE("triangulation " + std::to_string(seed));
    DrapeConfig base = config(25, false);
    base.specimen.seed = seed;
    const DrapeResult r0 = drape(base, "k/rho: median fabric");
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("drapegen_k_over_rho_base_" + std::to_string(::getpid()) + ".ply"))
                                 .string();
    ASSERT_TRUE(write_ply(path, r0.mesh));
    // The control restarts the base fabric from its own drape: the curvature rule recomputes the bending directions
    // from that drape, so even the control moves (0.4 mm on one triangulation, 2.8 mm on another); the claims concern
    // differences from it.
    DrapeConfig control = base;
    control.initial = InitialStateSpec{};
    control.initial.shape = InitialShape::kMesh;
    control.initial.mesh_path = path;
    const DrapeResult restarted = drape(control, "k/rho: restart from the base drape");
    const double control_moved = max_distance_mm(restarted.mesh.positions, r0.mesh.positions);
    for (const double s : {3.0, 0.5}) {
      DrapeConfig c = base;
      c.fabric.alpha = scaled(base.fabric.alpha, s);
      c.fabric.beta = scaled(base.fabric.beta, s);
      c.fabric.density *= s;
      const DrapeResult same = drape(c, "k/rho: k, rho x" + std::to_string(s).substr(0, 3));
      const double d_same = max_distance_mm(same.mesh.positions, r0.mesh.positions);
      // With exact Newton steps the path is insensitive to the last bit of the normalised moduli; the inexact (PCG)
      // steps amplify it through the lagged anisotropy directions, about as far as a restart of the base drape from
      // itself moves: the bound allows half as much again (triangulation 2 with OpenBLAS's SkylakeX kernels, chosen
      // on an AVX-512 CPU: 3.70 mm against the control's 3.62; with its Haswell kernels 0.004 mm; the others below).
      DrapeConfig exact_base = base, exact_scaled = c;
      exact_base.solver.max_pcg_iterations = exact_scaled.solver.max_pcg_iterations = 0;
      const double d_exact = max_distance_mm(drape(exact_scaled, "k/rho: scaled, exact Newton").mesh.positions,
                                             drape(exact_base, "k/rho: base, exact Newton").mesh.positions);
      std::printf("[ k/rho    ] x%.1f: max vertex distance %.2e mm (exact Newton steps %.2e mm; the control moved "
                  "%.3f mm)\n", s, d_same, d_exact, control_moved);
      EXPECT_LT(d_exact, 0.1) << "x" << s;
      EXPECT_LT(d_same, 1.5 * std::max(control_moved, 0.1)) << "x" << s;
      EXPECT_NEAR(same.measures.drape_coefficient, r0.measures.drape_coefficient, 1e-3);

      DrapeConfig absolute = control;
      absolute.membrane.stiffness /= s;
      absolute.platform.contact_stiffness /= s;
      DrapeConfig bending = control;
      bending.fabric.alpha = scaled(base.fabric.alpha, s);
      bending.fabric.beta = scaled(base.fabric.beta, s);
      const DrapeResult moved = drape(absolute, "k/rho: same, sigma and contact in absolute units");
      const DrapeResult bent = drape(bending, "k/rho: same, bending alone scaled");
      const double d_mean = mean_distance_mm(moved.mesh.positions, restarted.mesh.positions);
      const double d_dc = std::abs(moved.measures.drape_coefficient - restarted.measures.drape_coefficient);
      const double bent_mean = mean_distance_mm(bent.mesh.positions, restarted.mesh.positions);
      const double bent_dc = std::abs(bent.measures.drape_coefficient - restarted.measures.drape_coefficient);
      std::printf("[ k/rho    ] x%.1f, sigma and contact absolute: mean vertex distance %.3f mm, |dDC| %.4f; the "
                  "bending alone x%.1f: %.3f mm, %.4f\n", s, d_mean, d_dc, s, bent_mean, bent_dc);
      // Observed on triangulations 0, 1, 2: the mean distance is 0.38 / 0.48 / 0.30 of the bending's at x3 (sigma
      // falls to 67, below Figs. 5-7's range) and 0.25 / 0.25 / 0.15 at x0.5; the drape coefficient moves 0.13 /
      // 0.01 / 0.03 of the bending's at x3 (at x0.5 a restart keeps its folds and the bending alone hardly moves
      // the coefficient either: 0.009-0.014).
      EXPECT_LT(d_mean, 0.6 * bent_mean) << "x" << s;
      if (s > 1.0) {
        EXPECT_LT(d_dc, 0.2 * bent_dc) << "x" << s;
      }
    }
    std::filesystem::remove(path);
  }
}

// (b) The platform is a cylinder about the z axis and gravity points along it: rotating the specimen about the axis
// must rotate the drape, vertex by vertex. On an odd union jack grid the mesh itself is symmetric under a rotation by
// 90 degrees that maps vertex (i, j) to (n-1-j, i), so an isotropic drape must have that symmetry too (the solver must
// not break it), and swapping warp and weft of an anisotropic fabric must give the drape mirrored in x = y.
// (Newton keeps an exact symmetry, so a symmetric drape can also be a saddle: with warp = 4 x weft on a 31 x 31 grid,
// a restart from 1 micrometre of noise moves 12 mm to a lower energy. At 25 x 25 both drapes here are stable;
// bench/drape_physics.cpp checks that.)
TEST(DrapePhysics, RotationAboutTheAxisRotatesTheDrape) {
  constexpr int n = 25;
  DrapeConfig base = config(n, true);
  base.fabric = fabric_from_paper_units({11455, 11455, 11455}, {-29660, -29660, -29660}, 300.0);
  base.solver.max_pcg_iterations = 0;  // exact Newton steps keep the symmetry of the path (see k/rho above)
  const DrapeResult r0 = drape(base, "rotation: isotropic, 0 deg");
  DrapeConfig turned = base;
  turned.initial.rotation = kPi / 2.0;
  const DrapeResult r90 = drape(turned, "rotation: isotropic, 90 deg");
  const Eigen::Matrix3d q = Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const double d_rotated = max_distance_mm(r90.mesh.positions, q * r0.mesh.positions);
  EXPECT_LT(d_rotated, 0.1);
  EXPECT_NEAR(r90.measures.drape_coefficient, r0.measures.drape_coefficient, 1e-3);

  // Vertex (i, j) of the drape rotated by 90 degrees lands on vertex (n-1-j, i).
  auto symmetry_defect = [&](const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
    if (a.cols() != n * n) return 1e9;  // a failed drape
    Eigen::Matrix3Xd permuted(3, a.cols());
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) permuted.col(i * n + (n - 1 - j)) = q * a.col(j * n + i);
    }
    return max_distance_mm(permuted, b);
  };
  const double d_symmetry = symmetry_defect(r0.mesh.positions, r0.mesh.positions);
  std::printf("[ rotation ] 90 deg: max distance to the rotated drape %.2e mm; D4 symmetry defect %.2e mm\n",
              d_rotated, d_symmetry);
  EXPECT_LT(d_symmetry, 0.1);

  DrapeConfig warp_stiff = base;
  warp_stiff.fabric = fabric_from_paper_units({20000, 12500, 5000}, {-50000, -31250, -12500}, 300.0);
  DrapeConfig weft_stiff = warp_stiff;
  std::swap(weft_stiff.fabric.alpha.warp, weft_stiff.fabric.alpha.weft);
  std::swap(weft_stiff.fabric.beta.warp, weft_stiff.fabric.beta.weft);
  const DrapeResult a = drape(warp_stiff, "rotation: warp 4 x weft");
  const DrapeResult b = drape(weft_stiff, "rotation: weft 4 x warp");
  // Mirroring in the plane x = y maps the grid onto itself (vertex (i, j) to (j, i)) and swaps warp and weft.
  Eigen::Matrix3Xd mirrored(3, a.mesh.positions.cols());
  if (a.mesh.positions.cols() == n * n) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d p = a.mesh.positions.col(j * n + i);
        mirrored.col(i * n + j) = Eigen::Vector3d(p.y(), p.x(), p.z());
      }
    }
  }
  const double d_swap = max_distance_mm(mirrored, b.mesh.positions);
  const double d_swap_rotated = symmetry_defect(a.mesh.positions, b.mesh.positions);
  std::printf("[ rotation ] warp/weft swapped vs drape mirrored in x = y: max distance %.2e mm (vs rotated by 90 "
              "deg: %.2e mm)\n",
              d_swap, d_swap_rotated);
  EXPECT_LT(d_swap, 0.1);
  // The two images agree while the anisotropic drape keeps its mirror symmetries, as it does at 25 x 25 (at 61 x 61
  // it breaks them, to a fold pattern 34 mm away from its mirror image, so only the x = y mirror is exact there).
  EXPECT_LT(d_swap_rotated, 0.1);
}

// (c) Section 4.1: sigma barely changes the drape once it is large enough (Figs. 5-7), and a stiff sigma = 5000 does
// not lock thanks to the stretch band [0.99, 1.01] (Fig. 9). Without the band, sigma = 5000 locks: the specimen
// cannot form folds and stands out like a stiff skirt. At 25 x 25 some locking remains with the band, and how much
// depends on the triangulation: over eight random triangulations of each of two generators (`drapegen simulate
// --resolution 25 --seed S --sigma G`, S = 0..7), sigma 1000 moved the drape coefficient by -6% to +14% from sigma
// 200 and sigma 5000 by -3% to +28% (a single draw had shown +1% and -3%; the triangulations' own spread at sigma
// 200 is 0.13-0.16), while without the band it more than doubles. On finer meshes less remains: +1.5% to +7.5% at
// 60 x 60 over three triangulations (bench/drape_physics.cpp). So the claim is checked on three triangulations.
TEST(DrapePhysics, InPlaneStiffnessBarelyMattersAndDoesNotLock) {
  for (const std::uint64_t seed : {0, 1, 2}) {
    DrapeConfig base = config(25, false);
    base.specimen.seed = seed;
    auto with = [&](double sigma, bool band) {
      DrapeConfig c = base;
      c.membrane.stiffness = sigma;
      if (!band) c.membrane.band_low = c.membrane.band_high = 1.0;
      return drape(c, "sigma " + std::to_string(static_cast<int>(sigma)) + (band ? ", band" : ", no band"));
    };
    const DrapeResult s200 = with(200, true), s1000 = with(1000, true), s5000 = with(5000, true);
    const DrapeResult locked = with(5000, false);
    const double dc200 = s200.measures.drape_coefficient, dc1000 = s1000.measures.drape_coefficient;
    const double dc5000 = s5000.measures.drape_coefficient, dc_locked = locked.measures.drape_coefficient;
    std::printf("[ sigma    ] triangulation %d: DC 200 %.4f, 1000 %.4f, 5000 %.4f; no band 5000 %.4f; mean vertex "
                "distance to sigma 200: 1000 %.2f mm, 5000 without band %.2f mm\n",
                static_cast<int>(seed), dc200, dc1000, dc5000, dc_locked,
                mean_distance_mm(s1000.mesh.positions, s200.mesh.positions),
                mean_distance_mm(locked.mesh.positions, s200.mesh.positions));
    EXPECT_NEAR(dc1000, dc200, 0.2 * dc200) << "triangulation " << seed;
    EXPECT_NEAR(dc5000, dc200, 0.35 * dc200) << "triangulation " << seed;
    // Locking without the band: far stiffer than any bending change here (DC roughly doubles or more), and the band
    // takes away most of sigma 5000's stiffening.
    EXPECT_GT(dc_locked, dc200 + 0.1) << "triangulation " << seed;
    EXPECT_LT(std::abs(dc5000 - dc200), 0.25 * (dc_locked - dc200)) << "triangulation " << seed;
  }
}

/// Hem radius around the rest x axis (azimuths 0 and 180 degrees, +-15 degrees) over that around the rest y axis.
double hem_elongation(const ClothMesh& mesh) {
  const std::vector<double> p = hem_profile(mesh, 360);
  double x = 0.0, y = 0.0;
  for (int d = 0; d < 360; ++d) {
    if (std::min(d % 180, 180 - d % 180) <= 15) x += p[static_cast<std::size_t>(d)];
    if (std::abs(d % 180 - 90) <= 15) y += p[static_cast<std::size_t>(d)];
  }
  return x / y;
}

// (d) Section 4.4, Fig. 12: strongly anisotropic bending (alpha and beta warp = 4 x weft).
//
// The paper's comparison - drape coefficients on a structured and a perturbed mesh within 2% under the curvature
// rule, further apart under the edge rule - is printed but not asserted: at these resolutions the drape coefficient
// of *isotropic* bending already differs by 3-30% between the two triangulations (5-15% at 30 x 30, ~3% at 60 x 60;
// bench/drape_physics.cpp), and the perturbed mesh (a grid with random diagonals) has hinges along warp, weft and
// the bias like the structured one, so the edge rule errs little on it (0.4% at 25 x 25, 16% at 30 x 30: noise).
//
// What is asserted is where the edge rule must fail: on the equilateral mesh (edges at 0, 60 and 120 degrees) no
// hinge bends along the warp when the warp is the rest x axis, and none along the weft when the material is turned
// by 90 degrees. The anisotropy of the hem - warp over weft hem radius, averaged over the material at 0 and 90
// degrees so that the mesh's own x/y bias cancels - is then weaker under the edge rule than under the curvature
// rule (observed at 24-41 vertices per side: curvature 0.75-0.89, edge 0.84-0.95, the edge rule always higher, by
// 0.04-0.20; 60 x 60: 0.86 vs 0.92).
TEST(DrapePhysics, CurvatureRuleKeepsTheAnisotropyOnAnyMesh) {
  const FabricParameters fabric =
      fabric_from_paper_units({20000, 12500, 5000}, {-50000, -31250, -12500}, 300.0);
  for (const AnisotropyRule rule : {AnisotropyRule::kCurvature, AnisotropyRule::kEdge}) {
    const bool edge = rule == AnisotropyRule::kEdge;
    double dc[2];
    for (const bool structured : {true, false}) {
      DrapeConfig c = config(25, structured);
      c.fabric = fabric;
      c.anisotropy = rule;
      dc[structured] = drape(c, std::string(edge ? "edge" : "curvature") + " rule, " +
                                    (structured ? "structured" : "perturbed"))
                           .measures.drape_coefficient;
    }
    std::printf("[ fig 12   ] %s rule: DC structured %.4f, perturbed %.4f, relative difference %.1f%% "
                "(paper: < 2%% for the curvature rule; not asserted, see above)\n",
                edge ? "edge" : "curvature", dc[1], dc[0], 100 * std::abs(dc[1] - dc[0]) / (0.5 * (dc[0] + dc[1])));
  }

  double ratio[2];
  for (const AnisotropyRule rule : {AnisotropyRule::kCurvature, AnisotropyRule::kEdge}) {
    const bool edge = rule == AnisotropyRule::kEdge;
    double elongation[2];
    for (const bool turned : {false, true}) {
      DrapeConfig c = config(25, true);
      c.specimen.triangulation = Triangulation::kEquilateral;
      c.specimen.material_angle = turned ? kPi / 2.0 : 0.0;
      c.fabric = fabric;
      c.anisotropy = rule;
      elongation[turned] = hem_elongation(
          drape(c, std::string(edge ? "edge" : "curvature") + " rule, equilateral, warp " + (turned ? "y" : "x"))
              .mesh);
    }
    ratio[edge] = std::sqrt(elongation[0] / elongation[1]);
  }
  std::printf("[ fig 12   ] equilateral mesh, hem radius warp/weft: curvature rule %.4f, edge rule %.4f\n", ratio[0],
              ratio[1]);
  EXPECT_LT(ratio[0], 0.95);      // the anisotropy shows (isotropic bending: 1)
  EXPECT_GT(ratio[1], ratio[0]);  // the edge rule loses part of it
}

// (e) Fig. 16: flat, sine and fold starts all reach an equilibrium for the median fabric. They may settle in
// different local minima (other fold patterns), so only convergence and sanity are asserted.
TEST(DrapePhysics, EveryInitialStateConverges) {
  for (const InitialShape shape : {InitialShape::kFlat, InitialShape::kSine, InitialShape::kFold}) {
    const std::string name = shape == InitialShape::kFlat ? "flat" : shape == InitialShape::kSine ? "sine" : "fold";
    DrapeConfig c = config(25, false);
    c.initial.shape = shape;
    c.initial.seed = 3;
    const DrapeResult r = drape(c, "initial state " + name);
    EXPECT_GT(r.measures.drape_coefficient, 0.0) << name;
    EXPECT_LT(r.measures.drape_coefficient, 0.5) << name;
    EXPECT_GE(r.measures.folds, 3) << name;
    EXPECT_LT(r.measures.max_penetration, 1e-3) << name;
  }
}

// The outer loop of the lagged anisotropy directions starts at a residual of 30 vertex weights (DrapeConfig; the
// solver's own default is 3): the directions follow the shape, which has formed by then. The equilibrium it reaches
// must be the same drape as with the stricter threshold, on a strongly anisotropic fabric whose directions matter:
// the same folds and drape coefficient, and a mean vertex distance under 1 mm (a fold shifted by round-off in the
// path, not another drape: with OpenBLAS's SkylakeX kernels, chosen on an AVX-512 CPU, 0.53 mm mean and 4.8 mm at
// most; with its Haswell or Prescott kernels 0.17-0.18 mm and 1.2-1.3 mm).
TEST(DrapePhysics, TheOuterLoopThresholdLeavesTheDrapeInPlace) {
  DrapeConfig early = config(25, false);
  early.fabric = fabric_from_paper_units({40327, 6078, 15209}, {-81110, -11388, -33813}, 300.0);
  ASSERT_EQ(early.solver.lagged_outer_below, 30.0);
  DrapeConfig late = early;
  late.solver.lagged_outer_below = SolverOptions{}.lagged_outer_below;
  ASSERT_EQ(late.solver.lagged_outer_below, 3.0);
  const DrapeResult a = drape(early, "outer loop below 30");
  const DrapeResult b = drape(late, "outer loop below 3");
  const double mean = mean_distance_mm(a.mesh.positions, b.mesh.positions);
  std::printf("[ drape    ] outer loop 30 vs 3: mean %.3f mm, max %.3f mm\n", mean,
              max_distance_mm(a.mesh.positions, b.mesh.positions));
  EXPECT_LT(mean, 1.0);
  EXPECT_NEAR(a.measures.drape_coefficient, b.measures.drape_coefficient, 2e-3);
  EXPECT_EQ(a.measures.folds, b.measures.folds);
}

// Plastic flow is a lagged force: with a yield curvature the drape's outer loop keeps the solver's threshold (3)
// whatever DrapeConfig asks, so that the flow is computed near equilibrium: the two thresholds give the same drape.
TEST(DrapePhysics, PlasticFlowKeepsTheStrictOuterLoop) {
  DrapeConfig a = config(16, false);
  a.effects.bending_yield_curvature = 20.0;
  DrapeConfig b = a;
  b.solver.lagged_outer_below = SolverOptions{}.lagged_outer_below;
  ASSERT_NE(a.solver.lagged_outer_below, b.solver.lagged_outer_below);
  const DrapeResult ra = drape(a, "yield, DrapeConfig's threshold");
  const DrapeResult rb = drape(b, "yield, threshold 3");
  EXPECT_EQ(max_distance_mm(ra.mesh.positions, rb.mesh.positions), 0.0);
  EXPECT_EQ(ra.report.iterations, rb.report.iterations);
}

}  // namespace
}  // namespace drapegen::sim
