#pragma once
// Geometric measures of a draped specimen hanging from a circular platform of radius R centred on the z axis.
//
// The "shadow" of a mesh is the union of its triangles projected onto the xy plane (a vertical view from above).
// All functions take world positions in metres, require finite positions (below 1e100 m, so that squares cannot
// overflow) and triangle indices in range, and throw std::invalid_argument otherwise or on invalid parameters (as
// make_specimen does): these are programming errors, not data errors, since read_ply already rejects bad files.

#include <vector>

#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

/// Area (m^2) of the shadow: the union of the projected triangles, so overlapping folds count once.
///
/// The bounding box of all positions is covered by square cells of side `pixel` starting at its lower-left corner;
/// a cell counts when its centre lies in a (closed) projected triangle. The error is at most about the shadow's
/// perimeter times `pixel` and usually far smaller, since boundary cells err both ways. Triangles seen edge-on (zero
/// projected area) add nothing. Rows are swept with the triangles crossing them, merging their cell ranges: cost
/// O(triangle rows + rows * log), memory O(triangles); no raster is stored. More than 2^22 cells a side is refused.
[[nodiscard]] double projected_area(const ClothMesh& mesh, double pixel = 0.5e-3);

/// Cusick's drape coefficient (projected_area - pi R^2) / (rest area - pi R^2): 1 for a specimen that stays flat,
/// towards 0 for one that hangs straight down. The rest area is the total area of the rest triangles. Requires
/// 0 <= R and pi R^2 < rest area.
[[nodiscard]] double drape_coefficient(const ClothMesh& mesh, double platform_radius, double pixel = 0.5e-3);

/// The hem profile: for each of `bins` azimuth bins, bin b covering the azimuth [2 pi b / bins, 2 pi (b+1) / bins)
/// counter-clockwise from +x, the largest distance from the z axis of any shadow point in that (closed) wedge.
///
/// Exact, without rasterising: the farthest point of a convex polygon (a projected triangle) clipped to a wedge is a
/// vertex of the clipped polygon, i.e. one of its vertices inside the wedge or the crossing of one of its edges with
/// one of the wedge's two bounding rays. So the profile is the maximum over all vertices and all triangle-edge /
/// bin-ray crossings, O(vertices + edges * bins crossed). It follows folds that stick out beyond the hem as well.
/// Bins that the shadow does not reach (only if it does not cover the axis) hold 0. Requires bins >= 1.
[[nodiscard]] std::vector<double> hem_profile(const ClothMesh& mesh, int bins = 360);

/// The number of nodes (folds) of a circular hem profile, as from hem_profile.
///
/// The profile is first smoothed circularly with a Gaussian of standard deviation 2 degrees (bins / 180 bins; none
/// below 45 bins), then its circular local maxima (a plateau counts once) with a topographic prominence of at least
/// `min_prominence` metres are counted. The prominence of a peak is its height above the higher of the two lowest
/// points met walking round the circle in each direction until a strictly higher value; the highest peak's is its
/// height above the profile's minimum. A constant profile has no folds; a flat square specimen has 4 (its corners);
/// r0 + a cos(k psi) has k when 2a (times the smoothing's attenuation, 0.92 for k = 12) reaches `min_prominence`.
[[nodiscard]] int count_folds(const std::vector<double>& profile, double min_prominence = 2e-3);

/// The number of unordered pairs of triangles that share no vertex index and intersect, as closed sets: touching
/// counts, and so does overlap within a common plane.
///
/// Each pair is decided by testing the edges of each triangle against the other. A point within about 1e-9 of a
/// triangle's size from its plane counts as on the plane (so a flat sheet stays flat after rounding, whatever its
/// orientation); edges in the plane or ending on it are tested in 2D within it, edges clearly crossing it by the
/// signs of three volumes. Orientation signs use Shewchuk's error bounds and take 0 when rounding could flip them.
/// Triangles with (numerically) zero area, |cross product| <= 1e-6 longest edge^2, take part through their edges
/// only; two such never count. Candidate pairs come from a uniform grid with cells the size of the mean triangle,
/// each pair examined in one cell only, so the cost is about linear in the mesh size for cloth-like meshes.
/// Pairs that share a vertex are never counted, even if they also cross elsewhere; coincident but distinct
/// vertices are not shared.
[[nodiscard]] int count_self_intersections(const ClothMesh& mesh);

/// Whether the specimen lies turned over (its back face up): the projection of its triangles onto the xy plane,
/// counted with their orientation, covers a negative area. The rest triangles are counter-clockwise seen from +z, and
/// the signed sum is the cloth's area facing up less its area facing down, seen from above (by Green's theorem, the
/// area the projected boundary encloses, counted with its winding). A drape's folds turn small parts of it; a fold
/// that lays most of the cloth back over the rest turns the specimen. A sum of exactly 0 reads as face up.
[[nodiscard]] bool lies_face_down(const ClothMesh& mesh);

}  // namespace drapegen::sim
