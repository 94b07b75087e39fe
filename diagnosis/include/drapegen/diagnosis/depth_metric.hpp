#pragma once
// The distance between a captured depth view and a model's rendering of it: truncated depth differences where both
// return, the silhouette mismatch, and Bhat et al. 2003's fold-weighted orientation metric carried over to depth
// (their angle map becomes the surface normal estimated from smoothed depth; their gradient mask the capture's
// pixels where that normal turns fast, i.e. folds). docs/DIAGNOSIS.md, "Objective".

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "drapegen/renderer/camera.hpp"
#include "drapegen/renderer/depth_image.hpp"

namespace drapegen::diagnosis {

struct MetricWeights {
  double truncation = 0.02;          // m: a depth difference counts at most this much (a fold out of phase)
  double silhouette = 0.03;          // m per unit of silhouette mismatch (|A xor B| / |A or B|)
  double fold = 0.0002;              // m per degree of RMS normal-angle difference on the fold mask
  double fold_mask_deg = 12.0;       // fold mask: the capture's normal turns more than this over 2 pixels each way
  int smoothing_radius = 2;          // box filter (pixels) before normals
  /// Pixel weights by where the pixel lies on the specimen: the platform top and the bare cylinder side do not
  /// depend on which stable drape formed (weight 1); skirt and hem pixels do, and count with this weight.
  double variable_weight = 0.35;
  double cylinder_radius = 0.05;     // m
  /// The view score: stable * stable_rms + pixel * (depth_rms + silhouette + fold terms).
  double stable = 1.0;
  double pixel = 0.25;
  /// m per unit of the shape-feature distance (ForwardModel): a difference of one group scale counts this much.
  double shape = 0.004;
};

/// What is precomputed once per captured (or pseudo-captured) view: depth, smoothed normals, fold mask.
struct ViewFeatures {
  renderer::DepthImage depth;
  renderer::Intrinsics intrinsics;
  std::vector<Eigen::Vector3f> normals;  // camera frame, zero where unknown
  std::vector<unsigned char> fold_mask;
  /// Specimen frame to camera (the view's pose); identity: every pixel weighs 1.
  Eigen::Isometry3d world_to_camera = Eigen::Isometry3d::Identity();
  bool weighted = false;
};
[[nodiscard]] ViewFeatures view_features(const renderer::DepthImage& depth, const renderer::Intrinsics& intrinsics,
                                         const MetricWeights& weights = {});
/// With the pose: pixels are weighted by region (MetricWeights::variable_weight).
[[nodiscard]] ViewFeatures view_features(const renderer::DepthImage& depth, const renderer::Camera& camera,
                                         const MetricWeights& weights);
/// The weight of a pixel at camera depth z (1 on the top and bare cylinder side, variable_weight elsewhere).
[[nodiscard]] double pixel_weight(const ViewFeatures& features, int u, int v, float z, const MetricWeights& weights);
/// Whether the pixel at camera depth z sees the platform top or the bare cylinder side (needs the pose).
[[nodiscard]] bool stable_pixel(const ViewFeatures& features, int u, int v, float z, const MetricWeights& weights);

struct ViewComparison {
  double depth_rms = 0.0;     // m, weighted truncated RMS of captured - model where both return
  double silhouette = 0.0;    // weighted |A xor B| / |A or B|
  double fold_rms_deg = 0.0;  // RMS angle between normals on the fold mask where both return
  /// m: truncated RMS over the pixels where both the capture and the model see the platform top or the bare
  /// cylinder side (geometry that does not depend on which stable drape formed); the truncation where the capture
  /// sees such pixels but none of them is one the model sees so too (the stated camera, or the model, misses them);
  /// 0 where the capture sees none (no stable term: left out of ForwardModel's mean).
  double stable_rms = 0.0;
  int stable_pixels = 0;           // where both see the rigid surfaces
  int captured_stable_pixels = 0;  // where the capture does (with a pose; 0 without)
  double score = 0.0;         // m: w_stable stable_rms + w_pixel (depth_rms + w_s silhouette + w_f fold_rms_deg)
  int overlap = 0;            // pixels where both return
  /// Per pixel: captured - model clamped to +-truncation where both return; +truncation where only the capture
  /// returns, -truncation where only the model does; NaN where neither.
  std::vector<float> residual;
  /// Per pixel: the depth used to place the residual in 3D (captured if it returned, else the model's), 0 if none.
  std::vector<float> depth;
};

[[nodiscard]] ViewComparison compare_view(const ViewFeatures& captured, const renderer::DepthImage& model,
                                          const MetricWeights& weights = {});

}  // namespace drapegen::diagnosis
