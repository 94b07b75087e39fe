// Acceptance 1: the C++ decoder reproduces PyTorch's decoder on fixed latents within 1e-5. Runs /usr/bin/python3 with
// PyTorch (Debian's python3-torch); skips, saying why, only when that interpreter cannot import torch.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <nlohmann/json.hpp>

#include "drapegen/sampler/vae_model.hpp"

namespace drapegen::sampler {
namespace {

namespace fs = std::filesystem;
const std::string kPython = "/usr/bin/python3";
const std::string kSource = DRAPEGEN_SOURCE_DIR;

bool torch_available() {
  return std::system((kPython + " -c 'import torch, numpy, scipy' > /dev/null 2>&1").c_str()) == 0;
}

/// Runs a shell command and returns its standard output (empty and a failure on a non-zero exit).
testing::AssertionResult run(const std::string& command, std::string& out) {
  out.clear();
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return testing::AssertionFailure() << "cannot run " << command;
  std::array<char, 4096> buffer;
  std::size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  if (status != 0) return testing::AssertionFailure() << "'" << command << "' exited with " << status;
  return testing::AssertionSuccess();
}

/// Decodes PyTorch's reference lines (latents, then six features) with the C++ model; returns the largest
/// absolute difference and checks that the lines are complete.
double max_difference(const VaeModel& model, const std::string& reference, int expected_lines) {
  std::istringstream in(reference);
  std::string line;
  double worst = 0.0;
  int lines = 0;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    Eigen::VectorXd z(model.latent_dim);
    for (int i = 0; i < model.latent_dim; ++i) fields >> z(i);
    std::array<double, kFeatureCount> torch_out;
    for (double& v : torch_out) fields >> v;
    EXPECT_FALSE(fields.fail()) << "short reference line: " << line;
    const Eigen::MatrixXd ours = model.decode(z);
    for (int i = 0; i < kFeatureCount; ++i) {
      const double difference = std::abs(ours(i, 0) - torch_out[i]);
      EXPECT_TRUE(std::isfinite(difference)) << "feature " << i << " of " << line;  // max() would skip a NaN
      if (std::isfinite(difference)) worst = std::max(worst, difference);
    }
    ++lines;
  }
  EXPECT_EQ(lines, expected_lines);
  return worst;
}

TEST(TorchReference, CommittedDecoderMatchesPyTorch) {
  if (!torch_available()) GTEST_SKIP() << kPython << " cannot import torch/numpy/scipy: apt-get install python3-torch";
  auto model = load_vae_model(default_model_path());
  ASSERT_TRUE(model) << model.error().message;
  std::string reference;
  ASSERT_TRUE(run(kPython + " " + kSource + "/training/vae/reference_decode.py --checkpoint " + kSource +
                      "/training/vae/models/vae3.pt --count 256 --seed 11",
                  reference));
  const double worst = max_difference(*model, reference, 256);
  RecordProperty("max_abs_difference", std::to_string(worst));
  std::cout << "committed VAE-3: largest |C++ - PyTorch| over 256 latents x 6 features = " << worst << "\n";
  EXPECT_LT(worst, 1e-5);
}

TEST(TorchReference, FreshlyTrainedDecoderMatchesPyTorch) {
  // A tiny training run end to end (Student-t observation, format version 2): train.py exports the model file and the
  // PyTorch state; both decode the same latents.
  if (!torch_available()) GTEST_SKIP() << kPython << " cannot import torch/numpy/scipy: apt-get install python3-torch";
  const fs::path dir = fs::temp_directory_path() / ("drapegen_torch_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string out;
  ASSERT_TRUE(run(kPython + " " + kSource + "/training/vae/train.py --models VAE-4 --epochs 3 --iw-samples 10" +
                      " --observation student --generated 300 --seed 5 --export VAE-4=" + (dir / "m.dgvae").string() +
                      " --checkpoint " + (dir / "m.pt").string() + " 2>/dev/null",
                  out));
  auto model = load_vae_model((dir / "m.dgvae").string());
  ASSERT_TRUE(model) << model.error().message;
  EXPECT_EQ(model->observation, Observation::student_t);
  std::string reference;
  ASSERT_TRUE(run(kPython + " " + kSource + "/training/vae/reference_decode.py --checkpoint " +
                      (dir / "m.pt").string() + " --count 64 --seed 3",
                  reference));
  const double worst = max_difference(*model, reference, 64);
  std::cout << "freshly trained VAE-4: largest |C++ - PyTorch| over 64 latents x 6 features = " << worst << "\n";
  EXPECT_LT(worst, 1e-5);
  fs::remove_all(dir);
}

std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(TorchReference, TrainingIsReproducibleFromASeed) {
  if (!torch_available()) GTEST_SKIP() << kPython << " cannot import torch/numpy/scipy: apt-get install python3-torch";
  const fs::path dir = fs::temp_directory_path() / ("drapegen_seed_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto train = [&](int seed, const std::string& name) {
    std::string out;
    EXPECT_TRUE(run(kPython + " " + kSource + "/training/vae/train.py --models VAE-4 --epochs 4 --check-every 2" +
                        " --observation student --kl-warmup 2 --lr-final 1e-5 --iw-samples 9 --generated 300" +
                        " --seed " + std::to_string(seed) + " --export VAE-4=" +
                        (dir / name).string() + " 2>/dev/null",
                    out));
    return file_bytes(dir / name);
  };
  const std::string a = train(5, "a.dgvae"), b = train(5, "b.dgvae"), c = train(6, "c.dgvae");
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, b) << "two trainings with seed 5 exported different weights";
  EXPECT_NE(a, c) << "seeds 5 and 6 exported the same weights";
  fs::remove_all(dir);
}

TEST(TorchReference, CrossValidationValidatesEveryFabricOnce) {
  // training/vae/crossval.py on two folds with a tiny VAE-4: the folds partition the 251 distinct fabrics, the pooled
  // figures are those of the per-fabric ones, the best GMM is the rule's, and bad fold numbers are refused.
  if (!torch_available()) GTEST_SKIP() << kPython << " cannot import torch/numpy/scipy: apt-get install python3-torch";
  const fs::path dir = fs::temp_directory_path() / ("drapegen_crossval_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string script = kPython + " " + kSource + "/training/vae/crossval.py --folds 2 --dir " + dir.string();
  std::string out;
  for (int fold = 0; fold < 2; ++fold)
    ASSERT_TRUE(run(script + " --fold " + std::to_string(fold) +
                        " --vae VAE-4 --epochs 2 --check-every 1 --iw-samples 9 --generated 300 2>/dev/null",
                    out));
  ASSERT_TRUE(run(script + " --summarise", out));
  EXPECT_NE(out.find("2-fold cross-validation over 251 distinct fabrics (fold sizes 125, 126"), std::string::npos)
      << out;
  std::ifstream in(dir / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  const auto& models = summary.at("models");
  ASSERT_EQ(models.size(), 6u);
  std::string best;
  for (int k = 3; k <= 7; ++k) {
    const std::string name = "GMM-" + std::to_string(k);
    if (best.empty() || models.at(name).at("ll_mean") > models.at(best).at("ll_mean")) best = name;
    // The mean of the paired per-fabric differences is the difference of the pooled means.
    const auto& d = summary.at("ll_vae_minus").at(name);
    EXPECT_NEAR(d.at("mean").get<double>(),
                models.at("VAE-4").at("ll_mean").get<double>() - models.at(name).at("ll_mean").get<double>(), 1e-9);
    EXPECT_EQ(d.at("n").get<int>(), 251);
    const auto& e = summary.at("energy_gmm_minus_vae").at(name);
    EXPECT_NEAR(e.at("mean").get<double>(),
                models.at(name).at("energy").get<double>() - models.at("VAE-4").at("energy").get<double>(), 1e-9);
  }
  EXPECT_EQ(summary.at("best_gmm_ll").get<std::string>(), best);
  EXPECT_FALSE(run(script + " --fold 2 2>/dev/null", out)) << "fold 2 of 2 accepted";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace drapegen::sampler
