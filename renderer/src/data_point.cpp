#include "drapegen/renderer/data_point.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace drapegen::renderer {

sim::Status check_in_view(const TriangleMesh& cloth, const RigSpec& rig, const std::vector<DataPointSetup>& setups) {
  // Inside the facets (the polygon's inscribed circle) and between the bottom and the top: the cylinder is convex, so
  // a mesh whose vertices are all there is wholly hidden in it.
  const double inner = rig.cylinder.radius * std::cos(M_PI / rig.cylinder.segments);
  const bool hidden = std::all_of(cloth.vertices.begin(), cloth.vertices.end(), [&](const Eigen::Vector3f& x) {
    return std::hypot(x.x(), x.y()) < inner && x.z() < 0.0f && x.z() > -rig.cylinder.height;
  });
  if (hidden && !cloth.vertices.empty()) {
    return sim::Error{fmt::format("mesh lies inside the platform (every vertex within {:.3g} m of its axis and below "
                                  "its top at z = 0): no camera sees it (is the drape in metres, over the platform?)",
                                  rig.cylinder.radius)};
  }
  const Camera camera = rig.camera();
  const double W = rig.width, H = rig.height;
  for (const auto& p : setups) {
    for (int view = 0; view < rig.views; ++view) {
      const Eigen::Isometry3d model = rig.table_pose(p.orientation, view);
      for (int i = 0; i < cloth.vertex_count(); ++i) {
        const auto uvz = camera.project(model * cloth.vertices[i].cast<double>());
        if (!uvz || (*uvz)[0] < -0.5 || (*uvz)[0] > W - 0.5 || (*uvz)[1] < -0.5 || (*uvz)[1] > H - 0.5) {
          const Eigen::Vector3f& x = cloth.vertices[i];
          return sim::Error{fmt::format(
              "mesh is out of the camera's view: vertex {} at ({:.3g}, {:.3g}, {:.3g}) m leaves the {}x{} image at "
              "table angle {:.1f} deg (is the drape in metres, centred on the platform at z = 0?)",
              i, x.x(), x.y(), x.z(), rig.width, rig.height,
              (p.orientation + view * 2 * M_PI / rig.views) * 180 / M_PI)};
        }
      }
    }
  }
  return {};
}

sim::Expected<std::vector<DataPointRecord>> render_data_points(Renderer& renderer, const TriangleMesh& cloth,
                                                               const RenderRequest& request,
                                                               std::vector<std::vector<DepthImage>>* clean) {
  if (sim::Status s = validate(cloth); !s) return s.error();
  const auto setups = plan_data_points(request.rig, request.augmentation, request.seed);
  if (sim::Status s = check_in_view(cloth, request.rig, setups); !s) return s.error();
  if (sim::Status s = renderer.set_scene(tester_scene(cloth, request.rig)); !s) return s.error();
  const std::string noise = request.noise.describe();
  std::vector<DataPointRecord> points;
  if (clean != nullptr) clean->clear();
  for (const auto& setup : setups) {
    DataPointRecord point;
    point.index = setup.index;
    point.orientation = setup.orientation;
    point.seed = setup.seed;
    point.noise = noise;
    point.source = request.source;
    if (clean != nullptr) clean->emplace_back();
    for (int v = 0; v < static_cast<int>(setup.views.size()); ++v) {
      const ViewSetup& view = setup.views[v];
      auto image = renderer.render(view.camera, view.model);
      if (!image) return image.error();
      ViewRecord r;
      r.noise_seed = setup.noise_seed(v);
      r.table_angle = view.table_angle;
      r.camera.intrinsics = view.camera.intrinsics;
      r.camera.world_to_camera = view.mesh_to_camera();
      r.depth = request.noise.any() ? request.noise.apply(*image, r.noise_seed) : *image;
      r.depth.incidence.clear();
      if (clean != nullptr) clean->back().push_back(std::move(*image));
      point.views.push_back(std::move(r));
    }
    points.push_back(std::move(point));
  }
  return points;
}

}  // namespace drapegen::renderer
