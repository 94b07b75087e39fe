#pragma once
// One renderer of each kind per test program, created on first use (an OSMesa context is costly; tests reuse it),
// and the names of the kinds for tests run with every renderer.
#include <stdexcept>
#include <string>
#include <utility>

#include "drapegen/renderer/depth_renderer.hpp"
#include "drapegen/renderer/software_renderer.hpp"

namespace drapegen::renderer {

inline DepthRenderer& shared_renderer() {
  static DepthRenderer renderer = [] {
    auto r = DepthRenderer::create();
    if (!r) throw std::runtime_error(r.error().message);
    return std::move(*r);
  }();
  return renderer;
}

/// "osmesa" (shared_renderer()) or "software" (a SoftwareRenderer).
inline Renderer& shared_renderer(const std::string& kind) {
  static SoftwareRenderer software;
  if (kind == "software") return software;
  if (kind == "osmesa") return shared_renderer();
  throw std::invalid_argument("unknown renderer " + kind);
}

inline const char* const kRendererKinds[] = {"osmesa", "software"};

}  // namespace drapegen::renderer
