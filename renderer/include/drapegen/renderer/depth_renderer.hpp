#pragma once
// Headless OpenGL depth rendering through OSMesa (Mesa's off-screen driver, llvmpipe on the CPU: no display, no GPU).

#include <Eigen/Geometry>
#include <memory>
#include <string>

#include "drapegen/renderer/renderer.hpp"

namespace drapegen::renderer {

struct RendererOptions {
  /// Clipping planes, metres from the camera. Geometry outside [near, far] is not drawn.
  DepthRange range;
  /// llvmpipe rasteriser threads (the LP_NUM_THREADS environment variable, which Mesa reads once per process when
  /// the first context is made; set here only if the environment does not set it). 0 renders in the calling
  /// thread, the right choice for one worker process per core. Negative: leave Mesa's default (one per CPU).
  int threads = 0;
  /// Before each draw, project the scene on the CPU and leave out the triangles whose screen bounding box contains
  /// no pixel centre of the image: under OpenGL's rasterisation rules they produce no fragment, so the image is the
  /// same bit for bit (tested) and llvmpipe skips their setup. false: draw every triangle.
  bool skip_empty_triangles = true;
};

/// One OpenGL 3.3 core context with a float framebuffer, reused across renders: upload a scene once with
/// set_scene, then render it from any number of cameras and model poses. Not thread-safe; one renderer per thread
/// (it makes its context current on the calling thread at every call).
class DepthRenderer final : public Renderer {
 public:
  /// Creates the context and compiles the shaders. Fails with a message when OSMesa cannot give a 3.3 context.
  [[nodiscard]] static sim::Expected<DepthRenderer> create(const RendererOptions& options = {});

  DepthRenderer(DepthRenderer&&) noexcept;
  DepthRenderer& operator=(DepthRenderer&&) noexcept;
  ~DepthRenderer();

  [[nodiscard]] sim::Status set_scene(const TriangleMesh& mesh) override;
  [[nodiscard]] sim::Expected<DepthImage> render(
      const Camera& camera, const Eigen::Isometry3d& model = Eigen::Isometry3d::Identity()) override;
  /// GL_RENDERER of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
  [[nodiscard]] std::string name() const override;

 private:
  struct Impl;
  explicit DepthRenderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace drapegen::renderer
