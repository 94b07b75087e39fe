#include "drapegen/sampler/parameter_sampler.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "test_models.hpp"

namespace drapegen::sampler {
namespace {

bool identical(const SampledParameters& a, const SampledParameters& b) {
  if (a.features.size() != b.features.size()) return false;
  return std::memcmp(a.features.data(), b.features.data(), a.features.size() * sizeof(Features)) == 0 &&
         a.candidate_index == b.candidate_index;
}

TEST(ParameterSampler, DeterministicPerSeedIncludingZero) {
  const VaeModel model = testing::random_model();
  SamplerOptions o;
  o.count = 700;
  for (std::uint64_t seed : {0ULL, 7ULL}) {
    o.seed = seed;
    auto a = sample_parameters(model, o), b = sample_parameters(model, o);
    ASSERT_TRUE(a && b);
    EXPECT_TRUE(identical(*a, *b)) << "seed " << seed;
    EXPECT_EQ(a->vectors.size(), 700u);
  }
  o.seed = 0;
  auto zero = sample_parameters(model, o);
  o.seed = 1;
  auto one = sample_parameters(model, o);
  ASSERT_TRUE(zero && one);
  int equal = 0;
  for (std::size_t i = 0; i < zero->features.size(); ++i) equal += zero->features[i] == one->features[i];
  EXPECT_EQ(equal, 0);
}

TEST(ParameterSampler, PrefixOfALongerRunIsTheShorterRun) {
  // A restarted coordinator that asks for more samples regenerates the first ones unchanged.
  const VaeModel model = testing::random_model();
  SamplerOptions o;
  o.seed = 3;
  o.count = 1000;
  auto shorter = sample_parameters(model, o);
  o.count = 1600;
  auto longer = sample_parameters(model, o);
  ASSERT_TRUE(shorter && longer);
  EXPECT_EQ(std::memcmp(shorter->features.data(), longer->features.data(), 1000 * sizeof(Features)), 0);
}

TEST(ParameterSampler, WidenedLatentsHaveThePapersMoments) {
  // z = mu + sigma * n with mu ~ U[-0.5, 0.5], sigma ~ U[0.8, 1.2]: mean 0, variance E[sigma^2] + Var(mu)
  // = (0.64 + 0.96 + 1.44) / 3 + 1/12 = 1.09667; the prior has variance 1.
  SamplerOptions o;
  o.seed = 0;
  double s1 = 0, s2 = 0, p2 = 0;
  const int n = 40000, latent = 4;
  for (int j = 0; j < n; ++j) {
    const Eigen::VectorXd z = draw_latent(o, j, latent);
    s1 += z.sum(), s2 += z.squaredNorm();
  }
  o.latent = LatentSampling::kPrior;
  for (int j = 0; j < n; ++j) p2 += draw_latent(o, j, latent).squaredNorm();
  EXPECT_NEAR(s1 / (n * latent), 0.0, 0.01);
  EXPECT_NEAR(s2 / (n * latent), 1.09667, 0.015);
  EXPECT_NEAR(p2 / (n * latent), 1.0, 0.015);
}

TEST(ParameterSampler, EverySampleIsInsideTheWidenedRangeAndDistinct) {
  VaeModel model = testing::random_model();
  // Narrow the data range so that many candidates fall outside it.
  for (int i = 0; i < kFeatureCount; ++i) {
    model.range_low[i] = model.feature_mean[i] - 0.3 * model.feature_std[i];
    model.range_high[i] = model.feature_mean[i] + 0.3 * model.feature_std[i];
  }
  SamplerOptions o;
  o.count = 500;
  o.duplicate_distance = 0.05;
  auto s = sample_parameters(model, o);
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_GT(s->rejected_range, 0);
  EXPECT_GT(s->rejected_duplicate, 0);
  EXPECT_EQ(s->candidates, 500 + s->rejected_range + s->rejected_duplicate);
  const auto [low, high] = accepted_range(model, o);
  for (std::size_t a = 0; a < s->features.size(); ++a) {
    for (int i = 0; i < kFeatureCount; ++i) {
      ASSERT_GE(s->features[a][i], low[i]);
      ASSERT_LE(s->features[a][i], high[i]);
    }
    EXPECT_GT(s->vectors[a].alpha.warp, 0.0);
    for (std::size_t b = 0; b < a; ++b) {
      double d2 = 0;
      for (int i = 0; i < kFeatureCount; ++i) {
        const double d = (s->features[a][i] - s->features[b][i]) / model.feature_std[i];
        d2 += d * d;
      }
      ASSERT_GE(std::sqrt(d2), 0.05) << a << " and " << b << " are near-duplicates";
    }
  }
  // Without rejection the candidates are kept as decoded, and some lie outside the range.
  o.reject = false;
  auto all = sample_parameters(model, o);
  ASSERT_TRUE(all);
  EXPECT_EQ(all->candidates, 500);
  ASSERT_EQ(all->features.size(), 500u);
  EXPECT_EQ(all->rejected_range + all->rejected_duplicate, 0);
  int outside = 0;
  for (const Features& f : all->features) {
    for (int i = 0; i < kFeatureCount; ++i) {
      if (f[i] < low[i] || f[i] > high[i]) {
        ++outside;
        break;
      }
    }
  }
  EXPECT_GT(outside, 0);
}

TEST(ParameterSampler, VectorsAreTheDecodedLatents) {
  const VaeModel model = testing::random_model();
  SamplerOptions o;
  o.count = 20;
  o.seed = 9;
  auto s = sample_parameters(model, o);
  ASSERT_TRUE(s);
  for (std::size_t a = 0; a < s->features.size(); ++a) {
    const Eigen::MatrixXd f = model.decode(draw_latent(o, s->candidate_index[a], model.latent_dim));
    for (int i = 0; i < kFeatureCount; ++i) EXPECT_EQ(f(i, 0), s->features[a][i]);
    const ParameterVector v = from_features({f(0, 0), f(1, 0), f(2, 0), f(3, 0), f(4, 0), f(5, 0)});
    EXPECT_DOUBLE_EQ(s->vectors[a].alpha.warp, v.alpha.warp);
    EXPECT_DOUBLE_EQ(s->vectors[a].alpha.bias, v.alpha.bias);
    EXPECT_DOUBLE_EQ(s->vectors[a].alpha.weft, v.alpha.weft);
    EXPECT_DOUBLE_EQ(s->vectors[a].beta.warp, v.beta.warp);
    EXPECT_DOUBLE_EQ(s->vectors[a].beta.bias, v.beta.bias);
    EXPECT_DOUBLE_EQ(s->vectors[a].beta.weft, v.beta.weft);
  }
}

TEST(ParameterSampler, BadOptionsAreErrors) {
  const VaeModel model = testing::random_model();
  SamplerOptions o;
  for (int count : {0, -5}) {
    o.count = count;
    auto s = sample_parameters(model, o);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("positive"), std::string::npos);
  }
  o = {};
  o.sigma_low = 0.0;
  EXPECT_FALSE(sample_parameters(model, o));
  o = {};
  o.range_margin = -1;
  EXPECT_FALSE(sample_parameters(model, o));
  // A duplicate distance so small its grid cells' coordinates would overflow an integer: refused, not undefined.
  o = {};
  o.duplicate_distance = 1e-19;
  const auto tiny = sample_parameters(model, o);
  ASSERT_FALSE(tiny);
  EXPECT_NE(tiny.error().message.find("duplicate distance must be 0 (off) or at least 1e-6"), std::string::npos);
  // An empty accepted range: every candidate is rejected and the sampler gives up with an explanation.
  VaeModel narrow = model;
  narrow.range_low = narrow.range_high = Features{50, 50, 50, 50, 50, 50};
  o = {};
  o.count = 10;
  o.range_margin = 0.0;
  auto s = sample_parameters(narrow, o);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("gave up"), std::string::npos);
}

}  // namespace
}  // namespace drapegen::sampler
