#include "drapegen/sampler/vae_model.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

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
  bad[8] = 2;  // version
  EXPECT_NE(error_of(bad).find("version 2"), std::string::npos);
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
}

}  // namespace
}  // namespace drapegen::sampler
