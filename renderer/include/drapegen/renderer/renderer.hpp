#pragma once
// What every depth renderer offers: upload a scene once, then render it from any number of cameras and model poses.
// Implementations: DepthRenderer (OpenGL through OSMesa) and SoftwareRenderer (a CPU rasteriser); RayCaster is the
// independent reference both are tested against.

#include <Eigen/Geometry>
#include <string>

#include "drapegen/renderer/camera.hpp"
#include "drapegen/renderer/depth_image.hpp"
#include "drapegen/renderer/scene.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::renderer {

/// The camera-space depths drawn, metres from the camera (OpenGL's clipping planes): nearer or farther geometry is
/// not drawn.
struct DepthRange {
  double near = 0.05;
  double far = 10.0;
};

class Renderer {
 public:
  virtual ~Renderer() = default;

  /// Uploads the triangles to draw (replacing any earlier scene). Fails on an invalid mesh (see validate()).
  [[nodiscard]] virtual sim::Status set_scene(const TriangleMesh& mesh) = 0;

  /// Renders the scene, placed in the world by `model` (e.g. the rotary table's turn), seen by `camera`: linear
  /// camera-space z per pixel (0 where nothing is hit) and the cosine of the incidence angle. Pixel (u, v) samples
  /// the scene at its centre, as Camera::ray(u, v) does; only geometry within the renderer's DepthRange is drawn.
  [[nodiscard]] virtual sim::Expected<DepthImage> render(
      const Camera& camera, const Eigen::Isometry3d& model = Eigen::Isometry3d::Identity()) = 0;

  /// What renders: "drapegen software rasteriser", or OpenGL's renderer string such as "llvmpipe (LLVM 15.0.6, 256
  /// bits)" (in drapegen render's JSON summary).
  [[nodiscard]] virtual std::string name() const = 0;

 protected:
  Renderer() = default;
  Renderer(const Renderer&) = default;
  Renderer(Renderer&&) noexcept = default;
  Renderer& operator=(const Renderer&) = default;
  Renderer& operator=(Renderer&&) noexcept = default;
};

/// What every render() checks first: an image size of 1..8192 px per side and finite intrinsics and poses.
[[nodiscard]] sim::Status check_view(const Camera& camera, const Eigen::Isometry3d& model);

}  // namespace drapegen::renderer
