#pragma once
// A CPU depth rasteriser for small triangles (the drape: ~20,000 triangles of about one pixel each in a 240x180
// image), single-threaded, with the sampling rules of the OpenGL renderer: each pixel samples the scene at its
// centre, the nearest surface within the DepthRange wins. docs/RENDERER.md, "Software rasteriser".

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "drapegen/renderer/renderer.hpp"

namespace drapegen::renderer {

/// Coverage follows OpenGL's rules: a pixel is drawn where its centre is inside a triangle, a centre on an edge
/// shared by two triangles belongs to exactly one of them (top-left rule), zero-area triangles cover nothing,
/// triangles crossing the near plane are clipped to it. Depth is the perspective-correct interpolation of camera z
/// in double precision, the incidence cosine that of the triangle's plane. Back faces of closed surfaces
/// (TriangleMesh::closed_from) are skipped. Not thread-safe; one per thread.
class SoftwareRenderer final : public Renderer {
 public:
  explicit SoftwareRenderer(DepthRange range = {});

  [[nodiscard]] sim::Status set_scene(const TriangleMesh& mesh) override;
  [[nodiscard]] sim::Expected<DepthImage> render(
      const Camera& camera, const Eigen::Isometry3d& model = Eigen::Isometry3d::Identity()) override;
  [[nodiscard]] std::string name() const override;

  /// A vertex in the image: position (u, v) snapped to 1/256 px (for coverage) and exact (for depth), 1 / camera z,
  /// and whether it lies outside the volume drawn directly (behind the near plane or far outside the image).
  struct ImagePoint {
    std::int64_t u = 0, v = 0;
    double exact_u = 0.0, exact_v = 0.0, inverse_z = 0.0;
    bool clipped = false;
  };

  /// Pixel centres of the image (integer u, v) in a range, empty if lo > hi: for a vertex, those at or next to it;
  /// for a triangle, those in its bounding box (the smallest lo and largest hi of its vertices).
  struct Centres {
    int lo_u = 0, hi_u = -1, lo_v = 0, hi_v = -1;
    [[nodiscard]] bool empty() const { return (lo_u > hi_u) | (lo_v > hi_v); }
  };

 private:
  DepthRange range_;
  TriangleMesh scene_;
  // Per vertex, in the current view: camera-space position, and its image point.
  std::vector<Eigen::Vector3d> eye_;
  std::vector<ImagePoint> points_;
  std::vector<Centres> centres_;
  struct Candidate {
    int id;
    Centres box;
  };
  std::vector<Candidate> candidates_;  // the triangles of the current view with a pixel centre in their box
  std::vector<int> triangle_of_;  // per pixel: the triangle seen
};

}  // namespace drapegen::renderer
