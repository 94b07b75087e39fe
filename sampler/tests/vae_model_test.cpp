#include "drapegen/sampler/vae_model.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>

#include "test_models.hpp"

namespace drapegen::sampler {
namespace {

namespace fs = std::filesystem;

std::vector<char> read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_all(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

class ModelFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("drapegen_model_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    path_ = (dir_ / "model.dgvae").string();
    ASSERT_TRUE(save_vae_model(model_, path_));
    bytes_ = read_all(path_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string error_of(const std::vector<char>& bytes) {
    const std::string p = (dir_ / "bad.dgvae").string();
    write_all(p, bytes);
    auto loaded = load_vae_model(p);
    return loaded ? std::string() : loaded.error().message;
  }
  VaeModel model_ = testing::random_model();
  fs::path dir_;
  std::string path_;
  std::vector<char> bytes_;
};

TEST_F(ModelFileTest, RoundTripIsExact) {
  auto loaded = load_vae_model(path_);
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(loaded->hidden, model_.hidden);
  EXPECT_EQ(loaded->latent_dim, model_.latent_dim);
  EXPECT_EQ(loaded->feature_std, model_.feature_std);
  Eigen::MatrixXd z = Eigen::MatrixXd::Random(3, 20);
  EXPECT_EQ((loaded->decode(z) - model_.decode(z)).cwiseAbs().maxCoeff(), 0.0);
  // Size: header (8 + 5*4 + 2*4) + 30 reals + layers + checksum.
  const std::size_t reals = 30 + (6 + 1) * 12 + (12 + 1) * 8 + 2 * (8 + 1) * 3 + (3 + 1) * 8 + (8 + 1) * 12 +
                            (12 + 1) * 6;
  EXPECT_EQ(bytes_.size(), 36 + 8 * reals + 8);
}

TEST_F(ModelFileTest, MissingFile) {
  auto loaded = load_vae_model((dir_ / "nope.dgvae").string());
  ASSERT_FALSE(loaded);
  EXPECT_NE(loaded.error().message.find("cannot open"), std::string::npos) << loaded.error().message;
}

TEST_F(ModelFileTest, EmptyAndForeignFiles) {
  EXPECT_NE(error_of({}).find("bad magic"), std::string::npos);
  EXPECT_NE(error_of({'h', 'e', 'l', 'l', 'o', ',', 'w', 'o', 'r', 'l', 'd'}).find("bad magic"), std::string::npos);
}

TEST_F(ModelFileTest, EveryTruncationIsRejected) {
  for (std::size_t size = 0; size < bytes_.size(); size += (size < 64 ? 1 : 97)) {
    const std::vector<char> cut(bytes_.begin(), bytes_.begin() + static_cast<std::ptrdiff_t>(size));
    const std::string error = error_of(cut);
    EXPECT_FALSE(error.empty()) << "accepted a file cut to " << size << " bytes";
  }
  const std::string error = error_of({bytes_.begin(), bytes_.end() - 1});
  EXPECT_NE(error.find("truncated"), std::string::npos) << error;
}

TEST_F(ModelFileTest, TrailingBytesAreRejected) {
  std::vector<char> longer = bytes_;
  longer.push_back('\0');
  EXPECT_NE(error_of(longer).find("trailing"), std::string::npos);
}

TEST_F(ModelFileTest, EveryFlippedBodyByteIsRejected) {
  // Past the header a flipped bit changes a weight: only the checksum can tell.
  for (std::size_t i = 40; i < bytes_.size(); i += 53) {
    std::vector<char> bad = bytes_;
    bad[i] = static_cast<char>(bad[i] ^ 0x10);
    const std::string error = error_of(bad);
    EXPECT_FALSE(error.empty()) << "accepted a flip at byte " << i;
  }
  std::vector<char> bad = bytes_;
  bad[bytes_.size() / 2] ^= 1;
  EXPECT_NE(error_of(bad).find("checksum"), std::string::npos);
}

TEST_F(ModelFileTest, HeaderErrorsAreNamed) {
  std::vector<char> bad = bytes_;
  bad[8] = 3;  // version
  EXPECT_NE(error_of(bad).find("version 3"), std::string::npos);
  bad = bytes_;
  bad[12] = 7;  // features
  EXPECT_NE(error_of(bad).find("7 features"), std::string::npos);
  bad = bytes_;
  bad[23] = 0x7f;  // layer count high byte
  EXPECT_NE(error_of(bad).find("implausible"), std::string::npos);
}

TEST_F(ModelFileTest, NonFiniteWeightsAreRejectedOnSave) {
  VaeModel m = model_;
  m.decoder[1].weight(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(save_vae_model(m, (dir_ / "nan.dgvae").string()));
  m = model_;
  m.feature_std[2] = 0.0;
  EXPECT_FALSE(m.validate());
}

// A file with a valid checksum can still carry values no model has (another exporter, a bug): the loader checks
// them itself.
TEST_F(ModelFileTest, NonFiniteWeightsAreRejectedOnLoad) {
  std::vector<char> bad = bytes_;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::size_t first_weight = 36 + 8 * 30;  // past the header and the 30 per-feature reals
  std::memcpy(bad.data() + first_weight, &nan, sizeof nan);
  std::uint64_t h = 0xcbf29ce484222325ULL;  // FNV-1a over the body, stored little-endian at the end
  for (std::size_t i = 0; i + 8 < bad.size(); ++i) {
    h ^= static_cast<unsigned char>(bad[i]);
    h *= 0x100000001b3ULL;
  }
  for (int i = 0; i < 8; ++i) bad[bad.size() - 8 + i] = static_cast<char>(h >> (8 * i));
  const std::string error = error_of(bad);
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
  EXPECT_EQ(error.find("checksum"), std::string::npos) << error;
}

TEST_F(ModelFileTest, DevicesAreRefusedBeforeReading) {
  auto loaded = load_vae_model("/dev/zero");  // read whole, it would never end
  ASSERT_FALSE(loaded);
  EXPECT_NE(loaded.error().message.find("not a regular file"), std::string::npos) << loaded.error().message;
}

TEST_F(ModelFileTest, StudentTModelRoundTripsAsVersion2) {
  VaeModel m = model_;
  m.observation = Observation::student_t;
  m.degrees_of_freedom = {1.5, 2.0, 3.25, 4.0, 7.5, 30.0};
  const std::string p = (dir_ / "student.dgvae").string();
  ASSERT_TRUE(save_vae_model(m, p));
  const std::vector<char> bytes = read_all(p);
  EXPECT_EQ(bytes[8], 2);  // version
  EXPECT_EQ(bytes.size(), bytes_.size() + 4 + 8 * 6);  // observation code and the degrees of freedom
  auto loaded = load_vae_model(p);
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(loaded->observation, Observation::student_t);
  EXPECT_EQ(loaded->degrees_of_freedom, m.degrees_of_freedom);
  EXPECT_EQ(loaded->log_sigma, m.log_sigma);
  // Unknown observation codes and degrees of freedom <= 1 are rejected.
  std::vector<char> bad = bytes;
  bad[28] = 5;
  EXPECT_NE(error_of(bad).find("observation"), std::string::npos) << error_of(bad);
  m.degrees_of_freedom[3] = 1.0;
  EXPECT_FALSE(m.validate());
  EXPECT_FALSE(save_vae_model(m, p));
}

TEST(VaeModel, ObservationLogDensities) {
  VaeModel m = testing::random_model();
  Eigen::VectorXd s(6), mean(6);
  s << 0.3, -1.0, 2.0, 0.0, 0.5, -0.25;
  mean << 0.1, -0.5, 1.0, 0.2, 0.5, 0.75;
  double gauss = 0.0, student = 0.0;
  const double nu = 3.0;
  for (int i = 0; i < 6; ++i) {
    const double sigma = std::exp(m.log_sigma[i]), r = (s(i) - mean(i)) / sigma;
    gauss += -0.5 * r * r - std::log(sigma * std::sqrt(2.0 * std::numbers::pi));
    // Student-t with 3 degrees of freedom: 2 / (pi sqrt(3) sigma (1 + r^2/3)^2).
    student += std::log(2.0 / (std::numbers::pi * std::sqrt(3.0) * sigma)) - 2.0 * std::log1p(r * r / nu);
  }
  EXPECT_NEAR(m.log_observation(s, mean), gauss, 1e-12);
  m.observation = Observation::student_t;
  m.degrees_of_freedom.fill(nu);
  EXPECT_NEAR(m.log_observation(s, mean), student, 1e-12);
}

TEST(VaeModel, DecoderIsTheMlpWithElu) {
  VaeModel m = testing::random_model({4}, 2);
  Eigen::Vector2d z(0.3, -1.2);
  Eigen::VectorXd h = m.decoder[0].weight * z + m.decoder[0].bias;
  for (int i = 0; i < h.size(); ++i) h(i) = h(i) > 0 ? h(i) : std::exp(h(i)) - 1.0;
  const Eigen::VectorXd s = m.decoder[1].weight * h + m.decoder[1].bias;
  const Eigen::MatrixXd out = m.decode(z);
  for (int i = 0; i < kFeatureCount; ++i) {
    EXPECT_NEAR(out(i, 0), s(i) * m.feature_std[i] + m.feature_mean[i], 1e-12);
  }
}

TEST(VaeModel, CommittedModelLoads) {
  auto loaded = load_vae_model(default_model_path());
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(loaded->latent_dim, 8);
  EXPECT_EQ(loaded->hidden, (std::vector<int>{128, 32, 16}));
  EXPECT_EQ(loaded->observation, Observation::student_t);  // docs/SAMPLER.md, "Models"
  // The program's default is the same model built in: no source tree needed where it runs.
  auto builtin = builtin_vae_model();
  ASSERT_TRUE(builtin) << builtin.error().message;
  EXPECT_EQ(builtin->hidden, loaded->hidden);
  const Eigen::MatrixXd z = Eigen::MatrixXd::Random(loaded->latent_dim, 5);
  EXPECT_EQ(builtin->decode_standardised(z), loaded->decode_standardised(z));
}

}  // namespace
}  // namespace drapegen::sampler
