#include "drapegen/renderer/make_renderer.hpp"

#include <fmt/format.h>

#include "drapegen/renderer/software_renderer.hpp"

namespace drapegen::renderer {

sim::Expected<std::unique_ptr<Renderer>> make_renderer(const std::string& name, const RendererOptions& osmesa) {
  if (name == "software") return std::unique_ptr<Renderer>(std::make_unique<SoftwareRenderer>(osmesa.range));
  if (name == "osmesa") {
    auto created = DepthRenderer::create(osmesa);
    if (!created) return created.error();
    return std::unique_ptr<Renderer>(std::make_unique<DepthRenderer>(std::move(created).value()));
  }
  return sim::Error{fmt::format("unknown renderer '{}' (osmesa or software)", name)};
}

}  // namespace drapegen::renderer
