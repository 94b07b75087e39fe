#include "drapegen/sim/mesh_transfer.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace drapegen::sim {

Eigen::Matrix3Xd transfer_positions(const ClothMesh& from, const Eigen::Matrix2Xd& rest_points) {
  // Bucket the source triangles by their rest bounding boxes on a uniform grid of about one triangle per cell.
  const Eigen::Vector2d lo = from.rest.rowwise().minCoeff(), hi = from.rest.rowwise().maxCoeff();
  const int cells = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(from.triangle_count()))));
  const Eigen::Vector2d size = (hi - lo).cwiseMax(1e-12) / cells;
  auto cell_of = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d c = ((p - lo).array() / size.array()).floor().matrix();
    return Eigen::Vector2i(std::clamp(static_cast<int>(c.x()), 0, cells - 1),
                           std::clamp(static_cast<int>(c.y()), 0, cells - 1));
  };
  std::vector<std::vector<int>> bucket(static_cast<std::size_t>(cells) * cells);
  for (int t = 0; t < from.triangle_count(); ++t) {
    Eigen::Vector2d bmin = from.rest.col(from.triangles(0, t)), bmax = bmin;
    for (int k = 1; k < 3; ++k) {
      bmin = bmin.cwiseMin(from.rest.col(from.triangles(k, t)));
      bmax = bmax.cwiseMax(from.rest.col(from.triangles(k, t)));
    }
    const Eigen::Vector2i a = cell_of(bmin), b = cell_of(bmax);
    for (int j = a.y(); j <= b.y(); ++j)
      for (int i = a.x(); i <= b.x(); ++i) bucket[static_cast<std::size_t>(j) * cells + i].push_back(t);
  }
  auto barycentric = [&](int t, const Eigen::Vector2d& p) {
    const Eigen::Vector2d a = from.rest.col(from.triangles(0, t));
    Eigen::Matrix2d m;
    m.col(0) = from.rest.col(from.triangles(1, t)) - a;
    m.col(1) = from.rest.col(from.triangles(2, t)) - a;
    const Eigen::Vector2d uv = m.inverse() * (p - a);
    return Eigen::Vector3d(1.0 - uv.x() - uv.y(), uv.x(), uv.y());
  };
  Eigen::Matrix3Xd out(3, rest_points.cols());
  for (Eigen::Index v = 0; v < rest_points.cols(); ++v) {
    const Eigen::Vector2d p = rest_points.col(v);
    int best = -1;
    double best_outside = std::numeric_limits<double>::infinity();
    Eigen::Vector3d best_w;
    // Search the point's cell, widening to the neighbours if nothing contains it.
    for (int ring = 0; ring <= 1 && best_outside > 0.0; ++ring) {
      const Eigen::Vector2i c = cell_of(p);
      for (int j = std::max(0, c.y() - ring); j <= std::min(cells - 1, c.y() + ring); ++j) {
        for (int i = std::max(0, c.x() - ring); i <= std::min(cells - 1, c.x() + ring); ++i) {
          for (int t : bucket[static_cast<std::size_t>(j) * cells + i]) {
            const Eigen::Vector3d w = barycentric(t, p);
            const double outside = -std::min(0.0, w.minCoeff());
            if (outside < best_outside) {
              best_outside = outside;
              best = t;
              best_w = w;
            }
          }
        }
      }
    }
    // Clamp to the triangle so that points off the source's border are not extrapolated.
    best_w = best_w.cwiseMax(0.0);
    best_w /= best_w.sum();
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) x += best_w[k] * from.positions.col(from.triangles(k, best));
    out.col(v) = x;
  }
  return out;
}

}  // namespace drapegen::sim
