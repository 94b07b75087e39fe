#include "drapegen/renderer/scene.hpp"

#include <cmath>
#include <fmt/format.h>

namespace drapegen::renderer {

void TriangleMesh::append(const TriangleMesh& other) {
  const int offset = vertex_count();
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  triangles.reserve(triangles.size() + other.triangles.size());
  const int first = triangle_count();
  for (const auto& t : other.triangles) triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  closed_from = other.closed_from >= 0 ? first + other.closed_from : -1;
}

TriangleMesh make_cylinder(const CylinderSpec& spec) {
  TriangleMesh m;
  const int n = spec.segments;
  // Top ring 0..n-1, bottom ring n..2n-1, top centre 2n, bottom centre 2n+1.
  for (int ring = 0; ring < 2; ++ring) {
    const float z = ring == 0 ? 0.0f : static_cast<float>(-spec.height);
    for (int i = 0; i < n; ++i) {
      const double a = 2.0 * M_PI * i / n;
      m.vertices.emplace_back(static_cast<float>(spec.radius * std::cos(a)),
                              static_cast<float>(spec.radius * std::sin(a)), z);
    }
  }
  m.vertices.emplace_back(0.0f, 0.0f, 0.0f);
  m.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(-spec.height));
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.triangles.push_back({i, n + i, n + j});
    m.triangles.push_back({i, n + j, j});
    m.triangles.push_back({2 * n, i, j});
    m.triangles.push_back({2 * n + 1, n + j, n + i});
  }
  m.closed_from = 0;
  return m;
}

sim::Status validate(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) return sim::Error{"mesh has no triangles"};
  if (mesh.closed_from < -1 || mesh.closed_from > mesh.triangle_count()) {
    return sim::Error{fmt::format("closed triangles from {} of {}", mesh.closed_from, mesh.triangle_count())};
  }
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    if (!mesh.vertices[i].allFinite()) return sim::Error{fmt::format("mesh vertex {} is not finite", i)};
  }
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    for (int k : mesh.triangles[t]) {
      if (k < 0 || k >= mesh.vertex_count()) {
        return sim::Error{fmt::format("mesh triangle {} uses vertex {} of {}", t, k, mesh.vertex_count())};
      }
    }
  }
  return {};
}

sim::Expected<TriangleMesh> cloth_triangles(const sim::ClothMesh& mesh) {
  if (mesh.positions.cols() == 0 || mesh.triangles.cols() == 0) return sim::Error{"mesh is empty"};
  TriangleMesh m;
  m.vertices.reserve(mesh.positions.cols());
  for (Eigen::Index i = 0; i < mesh.positions.cols(); ++i) {
    const Eigen::Vector3d p = mesh.positions.col(i);
    if (!p.allFinite()) return sim::Error{fmt::format("mesh vertex {} is not finite", i)};
    m.vertices.push_back(p.cast<float>());
  }
  m.triangles.reserve(mesh.triangles.cols());
  for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) {
    m.triangles.push_back({mesh.triangles(0, t), mesh.triangles(1, t), mesh.triangles(2, t)});
  }
  if (sim::Status s = validate(m); !s) return s.error();
  return m;
}

}  // namespace drapegen::renderer
