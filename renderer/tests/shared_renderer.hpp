#pragma once
// One OSMesa renderer per test program, created on first use (a context is costly; tests reuse it).
#include <stdexcept>
#include <utility>

#include "drapegen/renderer/depth_renderer.hpp"

namespace drapegen::renderer {

inline DepthRenderer& shared_renderer() {
  static DepthRenderer renderer = [] {
    auto r = DepthRenderer::create();
    if (!r) throw std::runtime_error(r.error().message);
    return std::move(*r);
  }();
  return renderer;
}

}  // namespace drapegen::renderer
