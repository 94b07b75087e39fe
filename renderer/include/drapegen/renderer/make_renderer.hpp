#pragma once
// Choosing a renderer by name (the --renderer option of drapegen render and the renderer benchmark).

#include <memory>
#include <string>
#include <vector>

#include "drapegen/renderer/depth_renderer.hpp"
#include "drapegen/renderer/renderer.hpp"

namespace drapegen::renderer {

/// "osmesa": DepthRenderer with `osmesa` options, the default (OpenGL through OSMesa); "software": SoftwareRenderer,
/// the faster CPU rasteriser (docs/RENDERER.md, "Software rasteriser"). Fails on another name or when OSMesa gives no
/// context.
[[nodiscard]] sim::Expected<std::unique_ptr<Renderer>> make_renderer(const std::string& name,
                                                                     const RendererOptions& osmesa = {});

/// The names make_renderer() accepts, the default first.
inline const std::vector<std::string> kRendererNames = {"osmesa", "software"};

}  // namespace drapegen::renderer
