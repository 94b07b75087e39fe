#include "drapegen/sim/mesh.hpp"

#include <algorithm>
#include <map>
#include <Eigen/LU>
#include <stdexcept>
#include <utility>

namespace drapegen::sim {

Topology build_topology(const ClothMesh& mesh) {
  const int nv = mesh.vertex_count();
  Topology topo;
  topo.on_boundary.assign(nv, false);
  topo.vertex_triangles.resize(nv);
  topo.vertex_neighbours.resize(nv);

  // Directed half-edge (a, b) -> (triangle, opposite vertex).
  std::map<std::pair<int, int>, std::pair<int, int>> half_edges;
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles(k, t), b = mesh.triangles((k + 1) % 3, t), c = mesh.triangles((k + 2) % 3, t);
      if (!half_edges.emplace(std::make_pair(a, b), std::make_pair(t, c)).second) {
        throw std::invalid_argument("build_topology: non-manifold or inconsistently oriented mesh");
      }
      topo.vertex_triangles[a].push_back(t);
    }
  }
  for (const auto& [edge, tri_opposite] : half_edges) {
    const auto [a, b] = edge;
    const auto twin = half_edges.find({b, a});
    if (twin == half_edges.end()) {
      topo.boundary_edges.emplace_back(a, b);
      topo.on_boundary[a] = topo.on_boundary[b] = true;
      topo.edges.emplace_back(std::min(a, b), std::max(a, b));
    } else if (a < b) {
      topo.edges.emplace_back(a, b);
      topo.hinges.push_back(Hinge{a, b, tri_opposite.second, twin->second.second});
    }
  }
  for (const auto& e : topo.edges) {
    topo.vertex_neighbours[e[0]].push_back(e[1]);
    topo.vertex_neighbours[e[1]].push_back(e[0]);
  }
  for (auto& n : topo.vertex_neighbours) std::sort(n.begin(), n.end());
  return topo;
}

RestTriangle rest_triangle(const ClothMesh& mesh, int triangle) {
  Eigen::Matrix2d dm;
  dm.col(0) = mesh.rest.col(mesh.triangles(1, triangle)) - mesh.rest.col(mesh.triangles(0, triangle));
  dm.col(1) = mesh.rest.col(mesh.triangles(2, triangle)) - mesh.rest.col(mesh.triangles(0, triangle));
  const double det = dm.determinant();
  if (!(det > 0.0)) throw std::invalid_argument("degenerate or inverted rest triangle");
  RestTriangle rest;
  rest.inverse = dm.inverse();
  rest.gradients.row(1) = rest.inverse.row(0);
  rest.gradients.row(2) = rest.inverse.row(1);
  rest.gradients.row(0) = -(rest.gradients.row(1) + rest.gradients.row(2));
  rest.area = 0.5 * det;
  return rest;
}

Eigen::VectorXd rest_triangle_areas(const ClothMesh& mesh) {
  Eigen::VectorXd areas(mesh.triangle_count());
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    const Eigen::Vector2d a = mesh.rest.col(mesh.triangles(0, t));
    const Eigen::Vector2d e1 = mesh.rest.col(mesh.triangles(1, t)) - a;
    const Eigen::Vector2d e2 = mesh.rest.col(mesh.triangles(2, t)) - a;
    areas[t] = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  }
  return areas;
}

Eigen::VectorXd rest_vertex_areas(const ClothMesh& mesh) {
  const Eigen::VectorXd tri = rest_triangle_areas(mesh);
  Eigen::VectorXd areas = Eigen::VectorXd::Zero(mesh.vertex_count());
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) areas[mesh.triangles(k, t)] += tri[t] / 3.0;
  }
  return areas;
}

}  // namespace drapegen::sim
