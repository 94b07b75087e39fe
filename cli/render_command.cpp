// drapegen render: one drape to its noisy multi-view depth images (OpenEXR, one file per data point) and a preview.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "commands.hpp"
#include "failure.hpp"
#include "drapegen/renderer/data_point.hpp"
#include "drapegen/renderer/make_renderer.hpp"
#include "drapegen/renderer/preview.hpp"
#include "drapegen/sim/ply.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/json_text.hpp"
#include "parse.hpp"

namespace drapegen::cli {
namespace {

struct RenderOptions {
  std::string mesh;
  std::string out;
  int orientations = 12;
  std::string noise = "kinect";
  std::string renderer_name = renderer::kRendererNames.front();
  std::uint64_t seed = 0;
  std::string preview;
  bool json = false;
  bool augment = true;
  std::string pixel = "half";
  std::string compression = "zip";
  double quantum = 0.0;
};

const Failure fail{"render"};

/// "out.exr" for one data point; "out_00.exr", "out_01.exr", ... for several.
std::string output_path(const std::string& out, int index, int count) {
  if (count == 1) return out;
  const std::filesystem::path p(out);
  const std::string stem = p.stem().string(), ext = p.extension().string();
  return (p.parent_path() / fmt::format("{}_{:02d}{}", stem, index, ext.empty() ? ".exr" : ext)).string();
}

int run_render(const RenderOptions& o) {
  using namespace drapegen::renderer;
  const auto start = std::chrono::steady_clock::now();
  if (o.orientations < 1 || o.orientations > 360) return fail("--orientations must be between 1 and 360");
  RenderRequest request;
  request.seed = o.seed;
  request.augmentation =
      o.augment ? AugmentationSpec{} : AugmentationSpec::orientations_only(o.orientations);
  request.augmentation.orientations = o.orientations;
  request.noise = o.noise == "none" ? NoiseModel::none() : NoiseModel::kinect();
  request.source = std::filesystem::path(o.mesh).filename().string();
  ExrStorage storage;
  storage.pixel = o.pixel == "float" ? ExrStorage::Pixel::kFloat : ExrStorage::Pixel::kHalf;
  storage.compression = o.compression;
  storage.quantum = o.quantum;
  const ExrWriter writer(storage);
  if (sim::Status s = writer.validate(); !s) return fail(s.error().message);

  // Refuse unwritable outputs before rendering.
  std::vector<std::string> paths;
  for (int k = 0; k < o.orientations; ++k) paths.push_back(output_path(o.out, k, o.orientations));
  // No output over the input or over another output (the mesh replaced by an EXR, an EXR by the preview).
  std::vector<std::string> outputs = paths;
  if (!o.preview.empty()) outputs.push_back(o.preview);
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (same_file(outputs[i], o.mesh)) return fail(fmt::format("{} would overwrite the input mesh", outputs[i]));
    for (std::size_t j = 0; j < i; ++j) {
      if (same_file(outputs[i], outputs[j])) return fail(fmt::format("{} is two of the outputs", outputs[i]));
    }
  }
  for (const auto& path : paths) {
    if (sim::Status s = check_writable(path); !s) return fail(s.error().message, kExitIo);
  }
  if (!o.preview.empty()) {
    if (sim::Status s = check_writable(o.preview); !s) return fail(s.error().message, kExitIo);
  }

  const auto mesh = sim::read_ply(o.mesh);
  if (!mesh) return fail(mesh.error().message);
  const auto cloth = cloth_triangles(*mesh);
  if (!cloth) return fail(fmt::format("{}: {}", o.mesh, cloth.error().message));

  auto renderer = make_renderer(o.renderer_name);
  if (!renderer) return fail(renderer.error().message);
  const auto render_start = std::chrono::steady_clock::now();
  auto points = render_data_points(**renderer, *cloth, request);
  if (!points) return fail(fmt::format("{}: {}", o.mesh, points.error().message));
  // A view with no return at all is a broken setup, never a data point.
  for (const auto& p : *points) {
    for (std::size_t v = 0; v < p.views.size(); ++v) {
      if (p.views[v].depth.foreground_count() == 0) {
        return fail(fmt::format("{}: data point {} view {} is blank", o.mesh, p.index, v));
      }
    }
  }
  const double render_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - render_start).count();

  // Every data point's file written as one set: a failed write leaves an earlier render's files all as they were.
  std::vector<std::vector<char>> encoded;
  for (const auto& p : *points) {
    auto bytes = writer.encode(p);
    if (!bytes) return fail(bytes.error().message);
    encoded.push_back(std::move(*bytes));
  }
  std::vector<storage::FileBytes> set;
  for (std::size_t k = 0; k < encoded.size(); ++k) set.push_back({paths[k], {encoded[k].data(), encoded[k].size()}});
  if (sim::Status s = storage::write_files_atomic(set); !s) return fail(s.error().message, kExitIo);

  nlohmann::json files = nlohmann::json::array();
  std::uintmax_t total_bytes = 0;
  for (std::size_t k = 0; k < points->size(); ++k) {
    const auto& p = (*points)[k];
    const std::uintmax_t bytes = encoded[k].size();
    total_bytes += bytes;
    nlohmann::json views = nlohmann::json::array();
    for (const auto& v : p.views) {
      views.push_back({{"table_angle_rad", v.table_angle}, {"foreground_pixels", v.depth.foreground_count()},
                       {"noise_seed", std::to_string(v.noise_seed)}});
    }
    files.push_back({{"path", paths[k]}, {"bytes", bytes}, {"orientation_rad", p.orientation}, {"views", views}});
  }
  if (!o.preview.empty()) {
    std::vector<std::vector<DepthImage>> rows;
    for (const auto& p : *points) {
      rows.emplace_back();
      for (const auto& v : p.views) rows.back().push_back(v.depth);
    }
    if (sim::Status s = write_preview_png(o.preview, rows); !s) return fail(s.error().message, kExitIo);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const int views = o.orientations * request.rig.views;
  std::ostream& out = summary_stream(outputs);  // not over a file written to standard output
  if (o.json) {
    nlohmann::json summary = {{"mesh", o.mesh},
                              {"renderer", (*renderer)->name()},
                              {"noise", request.noise.describe()},
                              {"seed", o.seed},
                              {"storage", fmt::format("{} {} quantum={} m", o.pixel, o.compression, o.quantum)},
                              {"views", views},
                              {"bytes_per_view", static_cast<double>(total_bytes) / views},
                              {"render_and_noise_seconds", render_seconds},
                              {"seconds", seconds},
                              {"files", files}};
    if (!o.preview.empty()) summary["preview"] = o.preview;
    out << storage::json_text(summary) << "\n";
  } else {
    out << fmt::format("render: {} data points x {} views of {} in {:.2f} s, {:.0f} bytes per view\n",
                             points->size(), request.rig.views, o.mesh, seconds,
                             static_cast<double>(total_bytes) / views);
    out << fmt::format("  written to {}{}\n", paths.front(), paths.size() > 1 ? " ... " + paths.back() : "");
    if (!o.preview.empty()) out << "  preview " << o.preview << "\n";
  }
  return kExitOk;
}

}  // namespace

Runner add_render_command(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  app.add_option("--mesh", o->mesh, "Draped mesh (PLY, metres) as written by drapegen simulate --out")->required();
  app.add_option("--out", o->out,
                 "OpenEXR file per data point; with several orientations OUT_00.exr, OUT_01.exr, ...")
      ->required();
  app.add_option("--orientations", o->orientations, "Stratified random specimen orientations (data points)")
      ->capture_default_str();
  app.add_option("--noise", o->noise, "Depth noise model: kinect or none (clean depth)")
      ->check(CLI::IsMember({"kinect", "none"}))
      ->capture_default_str();
  app.add_option("--renderer", o->renderer_name,
                 "Depth renderer: osmesa (OpenGL through OSMesa) or software (the faster CPU rasteriser)")
      ->check(CLI::IsMember(renderer::kRendererNames))
      ->capture_default_str();
  app.add_option("--seed", o->seed, "Seed of orientations, perturbations and noise")
      ->check(kSeed)
      ->capture_default_str();
  app.add_option("--preview", o->preview, "Also write a PNG: one row per data point, its views side by side");
  app.add_flag("--json", o->json, "Print the summary as JSON");
  app.add_flag("!--no-augment", o->augment, "No camera or affine image perturbation (orientations only)");
  app.add_option("--pixel", o->pixel, "EXR pixel type: half or float")
      ->check(CLI::IsMember({"half", "float"}))
      ->capture_default_str();
  app.add_option("--compression", o->compression,
                 "EXR compression: none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab")
      ->capture_default_str();
  app.add_option("--quantum", o->quantum, "Round stored depth to multiples of this, metres (0: off; else 1e-9 .. 0.01)")
      ->capture_default_str();
  return [o] { return run_render(*o); };
}

}  // namespace drapegen::cli
