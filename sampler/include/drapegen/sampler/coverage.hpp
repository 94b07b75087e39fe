#pragma once
// How well sampled parameter vectors cover the measured fabrics: the metrics of training/vae (docs/SAMPLER.md).

#include <cstdint>
#include <vector>

#include "drapegen/sampler/parameters.hpp"
#include "drapegen/sampler/vae_model.hpp"

namespace drapegen::sampler {

struct WassersteinResult {
  double mean = 0.0;    // mean W1 over the chunks
  double stddev = 0.0;  // over the chunks
  int chunks = 0;
};

/// Exact W1 (Euclidean ground cost, feature space sign(k) ln|k|) between the empirical measure of `data` (n points)
/// and that of n generated points, solved as an assignment; averaged over the floor(generated / n) disjoint chunks of
/// n consecutive generated points. Needs at least as many generated points as data points.
[[nodiscard]] WassersteinResult wasserstein_exact(const std::vector<Features>& generated,
                                                  const std::vector<Features>& data);

/// Mean over `data` of an importance-sampling estimate of log p(x) in feature space (nats per fabric): log mean_k
/// p(x | z_k) p(z_k) / r(z_k | x) with `samples` (>= 3) draws per fabric from the defensive mixture r = 1/3 q(z|x) +
/// 1/3 q(z|x) with 3x its standard deviation + 1/3 N(0, I), as training/vae/vae.py (VAE.log_likelihood) computes it.
[[nodiscard]] double mean_log_likelihood(const VaeModel& model, const std::vector<Features>& data, int samples,
                                         std::uint64_t seed);

}  // namespace drapegen::sampler
