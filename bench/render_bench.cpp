// Renderer benchmark (docs/BENCHMARKS.md, docs/RENDERER.md): views per second on one core for a drape, split into
// render / noise / EXR encode; bytes per view and storage error for every EXR storage option; the cross-check of
// the renderer against the CPU ray cast.
//
//   drapegen_render_bench --mesh drape100.ply [--renderer osmesa|software] [--data-points 48] [--storage]
//                         [--crosscheck]
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>
#include <time.h>
#include <string>
#include <vector>

#include "drapegen/renderer/data_point.hpp"
#include "drapegen/renderer/make_renderer.hpp"
#include "drapegen/renderer/exr.hpp"
#include "drapegen/renderer/ray_caster.hpp"
#include "drapegen/sim/ply.hpp"

using namespace drapegen::renderer;
namespace sim = drapegen::sim;

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
/// CPU seconds of this process (all threads): on a shared machine, the honest measure of one core's work.
double cpu_now() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

template <class T>
T unwrap(sim::Expected<T> e) {
  if (!e) {
    fmt::print(stderr, "error: {}\n", e.error().message);
    std::exit(1);
  }
  return std::move(*e);
}

void timing(Renderer& renderer, const TriangleMesh& cloth, int data_points, const ExrStorage& storage) {
  RenderRequest request;
  request.augmentation.orientations = data_points;
  request.seed = 1;
  const auto setups = plan_data_points(request.rig, request.augmentation, request.seed);
  if (sim::Status s = renderer.set_scene(tester_scene(cloth, request.rig)); !s) std::exit(1);
  const ExrWriter writer(storage);
  // Warm-up (OSMesa: shader compilation, first framebuffer).
  (void)unwrap(renderer.render(setups[0].views[0].camera, setups[0].views[0].model));

  double t_render = 0, t_noise = 0, t_encode = 0;
  std::size_t bytes = 0;
  const double wall0 = now(), cpu0 = cpu_now();
  for (const auto& setup : setups) {
    DataPointRecord point;
    point.seed = setup.seed;
    point.noise = request.noise.describe();
    for (int v = 0; v < static_cast<int>(setup.views.size()); ++v) {
      const auto& view = setup.views[v];
      double t = cpu_now();
      DepthImage clean = unwrap(renderer.render(view.camera, view.model));
      t_render += cpu_now() - t;
      t = cpu_now();
      ViewRecord r;
      r.depth = request.noise.apply(clean, setup.noise_seed(v));
      t_noise += cpu_now() - t;
      r.camera.intrinsics = view.camera.intrinsics;
      r.camera.world_to_camera = view.mesh_to_camera();
      r.noise_seed = setup.noise_seed(v);
      r.table_angle = view.table_angle;
      point.views.push_back(std::move(r));
    }
    const double t = cpu_now();
    bytes += unwrap(writer.encode(point)).size();
    t_encode += cpu_now() - t;
  }
  const double wall = now() - wall0, cpu = cpu_now() - cpu0;
  const int views = data_points * request.rig.views;
  fmt::print("timing: {} data points x {} views, {} triangles (cloth + cylinder), storage {} {} (zip level {})\n",
             data_points, request.rig.views, tester_scene(cloth, request.rig).triangle_count(),
             storage.pixel == ExrStorage::Pixel::kHalf ? "half" : "float", storage.compression, storage.zip_level);
  fmt::print("  CPU time: render {:.3f} ms/view, noise {:.3f} ms/view, EXR encode {:.3f} ms/view\n",
             1e3 * t_render / views, 1e3 * t_noise / views, 1e3 * t_encode / views);
  // Per core = per CPU-second of this (single-threaded) process; wall time also counts waiting for a shared core.
  fmt::print(
      "  total {:.3f} ms/view CPU ({:.3f} ms/view wall) -> {:.0f} views per CPU-second ({:.0f} per wall-second)\n",
      1e3 * cpu / views, 1e3 * wall / views, views / cpu, views / wall);
  fmt::print("  {:.0f} bytes per view\n", static_cast<double>(bytes) / views);
}

struct StorageOption {
  ExrStorage storage;
  std::string label;
  bool with_openexr = false;  // through OpenEXR's writer (zlib) rather than ExrWriter::encode's own (libdeflate)
};

void storage_table(Renderer& renderer, const TriangleMesh& cloth, int data_points) {
  std::vector<StorageOption> options;
  for (const std::string c : {"zip", "zips", "piz", "pxr24", "rle", "b44a", "dwaa", "dwab"}) {
    options.push_back({ExrStorage{.pixel = ExrStorage::Pixel::kFloat, .compression = c}, "float " + c});
  }
  for (const std::string c : {"zip", "zips", "piz", "rle", "b44a", "dwaa", "dwab"}) {
    options.push_back({ExrStorage{.pixel = ExrStorage::Pixel::kHalf, .compression = c}, "half " + c});
  }
  for (int level : {1, 2, 3, 4, 6, 9}) {
    if (level == ExrStorage{}.zip_level) continue;  // the "half zip" row
    options.push_back({ExrStorage{.pixel = ExrStorage::Pixel::kHalf, .compression = "zip", .zip_level = level},
                       fmt::format("half zip level {}", level)});
  }
  for (int level : {3, 4}) {  // the choices before libdeflate
    options.push_back({ExrStorage{.pixel = ExrStorage::Pixel::kHalf, .compression = "zip", .zip_level = level},
                       fmt::format("half zip zlib level {}", level), true});
  }
  for (double q : {std::ldexp(1.0, -12), std::ldexp(1.0, -11), 0.001}) {
    options.push_back({ExrStorage{.pixel = ExrStorage::Pixel::kFloat, .compression = "zip", .quantum = q},
                       fmt::format("float zip quantum {:.3g} mm", q * 1e3)});
    options.push_back({ExrStorage{.pixel = ExrStorage::Pixel::kHalf, .compression = "zip", .quantum = q},
                       fmt::format("half zip quantum {:.3g} mm", q * 1e3)});
  }

  for (const bool noisy : {true, false}) {
    RenderRequest request;
    request.augmentation.orientations = data_points;
    request.seed = 2;
    request.noise = noisy ? NoiseModel::kinect() : NoiseModel::none();
    const auto points = unwrap(render_data_points(renderer, cloth, request));
    int views = 0;
    long foreground = 0;
    double z_max = 0.0, z_min = 1e9;
    for (const auto& p : points) {
      for (const auto& v : p.views) {
        ++views;
        foreground += v.depth.foreground_count();
        for (float z : v.depth.depth) {
          z_max = std::max(z_max, static_cast<double>(z));
          if (z > 0.0f) z_min = std::min(z_min, static_cast<double>(z));
        }
      }
    }
    fmt::print("\nstorage, noise {}: {} views, {:.0f} pixels with a return per view, depth {:.3f} to {:.3f} m\n",
               noisy ? "kinect" : "none", views, static_cast<double>(foreground) / views, z_min, z_max);
    fmt::print("  {:<28} {:>10} {:>12} {:>12} {:>12} {:>10}\n", "option", "bytes/view", "max err mm", "rms err mm",
               "bound mm", "ms/view");
    for (const auto& option : options) {
      const ExrWriter writer(option.storage);
      std::size_t bytes = 0;
      double worst = 0.0, sum_sq = 0.0;
      long n = 0;
      const double t0 = now();
      std::vector<std::vector<char>> encoded;
      for (const auto& p : points) {
        encoded.push_back(unwrap(option.with_openexr ? writer.encode_with_openexr(p) : writer.encode(p)));
      }
      const double t_encode = now() - t0;
      for (std::size_t k = 0; k < points.size(); ++k) {
        bytes += encoded[k].size();
        const auto back = unwrap(read_exr(encoded[k]));
        for (std::size_t v = 0; v < back.views.size(); ++v) {
          const auto& a = points[k].views[v].depth.depth;
          const auto& b = back.views[v].depth.depth;
          for (std::size_t i = 0; i < a.size(); ++i) {
            if (a[i] == 0.0f && b[i] == 0.0f) continue;
            const double e = std::abs(static_cast<double>(a[i]) - b[i]);
            worst = std::max(worst, e);
            sum_sq += e * e;
            ++n;
          }
        }
      }
      fmt::print("  {:<28} {:>10.0f} {:>12.4f} {:>12.4f} {:>12.4f} {:>10.3f}\n", option.label,
                 static_cast<double>(bytes) / views, 1e3 * worst, 1e3 * std::sqrt(sum_sq / std::max(n, 1L)),
                 1e3 * option.storage.max_error(z_max), 1e3 * t_encode / views);
    }
  }
}

void crosscheck(Renderer& renderer, const TriangleMesh& cloth, int data_points) {
  const RigSpec rig;
  const TriangleMesh scene = tester_scene(cloth, rig);
  if (sim::Status s = renderer.set_scene(scene); !s) std::exit(1);
  const RayCaster caster(scene);
  long foreground = 0, agree = 0, one_only = 0;
  double worst = 0.0;
  const double t0 = now();
  for (const auto& setup : plan_data_points(rig, AugmentationSpec{.orientations = data_points}, 3)) {
    for (const auto& view : setup.views) {
      const DepthImage image = unwrap(renderer.render(view.camera, view.model));
      const DepthImage reference = caster.render(view.camera, view.model);
      for (std::size_t i = 0; i < image.depth.size(); ++i) {
        if (image.depth[i] == 0.0f && reference.depth[i] == 0.0f) continue;
        ++foreground;
        if ((image.depth[i] == 0.0f) != (reference.depth[i] == 0.0f)) {
          ++one_only;
          continue;
        }
        const double e = std::abs(static_cast<double>(image.depth[i]) - reference.depth[i]);
        if (e <= 5e-4) ++agree;
        worst = std::max(worst, e);
      }
    }
  }
  fmt::print("\ncrosscheck: {} views, {} foreground pixels: {:.4f}% agree within 0.5 mm; {} hit in one renderer only; "
             "largest difference {:.3g} mm ({:.1f} s)\n",
             data_points * rig.views, foreground, 100.0 * agree / foreground, one_only, worst * 1e3, now() - t0);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"drapegen renderer benchmark"};
  std::string mesh_path;
  int data_points = 48;
  bool all_triangles = false;
  bool storage = false, check = false;
  std::string pixel = "half", compression = "zip", renderer_name = kRendererNames.front();
  int zip_level = ExrStorage{}.zip_level;
  app.add_option("--mesh", mesh_path, "Draped mesh (PLY) from drapegen simulate --out")->required();
  app.add_option("--data-points", data_points, "Data points (x 4 views) to time")->capture_default_str();
  app.add_option("--renderer", renderer_name, "osmesa (DepthRenderer) or software (SoftwareRenderer)")
      ->check(CLI::IsMember(kRendererNames))
      ->capture_default_str();
  app.add_option("--pixel", pixel, "EXR pixel type for the timing: half or float")->capture_default_str();
  app.add_option("--compression", compression, "EXR compression for the timing")->capture_default_str();
  app.add_option("--zip-level", zip_level, "deflate level of zip/zips for the timing (libdeflate)")
      ->capture_default_str();
  app.add_flag("--all-triangles", all_triangles,
               "osmesa: draw every triangle (RendererOptions::skip_empty_triangles off)");
  app.add_flag("--storage", storage, "Also measure bytes and storage error of every EXR option");
  app.add_flag("--crosscheck", check, "Also compare the renderer with the CPU ray cast on this drape");
  CLI11_PARSE(app, argc, argv);

  const auto mesh = unwrap(sim::read_ply(mesh_path));
  const auto cloth = unwrap(cloth_triangles(mesh));
  RendererOptions osmesa;
  osmesa.skip_empty_triangles = !all_triangles;
  const auto renderer = unwrap(make_renderer(renderer_name, osmesa));
  fmt::print("mesh {}: {} vertices, {} triangles; renderer {}\n", mesh_path, cloth.vertex_count(),
             cloth.triangle_count(), renderer->name());
  ExrStorage s;
  s.pixel = pixel == "float" ? ExrStorage::Pixel::kFloat : ExrStorage::Pixel::kHalf;
  s.compression = compression;
  s.zip_level = zip_level;
  timing(*renderer, cloth, data_points, s);
  if (storage) storage_table(*renderer, cloth, std::min(data_points, 12));
  if (check) crosscheck(*renderer, cloth, 3);
  return 0;
}
