#pragma once
// A CPU ray caster (bounding-volume hierarchy, Moeller-Trumbore in double precision): the independent reference
// the OpenGL renderer is checked against. Slow (tens of ms per 240x180 image); not for production.

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "drapegen/renderer/camera.hpp"
#include "drapegen/renderer/depth_image.hpp"
#include "drapegen/renderer/scene.hpp"

namespace drapegen::renderer {

class RayCaster {
 public:
  explicit RayCaster(const TriangleMesh& mesh);

  struct Hit {
    double t = 0.0;      // ray parameter: the hit is origin + t * direction
    int triangle = -1;
    Eigen::Vector3d normal;  // unit geometric normal of the triangle
  };
  /// The nearest hit with t > t_min, if any.
  [[nodiscard]] std::optional<Hit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                             double t_min = 0.0) const;

  /// The depth image that DepthRenderer::render(camera, model) should produce: one ray through each pixel centre.
  [[nodiscard]] DepthImage render(const Camera& camera,
                                  const Eigen::Isometry3d& model = Eigen::Isometry3d::Identity()) const;

 private:
  struct Node {
    Eigen::Vector3d lo, hi;
    // Leaf: triangles order_[first, first + count); inner: count == 0, children first, first+1.
    int first = 0, count = 0;
  };
  std::vector<Eigen::Vector3d> a_, b_, c_;  // triangle corners
  std::vector<int> order_;
  std::vector<Node> nodes_;
  int build(int first, int count);
};

}  // namespace drapegen::renderer
