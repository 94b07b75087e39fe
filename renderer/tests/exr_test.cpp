// Acceptance 3 (files) and 4: EXR round trip through the library's reader and OpenEXR's own API, the storage error
// bound, byte-identical files for the same seed.
#include <gtest/gtest.h>

#include <ImfInputFile.h>
#include <ImfHeader.h>
#include <ImfChannelList.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "drapegen/renderer/data_point.hpp"
#include "drapegen/renderer/exr.hpp"
#include "drapegen/renderer/random.hpp"
#include "drapegen/renderer/software_renderer.hpp"

namespace drapegen::renderer {
namespace {

std::string temp_path(const std::string& name) { return ::testing::TempDir() + "drapegen_exr_" + name; }

std::vector<char> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// A data point with smooth depth in [0.5, 1.5] m, holes, and distinct cameras per view.
DataPointRecord sample_point() {
  DataPointRecord p;
  p.index = 3;
  p.orientation = 1.25;
  p.seed = 18446744073709551557ULL;  // needs all 64 bits
  p.noise = "test noise";
  p.source = "drape.ply";
  const RigSpec rig;
  for (int v = 0; v < 4; ++v) {
    ViewRecord r;
    r.depth = DepthImage(240, 180);
    for (int y = 0; y < 180; ++y) {
      for (int x = 0; x < 240; ++x) {
        const bool hole = (x / 20 + y / 20 + v) % 3 == 0;
        r.depth.at(x, y) = hole ? 0.0f : static_cast<float>(1.0 + 0.5 * std::sin(0.03 * x + 0.05 * y + v));
      }
    }
    r.camera = rig.camera();
    r.camera.intrinsics.K(0, 1) = 0.01 * v;
    r.camera.world_to_camera = r.camera.world_to_camera * rig.table_pose(p.orientation, v);
    r.table_angle = p.orientation + v * M_PI / 2;
    r.noise_seed = mix_seed(p.seed, v);
    p.views.push_back(r);
  }
  return p;
}

void expect_same_metadata(const DataPointRecord& a, const DataPointRecord& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.orientation, b.orientation);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.noise, b.noise);
  EXPECT_EQ(a.source, b.source);
  ASSERT_EQ(a.views.size(), b.views.size());
  for (std::size_t v = 0; v < a.views.size(); ++v) {
    // Stored as 32-bit floats: 1e-7 relative, 0.1 um on a 1 m translation.
    EXPECT_TRUE(a.views[v].camera.intrinsics.K.isApprox(b.views[v].camera.intrinsics.K, 1e-7));
    EXPECT_LT((a.views[v].camera.world_to_camera.matrix() - b.views[v].camera.world_to_camera.matrix())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-6);
    EXPECT_EQ(a.views[v].table_angle, b.views[v].table_angle);
    EXPECT_EQ(a.views[v].noise_seed, b.views[v].noise_seed);
    EXPECT_EQ(a.views[v].camera.intrinsics.width, 240);
  }
}

TEST(Exr, FloatRoundTripIsExact) {
  const DataPointRecord p = sample_point();
  const ExrWriter writer(ExrStorage{.pixel = ExrStorage::Pixel::kFloat, .compression = "zip"});
  const std::string path = temp_path("float.exr");
  ASSERT_TRUE(writer.write_file(path, p));
  auto back = read_exr(path);
  ASSERT_TRUE(back) << back.error().message;
  expect_same_metadata(p, *back);
  for (std::size_t v = 0; v < 4; ++v) EXPECT_EQ(back->views[v].depth.depth, p.views[v].depth.depth);
  // The bytes in memory are the file's bytes.
  auto bytes = writer.encode(p);
  ASSERT_TRUE(bytes);
  EXPECT_EQ(*bytes, read_bytes(path));
  std::remove(path.c_str());
}

TEST(Exr, HalfStorageErrorStaysWithinItsBound) {
  const DataPointRecord p = sample_point();
  for (const std::string compression : {"zip", "piz", "zips", "rle", "none"}) {
    for (double quantum : {0.0, 0.001}) {
      const ExrStorage storage{.pixel = ExrStorage::Pixel::kHalf, .compression = compression, .quantum = quantum};
      auto bytes = ExrWriter(storage).encode(p);
      ASSERT_TRUE(bytes) << compression;
      auto back = read_exr(*bytes);
      ASSERT_TRUE(back) << back.error().message;
      expect_same_metadata(p, *back);
      double worst = 0.0;
      for (std::size_t v = 0; v < 4; ++v) {
        for (std::size_t i = 0; i < p.views[v].depth.depth.size(); ++i) {
          const float a = p.views[v].depth.depth[i], b = back->views[v].depth.depth[i];
          ASSERT_EQ(a == 0.0f, b == 0.0f) << "no-return pixels stay exactly 0";
          worst = std::max(worst, static_cast<double>(std::abs(a - b)));
        }
      }
      EXPECT_LE(worst, storage.max_error(1.5) + 1e-9) << compression << " quantum " << quantum;
      EXPECT_GT(worst, 0.0);
    }
  }
  // The bound itself: half below 1 m rounds to 2^-12 m (0.24 mm), below 2 m to 0.49 mm.
  EXPECT_NEAR(ExrStorage{}.max_error(0.95), std::ldexp(1.0, -12), 1e-12);
  EXPECT_LT(ExrStorage{}.max_error(1.0), 0.0005);
}

TEST(Exr, DataWindowIsTheBoundingBoxOfReturns) {
  DataPointRecord p = sample_point();
  for (auto& v : p.views) {
    for (int y = 0; y < 180; ++y)
      for (int x = 0; x < 240; ++x)
        if (x < 30 || x > 200 || y < 10 || y > 150) v.depth.at(x, y) = 0.0f;
  }
  const std::string path = temp_path("window.exr");
  ASSERT_TRUE(ExrWriter().write_file(path, p));
  {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i data = file.header().dataWindow(), display = file.header().displayWindow();
    EXPECT_EQ(data.min.x, 30);
    EXPECT_EQ(data.max.x, 200);
    EXPECT_EQ(data.min.y, 10);
    EXPECT_EQ(data.max.y, 150);
    EXPECT_EQ(display.max.x, 239);
    EXPECT_EQ(display.max.y, 179);
  }
  auto back = read_exr(path);
  ASSERT_TRUE(back);
  for (int v = 0; v < 4; ++v) {
    for (std::size_t i = 0; i < p.views[v].depth.depth.size(); ++i) {
      ASSERT_NEAR(back->views[v].depth.depth[i], p.views[v].depth.depth[i], 0.0005);
      ASSERT_EQ(back->views[v].depth.depth[i] == 0.0f, p.views[v].depth.depth[i] == 0.0f);
    }
  }
  // All views empty: still a valid file of zeros.
  for (auto& v : p.views) std::fill(v.depth.depth.begin(), v.depth.depth.end(), 0.0f);
  auto bytes = ExrWriter().encode(p);
  ASSERT_TRUE(bytes);
  auto empty = read_exr(*bytes);
  ASSERT_TRUE(empty);
  EXPECT_EQ(empty->views[0].depth.foreground_count(), 0);
  EXPECT_EQ(empty->views[0].depth.width, 240);
  std::remove(path.c_str());
}

TEST(Exr, OpenExrsOwnApiSeesTheLayout) {
  const std::string path = temp_path("layout.exr");
  ASSERT_TRUE(ExrWriter().write_file(path, sample_point()));
  Imf::InputFile file(path.c_str());
  const Imf::Header& h = file.header();
  for (int v = 0; v < 4; ++v) {
    const Imf::Channel* c = h.channels().findChannel("view" + std::to_string(v) + ".Z");
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(c->type, Imf::HALF);
  }
  EXPECT_EQ(h.compression(), Imf::ZIP_COMPRESSION);
  EXPECT_NE(h.find("view3.meshToCamera"), h.end());
  EXPECT_NE(h.find("drapegen.units"), h.end());
  std::remove(path.c_str());
}

TEST(Exr, ReportsBadInputAndUnwritablePaths) {
  EXPECT_FALSE(read_exr(std::string("/nonexistent/file.exr")));
  EXPECT_FALSE(read_exr(std::vector<char>{'n', 'o', 't', ' ', 'e', 'x', 'r'}));
  auto bytes = ExrWriter().encode(sample_point());
  ASSERT_TRUE(bytes);
  bytes->resize(bytes->size() / 2);
  EXPECT_FALSE(read_exr(*bytes));
  EXPECT_FALSE(ExrWriter().write_file("/nonexistent-dir/x.exr", sample_point()));
  EXPECT_FALSE(ExrWriter(ExrStorage{.compression = "jpeg"}).validate());
  EXPECT_FALSE(ExrWriter().encode(DataPointRecord{}));
}

TEST(Exr, OwnWriterWritesWhatOpenExrsWriterWrites) {
  // encode() writes NONE, ZIPS and ZIP files itself, OpenEXR's Imf::OutputFile is the reference: the same bytes
  // uncompressed; deflated by libdeflate instead of zlib, other bytes that OpenEXR reads back to the same pixels and
  // attributes. Smooth depth with holes; no return at all (a one-pixel data window: deflate makes it longer, so it
  // is stored raw); random depth (deflate gains little); 11 views (channels sort as view0, view1, view10, view2...).
  std::vector<DataPointRecord> points = {sample_point(), sample_point(), sample_point(), sample_point()};
  for (auto& v : points[1].views) v.depth = DepthImage(240, 180);
  std::uint64_t state = 5;
  for (auto& v : points[2].views) {
    for (float& z : v.depth.depth) {
      state = mix_seed(state, 1);
      z = 0.5f + static_cast<float>(state >> 40) * 0x1p-24f;
    }
  }
  while (points[3].views.size() < 11) points[3].views.push_back(points[3].views[points[3].views.size() % 4]);
  int compared = 0;
  for (const auto pixel : {ExrStorage::Pixel::kHalf, ExrStorage::Pixel::kFloat}) {
    for (const std::string compression : {"none", "zips", "zip"}) {
      for (const int level : {1, 3, 9}) {
        ExrStorage storage;
        storage.pixel = pixel;
        storage.compression = compression;
        storage.zip_level = level;
        const ExrWriter writer(storage);
        for (const auto& point : points) {
          const auto own = writer.encode(point), reference = writer.encode_with_openexr(point);
          ASSERT_TRUE(own && reference);
          const std::string what = compression + " level " + std::to_string(level) + ", data point of " +
                                   std::to_string(point.views.size()) + " views";
          if (compression == "none") {
            EXPECT_EQ(*own, *reference) << what;
          }
          const auto a = read_exr(*own), b = read_exr(*reference);
          ASSERT_TRUE(a && b) << what;
          expect_same_metadata(*a, *b);
          ASSERT_EQ(a->views.size(), b->views.size());
          for (std::size_t v = 0; v < a->views.size(); ++v) {
            EXPECT_EQ(a->views[v].depth.depth, b->views[v].depth.depth) << what << ", view " << v;
          }
          ++compared;
        }
      }
    }
  }
  EXPECT_EQ(compared, 72);
}

TEST(Exr, SameSeedGivesByteIdenticalFilesDifferentSeedsDiffer) {
  // The whole pipeline on a small scene: a hemisphere-ish cap on the cylinder.
  TriangleMesh cloth;
  const int n = 24;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = -0.15 + 0.3 * i / n, y = -0.15 + 0.3 * j / n, r = std::hypot(x, y);
      cloth.vertices.emplace_back(x, y, r < 0.05 ? 0.001 : 0.001 - 0.6 * (r - 0.05));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      cloth.triangles.push_back({a, a + 1, a + n + 2});
      cloth.triangles.push_back({a, a + n + 2, a + n + 1});
    }
  }
  SoftwareRenderer renderer;  // --renderer software; the default (OSMesa) is checked the same way in cli.render
  auto encode_all = [&](std::uint64_t seed) {
    RenderRequest request;
    request.seed = seed;
    request.augmentation.orientations = 2;
    auto points = render_data_points(renderer, cloth, request);
    EXPECT_TRUE(points) << points.error().message;
    std::vector<std::vector<char>> files;
    for (const auto& p : *points) files.push_back(*ExrWriter().encode(p));
    return files;
  };
  const auto a = encode_all(7), b = encode_all(7), c = encode_all(8);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a, b);
  EXPECT_NE(a[0], c[0]);
  EXPECT_NE(a[1], c[1]);
}

}  // namespace
}  // namespace drapegen::renderer
