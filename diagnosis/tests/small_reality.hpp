// Test fixture: a small capture of the reality generator (a 14x14 specimen of one medium fabric), written under the
// temporary directory and read back, for tests that need a capture whose truth they know.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <unistd.h>
#include <vector>

#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/reality.hpp"

namespace drapegen::diagnosis::fixture {

struct SmallReality {
  RealitySpec spec;
  std::filesystem::path dir;
  std::string truth_path;
  Capture capture;
};

/// The spec the tests share: the fabric of the CLI's examples on a 14x14 mesh, `effects` as `drapegen reality
/// --effect` takes them.
inline RealitySpec small_reality_spec(const std::vector<std::string>& effects = {}, std::uint64_t seed = 0) {
  RealitySpec spec;
  spec.bending.alpha = {13923, 11455, 8821};
  spec.bending.beta = {-35390, -29660, -22042};
  spec.resolution = 14;
  spec.seed = seed;
  for (const auto& e : effects) {
    auto parsed = parse_reality_effect(e);
    EXPECT_TRUE(parsed.has_value()) << e;
    if (parsed) spec.effects.push_back(*parsed);
  }
  return spec;
}

/// `spec` generated into a fresh directory named `name` (under one per test process) and read back; unset, with the
/// reason reported as a test failure, if either step fails.
inline std::optional<SmallReality> generate_small_reality(const std::string& name, const RealitySpec& spec) {
  SmallReality r;
  r.spec = spec;
  r.dir = std::filesystem::temp_directory_path() / ("drapegen_small_reality_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(r.dir);
  auto made = generate_reality(spec, r.dir.string());
  EXPECT_TRUE(made.has_value()) << (made ? "" : made.error().message);
  if (!made) return std::nullopt;
  r.truth_path = made->truth_path;
  auto capture = read_capture(r.dir.string());
  EXPECT_TRUE(capture.has_value()) << (capture ? "" : capture.error().message);
  if (!capture) return std::nullopt;
  r.capture = std::move(capture).value();
  return r;
}

}  // namespace drapegen::diagnosis::fixture
