#include "drapegen/renderer/ray_caster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drapegen::renderer {

RayCaster::RayCaster(const TriangleMesh& mesh) {
  const int n = mesh.triangle_count();
  a_.reserve(n);
  b_.reserve(n);
  c_.reserve(n);
  for (const auto& t : mesh.triangles) {
    a_.push_back(mesh.vertices[t[0]].cast<double>());
    b_.push_back(mesh.vertices[t[1]].cast<double>());
    c_.push_back(mesh.vertices[t[2]].cast<double>());
  }
  order_.resize(n);
  for (int i = 0; i < n; ++i) order_[i] = i;
  nodes_.reserve(2 * static_cast<std::size_t>(n) + 1);
  if (n > 0) build(0, n);
}

int RayCaster::build(int first, int count) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back({});
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  Eigen::Vector3d clo = lo, chi = hi;  // bounds of the centroids
  for (int i = first; i < first + count; ++i) {
    const int t = order_[i];
    lo = lo.cwiseMin(a_[t]).cwiseMin(b_[t]).cwiseMin(c_[t]);
    hi = hi.cwiseMax(a_[t]).cwiseMax(b_[t]).cwiseMax(c_[t]);
    const Eigen::Vector3d centroid = (a_[t] + b_[t] + c_[t]) / 3.0;
    clo = clo.cwiseMin(centroid);
    chi = chi.cwiseMax(centroid);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  if (count <= 4 || chi[axis] - clo[axis] <= 0.0) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  // Median split along the widest axis of the centroids.
  const int half = count / 2;
  auto key = [&](int t) { return a_[t][axis] + b_[t][axis] + c_[t][axis]; };
  std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                   [&](int x, int y) { return key(x) < key(y); });
  build(first, half);  // the left child is node index + 1
  const int right = build(first + half, count - half);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

std::optional<RayCaster::Hit> RayCaster::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                                   double t_min) const {
  if (nodes_.empty()) return std::nullopt;
  const Eigen::Vector3d inv = direction.cwiseInverse();
  double best = std::numeric_limits<double>::infinity();
  int best_triangle = -1;
  auto box_hit = [&](const Node& node) {
    double t0 = t_min, t1 = best;
    for (int k = 0; k < 3; ++k) {
      double ta = (node.lo[k] - origin[k]) * inv[k];
      double tb = (node.hi[k] - origin[k]) * inv[k];
      if (std::isnan(ta) || std::isnan(tb)) {  // direction[k] == 0 and origin on the slab plane
        if (origin[k] < node.lo[k] || origin[k] > node.hi[k]) return false;
        continue;
      }
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    return true;
  };
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const int ni = stack[--top];
    const Node& node = nodes_[ni];
    if (!box_hit(node)) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const int t = order_[i];
        // Moeller-Trumbore.
        const Eigen::Vector3d e1 = b_[t] - a_[t], e2 = c_[t] - a_[t];
        const Eigen::Vector3d p = direction.cross(e2);
        const double det = e1.dot(p);
        if (det == 0.0) continue;
        const double inv_det = 1.0 / det;
        const Eigen::Vector3d s = origin - a_[t];
        const double u = s.dot(p) * inv_det;
        if (u < 0.0 || u > 1.0) continue;
        const Eigen::Vector3d q = s.cross(e1);
        const double v = direction.dot(q) * inv_det;
        if (v < 0.0 || u + v > 1.0) continue;
        const double tt = e2.dot(q) * inv_det;
        if (tt > t_min && tt < best) {
          best = tt;
          best_triangle = t;
        }
      }
    } else {
      if (top + 2 > 128) continue;  // cannot happen for a median-split tree of < 2^100 triangles
      stack[top++] = ni + 1;
      stack[top++] = node.first;
    }
  }
  if (best_triangle < 0) return std::nullopt;
  const int t = best_triangle;
  return Hit{best, t, (b_[t] - a_[t]).cross(c_[t] - a_[t]).normalized()};
}

DepthImage RayCaster::render(const Camera& camera, const Eigen::Isometry3d& model) const {
  const int W = camera.intrinsics.width, H = camera.intrinsics.height;
  DepthImage image(W, H);
  image.incidence.assign(image.depth.size(), 0.0f);
  // Rays in the mesh's own frame: the camera-space direction K^-1 (u, v, 1) has z = 1, so the ray parameter of a
  // hit is its camera depth (rigid transforms keep it).
  const Eigen::Isometry3d mesh_to_camera = camera.world_to_camera * model;
  const Eigen::Isometry3d camera_to_mesh = mesh_to_camera.inverse();
  const Eigen::Vector3d origin = camera_to_mesh.translation();
  const Eigen::Matrix3d Kinv = camera.intrinsics.K.inverse();
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const Eigen::Vector3d d_cam = Kinv * Eigen::Vector3d(u, v, 1.0);
      const Eigen::Vector3d d = camera_to_mesh.linear() * d_cam;
      if (const auto hit = intersect(origin, d)) {
        image.at(u, v) = static_cast<float>(hit->t);
        image.incidence[static_cast<std::size_t>(v) * W + u] =
            static_cast<float>(std::abs(hit->normal.dot(d)) / d.norm());
      }
    }
  }
  return image;
}

}  // namespace drapegen::renderer
