#include "drapegen/sampler/coverage.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "drapegen/sampler/assignment.hpp"
#include "drapegen/sampler/random.hpp"

namespace drapegen::sampler {

WassersteinResult wasserstein_exact(const std::vector<Features>& generated, const std::vector<Features>& data) {
  const int n = static_cast<int>(data.size());
  if (n == 0 || generated.size() < data.size()) {
    throw std::invalid_argument("wasserstein_exact: needs data and at least as many generated points");
  }
  WassersteinResult result;
  result.chunks = static_cast<int>(generated.size() / data.size());
  std::vector<double> values;
  Eigen::MatrixXd cost(n, n);
  for (int c = 0; c < result.chunks; ++c) {
    for (int i = 0; i < n; ++i) {
      const Features& g = generated[static_cast<std::size_t>(c) * n + i];
      for (int j = 0; j < n; ++j) {
        double d2 = 0.0;
        for (int k = 0; k < kFeatureCount; ++k) d2 += (g[k] - data[j][k]) * (g[k] - data[j][k]);
        cost(i, j) = std::sqrt(d2);
      }
    }
    const std::vector<int> match = solve_assignment(cost);
    double total = 0.0;
    for (int i = 0; i < n; ++i) total += cost(i, match[i]);
    values.push_back(total / n);
  }
  for (double v : values) result.mean += v / values.size();
  for (double v : values) result.stddev += (v - result.mean) * (v - result.mean) / values.size();
  result.stddev = std::sqrt(result.stddev);
  return result;
}

double mean_log_likelihood(const VaeModel& model, const std::vector<Features>& data, int samples, std::uint64_t seed) {
  if (data.empty() || samples < 3) throw std::invalid_argument("mean_log_likelihood: needs data and samples >= 3");
  const int latent = model.latent_dim;
  const double log_2pi = std::log(2.0 * std::numbers::pi);
  double log_std_sum = 0.0;
  for (int i = 0; i < kFeatureCount; ++i) log_std_sum += std::log(model.feature_std[i]);
  // log N(z; centre, diag(sd^2)) for every column of z.
  auto log_normal = [&](const Eigen::MatrixXd& z, const Eigen::VectorXd& centre, const Eigen::VectorXd& sd) {
    const Eigen::ArrayXd r2 = ((z.colwise() - centre).array().colwise() / sd.array()).square().colwise().sum();
    return Eigen::ArrayXd(-0.5 * r2 - sd.array().log().sum() - 0.5 * latent * log_2pi);
  };
  const int third = samples / 3;
  const double log_share_q = std::log(double(third) / samples),  // each of the two q parts
               log_share_prior = std::log(double(samples - 2 * third) / samples);
  double total = 0.0;
  Eigen::MatrixXd eps(latent, samples);
  for (std::size_t f = 0; f < data.size(); ++f) {
    Eigen::VectorXd s(kFeatureCount);
    for (int i = 0; i < kFeatureCount; ++i) s(i) = (data[f][i] - model.feature_mean[i]) / model.feature_std[i];
    Eigen::MatrixXd mu, logvar;
    model.encode_standardised(s, mu, logvar);
    const Eigen::VectorXd centre = mu.col(0), sd = (0.5 * logvar.col(0).array()).exp(), wide = 3.0 * sd;
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(latent), one = Eigen::VectorXd::Ones(latent);
    Random rng(derive_seed(seed, {3, f}));
    for (int k = 0; k < samples; ++k) {
      for (int d = 0; d < latent; ++d) eps(d, k) = rng.normal();
    }
    // Proposal: K/3 draws from q(z|x), K/3 from q(z|x) with 3x its standard deviation, the rest from the prior
    // (training/vae/vae.py).
    Eigen::MatrixXd z(latent, samples);
    for (int k = 0; k < samples; ++k) {
      if (k < third) {
        z.col(k) = centre.array() + sd.array() * eps.col(k).array();
      } else if (k < 2 * third) {
        z.col(k) = centre.array() + wide.array() * eps.col(k).array();
      } else {
        z.col(k) = eps.col(k);
      }
    }
    const Eigen::ArrayXd a = log_normal(z, centre, sd), b = log_normal(z, centre, wide),
                         prior = log_normal(z, zero, one);
    // The mixture's weights are the shares of the draws each part got (a third each when 3 divides the count).
    const Eigen::ArrayXd la = a + log_share_q, lb = b + log_share_q, lp = prior + log_share_prior;
    const Eigen::ArrayXd top = la.max(lb).max(lp);
    const Eigen::ArrayXd log_q = top + ((la - top).exp() + (lb - top).exp() + (lp - top).exp()).log();
    const Eigen::MatrixXd mean = model.decode_standardised(z);
    Eigen::ArrayXd w(samples);
    for (int k = 0; k < samples; ++k) w(k) = model.log_observation(s, mean.col(k)) + prior(k) - log_q(k);
    const double best = w.maxCoeff();
    total += best + std::log((w - best).exp().sum() / samples) - log_std_sum;
  }
  return total / data.size();
}

}  // namespace drapegen::sampler
