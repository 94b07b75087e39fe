#include "drapegen/sampler/fabric_data.hpp"
#include "drapegen/sampler/parameters.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "drapegen/sampler/random.hpp"

namespace drapegen::sampler {
namespace {

namespace fs = std::filesystem;

TEST(Random, SameSeedSameStreamDifferentSeedsDiffer) {
  Random a(0), b(0), c(1);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const std::uint64_t x = a.next_u64();
    EXPECT_EQ(x, b.next_u64());
    differs = differs || x != c.next_u64();
  }
  EXPECT_TRUE(differs);
  EXPECT_NE(derive_seed(0, {1, 0}), derive_seed(0, {1, 1}));
  EXPECT_NE(derive_seed(0, {1, 2}), derive_seed(0, {2, 1}));
  EXPECT_NE(derive_seed(0, {1}), derive_seed(1, {1}));
}

TEST(Random, UniformAndNormalMoments) {
  Random rng(0);
  const int n = 200000;
  double su = 0, sn = 0, sn2 = 0, sn4 = 0;
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform();
    ASSERT_TRUE(u >= 0.0 && u < 1.0);
    su += u;
    const double z = rng.normal();
    sn += z, sn2 += z * z, sn4 += z * z * z * z;
  }
  EXPECT_NEAR(su / n, 0.5, 0.005);
  EXPECT_NEAR(sn / n, 0.0, 0.01);
  EXPECT_NEAR(sn2 / n, 1.0, 0.01);
  EXPECT_NEAR(sn4 / n, 3.0, 0.06);
  std::vector<int> counts(6);
  for (int i = 0; i < 60000; ++i) ++counts[rng.below(6)];
  for (int c : counts) EXPECT_NEAR(c, 10000, 400);
}

TEST(Parameters, FeaturesRoundTripAndSignedLog) {
  const ParameterVector p{{13923, 11455, 8821}, {-35390, -29660, 22042}};
  const Features f = to_features(p);
  EXPECT_NEAR(f[0], std::log(13923.0), 1e-15);
  EXPECT_NEAR(f[3], -std::log(35390.0), 1e-15);
  EXPECT_NEAR(f[5], std::log(22042.0), 1e-15);
  const ParameterVector q = from_features(f);
  EXPECT_NEAR(q.alpha.bias, 11455, 1e-9);
  EXPECT_NEAR(q.beta.warp, -35390, 1e-9);
  EXPECT_NEAR(q.beta.weft, 22042, 1e-9);
}

TEST(Parameters, DensityConversionKeepsKOverRho) {
  const ParameterVector measured{{1000, 2000, 3000}, {-100, -200, 300}};
  const ParameterVector normalised = normalise_density(measured, 150.0);
  EXPECT_DOUBLE_EQ(normalised.alpha.warp, 2000.0);
  EXPECT_DOUBLE_EQ(normalised.beta.weft, 600.0);
  const ParameterVector back = at_density(normalised, 150.0);
  EXPECT_DOUBLE_EQ(back.alpha.weft, 3000.0);
  EXPECT_DOUBLE_EQ(at_density(normalised, 450.0).alpha.warp, 3000.0);
}

TEST(Parameters, ReadsTheMeasuredFabrics) {
  auto fabrics = read_fabric_csv(DRAPEGEN_FABRIC_DATA);
  ASSERT_TRUE(fabrics) << fabrics.error().message;
  ASSERT_EQ(fabrics->size(), 618u);
  // First row: 0.0673, 1779.9 (warp), 3076.2 (weft), 2244.1 (diag), -8478.2, -4158.5, -3351.1.
  const MeasuredFabric& f = fabrics->front();
  EXPECT_DOUBLE_EQ(f.density_g_per_m2, 67.3);
  EXPECT_DOUBLE_EQ(f.moduli.alpha.warp, 1779.9);
  EXPECT_DOUBLE_EQ(f.moduli.alpha.bias, 2244.1);
  EXPECT_DOUBLE_EQ(f.moduli.alpha.weft, 3076.2);
  EXPECT_DOUBLE_EQ(f.moduli.beta.bias, -3351.1);
  EXPECT_EQ(distinct_features(*fabrics).size(), 251u);
}

class CsvErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (fs::temp_directory_path() / ("drapegen_csv_test_" + std::to_string(::getpid()) + ".csv")).string();
  }
  void TearDown() override { fs::remove(path_); }
  std::string error_of(const std::string& content) {
    std::ofstream(path_) << content;
    auto r = read_fabric_csv(path_);
    return r ? std::string() : r.error().message;
  }
  std::string path_;
};

TEST_F(CsvErrors, BadFilesSayWhatIsWrong) {
  const std::string header = "density, linear warp, linear weft, linear diag, nonlinear warp, nonlinear weft, "
                             "nonlinear diag\n";
  EXPECT_NE(error_of("").find("empty"), std::string::npos);
  // No header (its first fabric would have been skipped), or columns in another order.
  EXPECT_NE(error_of("0.1,1,2,3,4,5,6\n0.1,1,2,3,4,5,6\n").find("line 1: expected the header"), std::string::npos);
  EXPECT_NE(error_of("density,warp,diag,weft,warp,diag,weft\n0.1,1,2,3,4,5,6\n").find("line 1"), std::string::npos);
  EXPECT_NE(error_of(header).find("no rows"), std::string::npos);
  EXPECT_NE(error_of(header + "0.1,1,2,3,4,5\n").find("line 2"), std::string::npos);
  EXPECT_NE(error_of(header + "0.1,1,2,3,4,5,6,7\n").find("7 finite"), std::string::npos);
  EXPECT_NE(error_of(header + "0.1,1,2,3,4,5,6\n0.1,1,x,3,4,5,6\n").find("line 3"), std::string::npos);
  EXPECT_NE(error_of(header + "0.1,1,2,3,4,nan,6\n").find("finite"), std::string::npos);
  EXPECT_NE(error_of(header + "-0.1,1,2,3,4,5,6\n").find("positive"), std::string::npos);
  EXPECT_NE(error_of(header + "0.1,1,0,3,4,5,6\n").find("non-zero"), std::string::npos);
  // The nonlinear block first: its moduli would be read as alpha.
  EXPECT_NE(error_of("density, nonlinear warp, nonlinear weft, nonlinear diag, linear warp, linear weft, linear diag\n"
                     "0.1,-4,-5,-6,1,2,3\n")
                .find("line 1"),
            std::string::npos);
  EXPECT_NE(error_of(header + "0.1,-1,2,3,4,5,6\n").find("line 2: the linear moduli"), std::string::npos);
  // Moduli in SI (1.8e-6 rather than 1779.9): ln would turn them into large features of the other sign.
  EXPECT_NE(error_of(header + "0.0673,1.78e-6,3.07e-6,2.24e-6,-8.4e-9,-4.1e-9,-3.3e-9\n").find("line 2: a modulus"),
            std::string::npos);
  EXPECT_TRUE(error_of(header + "0.1, 1 ,2,3,4,5,6\r\n\n").empty());
  auto missing = read_fabric_csv("/nonexistent/fabrics.csv");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("cannot open"), std::string::npos);
  auto directory = read_fabric_csv(fs::temp_directory_path().string());
  EXPECT_FALSE(directory);
}

}  // namespace
}  // namespace drapegen::sampler
