#pragma once
// Anisotropic bending (Feng et al. 2022, Section 4.4): interpolation of bending parameters between the warp, bias
// and weft sample directions (Eq. 8), and the bending direction of every hinge, either from principal curvature
// directions measured in the material frame (the curvature-based rule) or from the rest edge (the edge-based rule).

#include <Eigen/Core>

#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

/// A material property sampled in the three directions of the paper: warp (phi = 0), bias (phi = pi/4) and weft
/// (phi = pi/2). The members may hold any scalar bending parameter (alpha, beta or gamma).
struct DirectionalValues {
  double warp = 0.0;
  double bias = 0.0;
  double weft = 0.0;
};

/// Eq. 8: the value in bending direction `phi` (radians from the warp direction, any value). Between two sample
/// directions phi0 < phi1 the value is [cos^2 phi, sin^2 phi] M^-1 [k(phi0); k(phi1)] with
/// M = [[cos^2 phi0, sin^2 phi0], [cos^2 phi1, sin^2 phi1]], using the symmetry k(phi) = k(-phi) = k(pi - phi).
/// Exact at the three samples, continuous everywhere, and equal to Eq. 7 (cos^2 warp + sin^2 weft) whenever
/// bias = (warp + weft) / 2.
[[nodiscard]] double interpolate_directional(const DirectionalValues& k, double phi);

/// How the bending direction of a hinge is chosen.
enum class AnisotropyRule {
  kCurvature,  // mean greater principal curvature direction at the hinge's edge vertices (paper, Fig. 12c/d)
  kEdge,       // rest direction perpendicular to the hinge edge (mesh-dependent, Fig. 12a/b)
};

/// Principal curvatures per vertex. Directions are unit vectors in the rest (material) frame and are axes: d and -d
/// are the same direction. Curvatures are signed, in 1/m, positive where the surface bends towards its normal
/// (the normal of the counter-clockwise rest triangles; +z for a flat specimen, so a bowl is positive).
struct CurvatureField {
  Eigen::Matrix2Xd direction;      // direction of the principal curvature of largest magnitude
  Eigen::VectorXd max_curvature;   // signed curvature along `direction` (largest magnitude)
  Eigen::VectorXd min_curvature;   // signed curvature along the perpendicular direction
};

/// Scratch storage of principal_curvatures; reuse it between calls to avoid reallocation.
struct CurvatureWorkspace {
  Eigen::Matrix3Xd vertex_normals;
  Eigen::Matrix<double, 20, Eigen::Dynamic> systems;  // per vertex: 1-ring normal equations incl. tilt (15 + 5)
  Eigen::Matrix<double, 9, Eigen::Dynamic> reduced;   // per vertex: the same with the tilt eliminated (6 + 3)
};

/// Estimates the curvature tensor of every vertex in material coordinates (Meyer et al. 2003, fitted in the rest
/// frame). Each incident edge ij gives a normal-curvature sample kappa_ij = 2 (x_j - x_i).n_i / |x_j - x_i|^2 along
/// its rest direction D_ij, and the symmetric 2x2 tensor B is fitted to D^T B D ~ kappa in weighted least squares
/// (weight: half the rest area of each incident triangle per edge). Two refinements make the estimate mesh
/// independent:
///  * the vertex normal is only an estimate; a tilt error e adds 2 e.(x_j - x_i) / |x_j - x_i|^2 to every sample,
///    which is O(|B|) on irregular meshes. Each vertex therefore also fits a tilt term 2 g.(X_j - X_i) /
///    |x_j - x_i|^2 and eliminates it (Schur complement), keeping only the information about B that does not
///    depend on the normal;
///  * a vertex's 1-ring may not determine all of B (a valence-4 grid vertex sees only two axes; a boundary vertex
///    or a corner sees a half or quarter fan), so the reduced normal equations of the vertex and of its neighbours
///    are summed before solving. This smooths the field over about two edge lengths.
/// Boundary vertices need no special case: the tilt term absorbs the bias of their one-sided normals and pooling
/// supplies the directions their fan lacks. Components that remain unobserved are ridge-regularised towards zero
/// (a flat or degenerate neighbourhood gives B = 0). On a stretched mesh B measures the world normal curvature along
/// the image F D of each rest direction D.
[[nodiscard]] CurvatureField principal_curvatures(const ClothMesh& mesh, const Topology& topo);

/// As above, writing into `field` and using `workspace`; allocates nothing when the sizes are unchanged.
void principal_curvatures(const ClothMesh& mesh, const Topology& topo, CurvatureWorkspace& workspace,
                          CurvatureField& field);

/// Settings of hinge_bending_angles.
struct AnisotropyOptions {
  /// Curvature anisotropy (1/m) above which the curvature rule is used unmodified. A vertex's anisotropy is
  /// |max_curvature| - |min_curvature|: the confidence in its greater principal direction (zero where the surface
  /// is flat, spherical or a symmetric saddle). Where the mean anisotropy a of a hinge's two edge vertices is below
  /// this value, the direction blends smoothly into the edge rule with weight 1 - smoothstep(a / flat_curvature),
  /// so flat regions get a stable, continuous direction instead of noise.
  double flat_curvature = 2.0;
};

/// Scratch storage of hinge_bending_angles. After a kCurvature call `field` holds the vertex curvatures.
struct AnisotropyWorkspace {
  CurvatureWorkspace curvature;
  CurvatureField field;
};

/// The bending direction of every hinge as an angle relative to the warp direction, in [0, pi), one per
/// topo.hinges entry. kEdge: the rest direction perpendicular to the hinge edge. kCurvature: the mean of the
/// greater principal directions at the edge vertices v0 and v1 (signs aligned, weighted by their anisotropy),
/// blended into the edge rule in flat regions (see AnisotropyOptions).
void hinge_bending_angles(const ClothMesh& mesh, const Topology& topo, AnisotropyRule rule,
                          Eigen::VectorXd& phi_out);

/// As above with explicit options and reusable scratch storage (no allocation when the sizes are unchanged).
void hinge_bending_angles(const ClothMesh& mesh, const Topology& topo, AnisotropyRule rule,
                          const AnisotropyOptions& options, AnisotropyWorkspace& workspace,
                          Eigen::VectorXd& phi_out);

}  // namespace drapegen::sim
