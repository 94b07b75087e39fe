#pragma once
// The trained subspace model (paper Section 5.1.3): a VAE's decoder (and encoder, for the log-likelihood of the
// coverage report), loaded from the binary file that training/vae/export.py writes.
//
// File format (versions 1 and 2), all integers unsigned 32-bit and all reals IEEE-754 float64, little-endian:
//   magic      8 bytes "DGVAE\0\0\1"
//   header     u32 version (1 or 2), u32 D (features, = 6), u32 L (latent dimension, 1..1024),
//              u32 H (hidden layers, 1..16), u32 activation (1 = ELU with alpha 1),
//              version 2 only: u32 observation (0 = Gaussian, 1 = Student-t),
//              u32 widths[H] (1..8192, encoder order: D -> widths[0] -> ... -> widths[H-1])
//   f64[D] x 5 feature mean, feature std (> 0), data range low, data range high (features of the measured
//              fabrics, low <= high), observation log-scale (log sigma, standardised units)
//   f64[D]     version 2 with a Student-t observation only: degrees of freedom nu (> 1)
//   encoder    H dense layers, then the mean head (widths[H-1] -> L) and the log-variance head (same shape)
//   decoder    H + 1 dense layers: L -> widths[H-1] -> ... -> widths[0] -> D
//              each dense layer: weights f64[out][in] (row-major, as torch.nn.Linear stores them), bias f64[out];
//              the activation follows every layer except the last of each network (and the encoder's output
//              feeds both heads after its activation)
//   checksum   u64 FNV-1a (64-bit) of every preceding byte
// Version 1 is a Gaussian observation model; writers use version 1 for Gaussian models, version 2 otherwise.
// The observation model p(s | z) is per feature, independent: N(decoder(z), sigma^2) or Student-t with location
// decoder(z), scale sigma and nu degrees of freedom; either way its mean is the decoder output (nu > 1), which is what
// the sampler uses.
// The decoder maps a latent vector z to standardised features s; features = s * std + mean (sign(k) ln|k|).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "drapegen/sampler/parameters.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::sampler {

struct DenseLayer {
  Eigen::MatrixXd weight;  // out x in
  Eigen::VectorXd bias;    // out
};

enum class Observation : std::uint32_t { gaussian = 0, student_t = 1 };

struct VaeModel {
  int latent_dim = 0;
  std::vector<int> hidden;  // encoder order
  Features feature_mean{};
  Features feature_std{};
  Features range_low{};   // of the measured fabrics' features
  Features range_high{};
  Observation observation = Observation::gaussian;
  Features log_sigma{};   // observation scale, standardised units
  Features degrees_of_freedom{};  // Student-t only (> 1)
  std::vector<DenseLayer> encoder;  // H layers
  DenseLayer encoder_mu, encoder_logvar;
  std::vector<DenseLayer> decoder;  // H + 1 layers

  /// Features (sign-log moduli) of latent vectors, one per column (latent_dim x n -> 6 x n).
  [[nodiscard]] Eigen::MatrixXd decode(const Eigen::MatrixXd& latents) const;
  /// Standardised decoder output (6 x n), before feature = s * std + mean.
  [[nodiscard]] Eigen::MatrixXd decode_standardised(const Eigen::MatrixXd& latents) const;
  /// Posterior mean and log-variance of q(z | features) for standardised inputs, one per column.
  void encode_standardised(const Eigen::MatrixXd& standardised, Eigen::MatrixXd& mu, Eigen::MatrixXd& logvar) const;
  /// log p(s | decoder mean) of the observation model, summed over the features (standardised units).
  [[nodiscard]] double log_observation(const Eigen::VectorXd& standardised, const Eigen::VectorXd& mean) const;
  /// Checks shapes and finiteness (the loader calls it).
  [[nodiscard]] sim::Status validate() const;
};

/// Loads a model file. Errors name the file and say what is wrong: missing, unreadable, not a model file, an
/// unsupported version, implausible sizes, truncated or with trailing bytes, a checksum mismatch, non-finite values.
[[nodiscard]] sim::Expected<VaeModel> load_vae_model(const std::string& path);
/// A model from the bytes of a model file; errors name it as `where`.
[[nodiscard]] sim::Expected<VaeModel> parse_vae_model(const std::vector<unsigned char>& bytes,
                                                     const std::string& where);
/// The committed model (sampler/models/vae3.dgvae), embedded in the program at build time: the sampler's default,
/// which needs no source tree where the program runs.
[[nodiscard]] sim::Expected<VaeModel> builtin_vae_model();
/// Writes `model` in the format above (for tests and tools; training writes the same bytes from Python).
[[nodiscard]] sim::Status save_vae_model(const VaeModel& model, const std::string& path);

/// The model committed with the source (sampler/models/vae3.dgvae), as an absolute path fixed at build time (for
/// tests and tools in the source tree; the program's default is builtin_vae_model()).
[[nodiscard]] std::string default_model_path();

/// The measured fabrics committed with the source (sampler/data/fabrics618.csv), an absolute path fixed at build time.
[[nodiscard]] std::string default_fabric_data_path();

}  // namespace drapegen::sampler
