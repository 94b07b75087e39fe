#pragma once
// Samples bending parameter vectors from the VAE subspace as the paper does (Section 5.1.3): every latent
// coordinate from N(mu, sigma) with mu ~ U[-0.5, 0.5] and sigma ~ U[0.8, 1.2] drawn per sample and coordinate,
// decoded to features, with rejection of vectors outside a widened data range and of near-duplicates.

#include <cstdint>
#include <vector>

#include "drapegen/sampler/parameters.hpp"
#include "drapegen/sampler/vae_model.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::sampler {

enum class LatentSampling {
  kWidened,  // the paper's N(mu, sigma), mu ~ U[-0.5, 0.5], sigma ~ U[0.8, 1.2] (default)
  kPrior,    // N(0, 1): the model's own distribution (for the coverage report)
};

struct SamplerOptions {
  int count = 6000;
  std::uint64_t seed = 0;
  LatentSampling latent = LatentSampling::kWidened;
  double mu_half_width = 0.5;
  double sigma_low = 0.8, sigma_high = 1.2;
  /// Accepted feature range: the measured fabrics' [low, high] per feature widened by this fraction of its width
  /// on each side (features are sign(k) ln|k|; the range keeps alpha positive).
  double range_margin = 0.1;
  /// A candidate closer than this (Euclidean, in features standardised by the model's feature std) to an accepted
  /// vector is a near-duplicate and is rejected. 0 turns the check off.
  double duplicate_distance = 1e-3;
  /// Give up (an error) after this many candidates per requested vector.
  int max_candidates_per_sample = 50;
  bool reject = true;  // false: keep every decoded candidate (for the report)
};

struct SampledParameters {
  std::vector<ParameterVector> vectors;  // normalised to 300 g/m^2, paper units
  std::vector<Features> features;        // the same vectors as features
  std::vector<std::uint64_t> candidate_index;  // which candidate stream each accepted vector came from
  std::int64_t candidates = 0;
  std::int64_t rejected_range = 0;
  std::int64_t rejected_duplicate = 0;
};

/// Candidate j of a run with seed s is decoded from latents drawn from the stream derive_seed(s, {1, j}); candidates
/// are considered in order 0, 1, 2, ... and accepted unless rejected. The result is a pure function of (model,
/// options): identical for the same seed (seed 0 included), on every run and after any restart.
/// Errors: count <= 0 or above 10,000,000, invalid widths/margins, too many rejections.
[[nodiscard]] sim::Expected<SampledParameters> sample_parameters(const VaeModel& model,
                                                                 const SamplerOptions& options);

/// The latent vector of candidate `candidate` (from the stream derive_seed(options.seed, {1, candidate})).
[[nodiscard]] Eigen::VectorXd draw_latent(const SamplerOptions& options, std::uint64_t candidate, int latent_dim);

/// The accepted feature range of `model` under `options` (low, high).
[[nodiscard]] std::pair<Features, Features> accepted_range(const VaeModel& model, const SamplerOptions& options);

}  // namespace drapegen::sampler
