#pragma once
// Small models with seeded random weights for the sampler tests.

#include "drapegen/sampler/random.hpp"
#include "drapegen/sampler/vae_model.hpp"

namespace drapegen::sampler::testing {

inline DenseLayer random_layer(int in, int out, Random& rng, double scale) {
  DenseLayer l{Eigen::MatrixXd(out, in), Eigen::VectorXd(out)};
  for (int r = 0; r < out; ++r) {
    for (int c = 0; c < in; ++c) l.weight(r, c) = scale * rng.normal() / std::sqrt(double(in));
    l.bias(r) = 0.1 * rng.normal();
  }
  return l;
}

/// A VAE with `hidden` widths and `latent` dimensions, features centred on typical fabric values.
inline VaeModel random_model(std::vector<int> hidden = {12, 8}, int latent = 3, std::uint64_t seed = 1) {
  Random rng(seed);
  VaeModel m;
  m.latent_dim = latent;
  m.hidden = hidden;
  m.feature_mean = {9.5, 9.3, 9.2, -10.5, -10.0, -10.0};
  m.feature_std = {1.0, 0.9, 0.9, 2.5, 1.5, 1.4};
  m.range_low = {7.2, 6.9, 7.1, -13.6, -13.8, -13.2};
  m.range_high = {12.1, 12.1, 11.7, 15.1, 7.6, 9.7};
  m.log_sigma = {-1.0, -0.8, -0.7, -1.2, -0.5, -0.9};
  int in = kFeatureCount;
  for (int w : hidden) {
    m.encoder.push_back(random_layer(in, w, rng, 1.0));
    in = w;
  }
  m.encoder_mu = random_layer(in, latent, rng, 1.0);
  m.encoder_logvar = random_layer(in, latent, rng, 0.3);
  in = latent;
  for (auto it = hidden.rbegin(); it != hidden.rend(); ++it) {
    m.decoder.push_back(random_layer(in, *it, rng, 1.0));
    in = *it;
  }
  m.decoder.push_back(random_layer(in, kFeatureCount, rng, 0.5));
  return m;
}

}  // namespace drapegen::sampler::testing
