#include "drapegen/sampler/parameter_sampler.hpp"

#include <cmath>
#include <string>
#include <unordered_map>

#include "drapegen/sampler/random.hpp"
#include "drapegen/sim/logging.hpp"

namespace drapegen::sampler {
namespace {

constexpr std::uint64_t kParameterStream = 1;
constexpr int kBatch = 512;

sim::Status validate(const SamplerOptions& o) {
  if (o.count <= 0) return sim::Error{"the number of samples must be positive, got " + std::to_string(o.count)};
  if (o.count > 10'000'000) return sim::Error{"at most 10,000,000 samples per run"};
  if (!(o.mu_half_width >= 0.0) || !std::isfinite(o.mu_half_width)) return sim::Error{"mu half width must be >= 0"};
  if (!(o.sigma_low > 0.0) || !(o.sigma_low <= o.sigma_high) || !std::isfinite(o.sigma_high)) {
    return sim::Error{"sigma range must satisfy 0 < low <= high"};
  }
  if (!(o.range_margin >= 0.0) || !std::isfinite(o.range_margin)) return sim::Error{"range margin must be >= 0"};
  // Off (0) or at least 1e-6: the duplicate index's grid cells are the distance wide, and a smaller one would put
  // cell coordinates beyond any integer.
  if (!(o.duplicate_distance == 0.0 || (o.duplicate_distance >= 1e-6 && std::isfinite(o.duplicate_distance)))) {
    return sim::Error{"duplicate distance must be 0 (off) or at least 1e-6"};
  }
  if (o.max_candidates_per_sample < 1) return sim::Error{"max candidates per sample must be >= 1"};
  return {};
}

/// Accepted vectors bucketed by their first two standardised coordinates in cells of the duplicate distance, so a
/// near-duplicate is found among the 3 x 3 neighbouring cells.
class DuplicateIndex {
 public:
  DuplicateIndex(double distance, const Features& scale) : distance_(distance), scale_(scale) {}

  bool near_existing(const Features& f) const {
    if (distance_ <= 0.0) return false;
    const auto [cx, cy] = cell(f);
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = cells_.find(key(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (const Features& g : it->second) {
          double d2 = 0.0;
          for (int i = 0; i < kFeatureCount; ++i) {
            const double d = (f[i] - g[i]) / scale_[i];
            d2 += d * d;
          }
          if (d2 < distance_ * distance_) return true;
        }
      }
    }
    return false;
  }
  void add(const Features& f) {
    if (distance_ <= 0.0) return;
    const auto [cx, cy] = cell(f);
    cells_[key(cx, cy)].push_back(f);
  }

 private:
  std::pair<std::int64_t, std::int64_t> cell(const Features& f) const {
    return {static_cast<std::int64_t>(std::floor(f[0] / scale_[0] / distance_)),
            static_cast<std::int64_t>(std::floor(f[1] / scale_[1] / distance_))};
  }
  static std::uint64_t key(std::int64_t x, std::int64_t y) {
    return mix64(static_cast<std::uint64_t>(x)) ^ (static_cast<std::uint64_t>(y) * 0x9e3779b97f4a7c15ULL);
  }
  double distance_;
  Features scale_;
  std::unordered_map<std::uint64_t, std::vector<Features>> cells_;
};

}  // namespace

Eigen::VectorXd draw_latent(const SamplerOptions& options, std::uint64_t candidate, int latent_dim) {
  Random rng(derive_seed(options.seed, {kParameterStream, candidate}));
  Eigen::VectorXd z(latent_dim);
  for (int d = 0; d < latent_dim; ++d) {
    if (options.latent == LatentSampling::kWidened) {
      const double mu = rng.uniform(-options.mu_half_width, options.mu_half_width);
      const double sigma = rng.uniform(options.sigma_low, options.sigma_high);
      z(d) = mu + sigma * rng.normal();
    } else {
      z(d) = rng.normal();
    }
  }
  return z;
}

std::pair<Features, Features> accepted_range(const VaeModel& model, const SamplerOptions& options) {
  Features low, high;
  for (int i = 0; i < kFeatureCount; ++i) {
    const double width = model.range_high[i] - model.range_low[i];
    low[i] = model.range_low[i] - options.range_margin * width;
    high[i] = model.range_high[i] + options.range_margin * width;
  }
  return {low, high};
}

sim::Expected<SampledParameters> sample_parameters(const VaeModel& model, const SamplerOptions& options) {
  if (sim::Status s = validate(options); !s) return s.error();
  const auto [low, high] = accepted_range(model, options);
  SampledParameters out;
  out.vectors.reserve(options.count);
  out.features.reserve(options.count);
  out.candidate_index.reserve(options.count);
  DuplicateIndex duplicates(options.duplicate_distance, model.feature_std);
  const std::int64_t limit = static_cast<std::int64_t>(options.count) * options.max_candidates_per_sample;
  const int latent = model.latent_dim;
  Eigen::MatrixXd z(latent, kBatch);
  std::int64_t next = 0;
  while (static_cast<int>(out.vectors.size()) < options.count) {
    if (next >= limit) {
      return sim::Error{"gave up after " + std::to_string(next) + " candidates for " + std::to_string(options.count) +
                        " samples (" + std::to_string(out.rejected_range) + " outside the range, " +
                        std::to_string(out.rejected_duplicate) + " near-duplicates)"};
    }
    for (int b = 0; b < kBatch; ++b) z.col(b) = draw_latent(options, static_cast<std::uint64_t>(next + b), latent);
    const Eigen::MatrixXd decoded = model.decode(z);
    for (int b = 0; b < kBatch && static_cast<int>(out.vectors.size()) < options.count; ++b) {
      ++out.candidates;
      Features f;
      bool inside = true;
      for (int i = 0; i < kFeatureCount; ++i) {
        f[i] = decoded(i, b);
        inside = inside && std::isfinite(f[i]) && f[i] >= low[i] && f[i] <= high[i];
      }
      inside = inside && f[0] > 0.0 && f[1] > 0.0 && f[2] > 0.0;  // alpha must stay positive
      if (options.reject && !inside) {
        ++out.rejected_range;
        continue;
      }
      if (options.reject && duplicates.near_existing(f)) {
        ++out.rejected_duplicate;
        continue;
      }
      duplicates.add(f);
      out.features.push_back(f);
      out.vectors.push_back(from_features(f));
      out.candidate_index.push_back(static_cast<std::uint64_t>(next + b));
    }
    next += kBatch;
  }
  sim::logger()->debug("sampler: {} vectors from {} candidates ({} outside the range, {} near-duplicates), seed {}",
                       out.vectors.size(), out.candidates, out.rejected_range, out.rejected_duplicate, options.seed);
  return out;
}

}  // namespace drapegen::sampler
