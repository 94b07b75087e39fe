#pragma once
// The cloth mesh: material (rest) coordinates, triangles and current world positions.

#include <Eigen/Core>
#include <vector>

namespace drapegen::sim {

/// A triangle mesh of a flat specimen. Units are SI (metres).
///
/// `rest` holds the planar reference coordinates of every vertex in the specimen frame (x along the specimen's
/// first edge, y along its second, origin at the specimen centre). `positions` holds the current world
/// positions (z up; the platform top is z = 0). Triangles are counter-clockwise in the rest frame.
struct ClothMesh {
  Eigen::Matrix2Xd rest;
  Eigen::Matrix3Xi triangles;
  Eigen::Matrix3Xd positions;

  /// The warp direction's angle in the rest frame, radians (0: warp along rest x, weft along rest y).
  double material_angle = 0.0;

  [[nodiscard]] int vertex_count() const { return static_cast<int>(rest.cols()); }
  [[nodiscard]] int triangle_count() const { return static_cast<int>(triangles.cols()); }
};

/// A bending element: two triangles sharing the edge (v0, v1); v2 lies in the first triangle (v0, v1, v2, which is
/// counter-clockwise in the rest frame), v3 in the second (v1, v0, v3).
struct Hinge {
  int v0 = 0, v1 = 0, v2 = 0, v3 = 0;
};

/// Connectivity derived once from the triangles.
struct Topology {
  std::vector<Eigen::Vector2i> edges;            // unique undirected edges (a < b)
  std::vector<Hinge> hinges;                     // one per interior edge
  std::vector<Eigen::Vector2i> boundary_edges;   // directed counter-clockwise along the boundary
  std::vector<bool> on_boundary;                 // per vertex
  std::vector<std::vector<int>> vertex_triangles;  // incident triangles per vertex
  std::vector<std::vector<int>> vertex_neighbours; // adjacent vertices per vertex
};

/// Builds the topology. The mesh must be a manifold (every edge shared by at most two triangles).
[[nodiscard]] Topology build_topology(const ClothMesh& mesh);

/// A rest triangle's linear shape functions: `gradients` row k is the rest-frame gradient of vertex k's barycentric
/// coordinate (so the deformation gradient is F = sum_k x_k gradients.row(k)), `inverse` is Dm^-1 for the edge matrix
/// Dm = [r1 - r0, r2 - r0], `area` the rest area. Throws std::invalid_argument for a degenerate or inverted triangle.
struct RestTriangle {
  Eigen::Matrix<double, 3, 2> gradients;
  Eigen::Matrix2d inverse;
  double area = 0.0;
};
[[nodiscard]] RestTriangle rest_triangle(const ClothMesh& mesh, int triangle);

/// Rest area of every triangle (m^2).
[[nodiscard]] Eigen::VectorXd rest_triangle_areas(const ClothMesh& mesh);

/// Lumped rest area per vertex: a third of every incident triangle (m^2).
[[nodiscard]] Eigen::VectorXd rest_vertex_areas(const ClothMesh& mesh);

}  // namespace drapegen::sim
