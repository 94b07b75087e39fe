#pragma once
// The depth-sensor noise model: each term has a formula, named parameters and a switch (docs/RENDERER.md, "Noise
// model", gives the formulas and their sources). All randomness comes from the seed given to apply().

#include <cstdint>
#include <string>

#include "drapegen/renderer/depth_image.hpp"

namespace drapegen::renderer {

struct NoiseModel {
  /// Angle theta between the viewing ray and the surface normal, radians, from DepthImage::incidence.

  /// 1. Axial noise (Nguyen, Izadi, Lovell 2012, Kinect): Gaussian with
  ///    sigma_z(z, theta) = a + b (z - z0)^2 + c / sqrt(z) * theta^2 / (pi/2 - theta)^2      [m, z in m].
  bool axial = true;
  double axial_a = 0.0012;   // m
  double axial_b = 0.0019;   // 1/m
  double axial_z0 = 0.4;     // m
  double axial_c = 0.0001;   // m^1.5
  /// Scales sigma_z (1: the published Kinect model).
  double axial_scale = 1.0;

  /// 2. Lateral jitter (same paper): each pixel takes the depth found at a Gaussian offset of
  ///    sigma_L(theta) = l0 + l1 * theta / (pi/2 - theta) pixels per axis (rounded to the nearest pixel). The
  ///    published 0.8 + 0.035 theta/(pi/2 - theta) px are for a 585 px focal length; the defaults keep the same
  ///    metric jitter at the rig's 252 px (x 252/585).
  bool lateral = true;
  double lateral_l0_px = 0.8 * 252.0 / 585.0;
  double lateral_l1_px = 0.035 * 252.0 / 585.0;

  /// 3. Invalid pixels at grazing angles: no return where theta > grazing_max_deg.
  bool grazing = true;
  double grazing_max_deg = 80.0;

  /// 4. Depth discontinuities: where a 4-neighbour differs by more than edge_jump (or has no return), the pixel
  ///    becomes a hole (no return) with probability edge_hole_probability next to a pixel with no return, and a
  ///    flying pixel z + w (z_n - z), w ~ U(0, 1), between the two surfaces with probability flying_probability
  ///    next to a farther or nearer surface (ToF mixed pixels).
  bool edges = true;
  double edge_jump = 0.02;  // m
  double edge_hole_probability = 0.3;
  double flying_probability = 0.5;

  /// 5. Random dropout: any returned pixel has no return with this probability.
  bool dropout = true;
  double dropout_probability = 0.002;

  /// 6. Quantisation: z -> step * round(z / step) (the Azure Kinect reports whole millimetres).
  bool quantisation = true;
  double quantisation_step = 0.001;  // m

  /// The published models with the parameters above ("kinect"), or every term off ("none": the clean depth).
  [[nodiscard]] static NoiseModel kinect();
  [[nodiscard]] static NoiseModel none();
  [[nodiscard]] bool any() const { return axial || lateral || grazing || edges || dropout || quantisation; }

  [[nodiscard]] double axial_sigma(double z, double theta) const;
  [[nodiscard]] double lateral_sigma_px(double theta) const;

  /// The noisy image (without incidence). Deterministic: the same clean image and seed give the same bytes.
  [[nodiscard]] DepthImage apply(const DepthImage& clean, std::uint64_t seed) const;

  /// One line naming every enabled term and its parameters (stored in the EXR header).
  [[nodiscard]] std::string describe() const;
};

}  // namespace drapegen::renderer
