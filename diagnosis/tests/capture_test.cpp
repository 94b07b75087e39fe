#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <vector>
#include <nlohmann/json.hpp>

#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/depth_exr.hpp"
#include "drapegen/diagnosis/forward_model.hpp"
#include "drapegen/renderer/rig.hpp"

namespace fs = std::filesystem;
using namespace drapegen;
using namespace drapegen::diagnosis;

namespace {

Capture plane_capture() {
  renderer::RigSpec rig;
  Capture c;
  c.specimen.density = 250.0;
  for (int v = 0; v < kCaptureViews; ++v) {
    CaptureView view;
    view.camera = rig.camera();
    view.camera.world_to_camera = view.camera.world_to_camera * rig.table_pose(0.3, v);
    view.depth = renderer::DepthImage(rig.width, rig.height);
    for (int y = 40; y < 150; ++y)
      for (int x = 30; x < 200; ++x) view.depth.at(x, y) = 0.6f + 0.001f * static_cast<float>(y + v);
    c.views.push_back(view);
  }
  return c;
}

std::string fresh_dir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("drapegen_capture_test_" + name);
  fs::remove_all(p);
  return p.string();
}

std::string read_error(const std::string& dir) {
  const auto r = read_capture(dir);
  EXPECT_FALSE(r.has_value()) << dir;
  return r ? std::string() : r.error().message;
}

/// The reader's error on the capture in `dir` with its capture.json `good` edited by `edit`.
std::string error_with(const std::string& dir, nlohmann::json good, const std::function<void(nlohmann::json&)>& edit) {
  edit(good);
  std::ofstream(fs::path(dir) / "capture.json") << good.dump();
  return read_error(dir);
}

}  // namespace

TEST(Capture, RoundTrip) {
  const std::string dir = fresh_dir("roundtrip");
  const Capture c = plane_capture();
  ASSERT_TRUE(write_capture(dir, c).ok());
  const auto r = read_capture(dir);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  EXPECT_NEAR(r->specimen.density, 250.0, 1e-12);
  EXPECT_NEAR(r->specimen.cylinder_diameter, 0.1, 1e-12);
  ASSERT_EQ(r->views.size(), 4u);
  for (int v = 0; v < 4; ++v) {
    EXPECT_TRUE(r->views[v].camera.world_to_camera.isApprox(c.views[v].camera.world_to_camera, 1e-12));
    EXPECT_TRUE(r->views[v].camera.intrinsics.K.isApprox(c.views[v].camera.intrinsics.K, 1e-12));
    EXPECT_EQ(r->views[v].depth.depth, c.views[v].depth.depth);  // float EXR: exact
  }
}

TEST(Capture, AFailedWriteLeavesTheEarlierCaptureWhole) {
  const std::string dir = fresh_dir("rewrite");
  const Capture c = plane_capture();
  ASSERT_TRUE(write_capture(dir, c).ok());
  Capture other = plane_capture();
  for (auto& view : other.views) view.depth.at(100, 100) = 0.7f;
  other.views[3].depth.depth.pop_back();  // the last view cannot be encoded
  const auto s = write_capture(dir, other);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("view3.exr: bad depth image size"), std::string::npos) << s.error().message;
  const auto r = read_capture(dir);  // the first capture, every view of it
  ASSERT_TRUE(r.has_value()) << r.error().message;
  for (int v = 0; v < 4; ++v) EXPECT_EQ(r->views[v].depth.depth, c.views[v].depth.depth) << "view " << v;
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 5u);  // four views and capture.json: no temporary left
}

TEST(Capture, MeasuredBendingRoundTripsAndIsOptional) {
  const std::string dir = fresh_dir("measured");
  Capture c = plane_capture();
  ASSERT_TRUE(write_capture(dir, c).ok());
  auto r = read_capture(dir);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  EXPECT_FALSE(r->specimen.measured_bending.has_value());
  c.specimen.measured_bending = MeasuredBending{
      .bending = {.alpha = {5000.0, 4000.0, 3000.0}, .beta = {-12500.0, 800.0, -7500.0}}, .within_factor = 1.3,
      .method = "cantilever"};
  ASSERT_TRUE(write_capture(dir, c).ok());
  r = read_capture(dir);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  ASSERT_TRUE(r->specimen.measured_bending.has_value());
  const MeasuredBending& m = *r->specimen.measured_bending;
  EXPECT_EQ(m.bending.alpha.bias, 4000.0);
  EXPECT_EQ(m.bending.beta.bias, 800.0);  // a stiffening direction keeps its sign
  EXPECT_EQ(m.bending.beta.weft, -7500.0);
  EXPECT_EQ(m.within_factor, 1.3);
  EXPECT_EQ(m.method, "cantilever");
}

TEST(Capture, TheFaceRoundTripsIsUpByDefaultAndRefusesOtherValues) {
  const std::string dir = fresh_dir("face");
  Capture c = plane_capture();
  ASSERT_TRUE(write_capture(dir, c).ok());
  nlohmann::json written = nlohmann::json::parse(std::ifstream(fs::path(dir) / "capture.json"));
  EXPECT_FALSE(written.contains("face"));  // face up: the format's default, not written
  auto r = read_capture(dir);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  EXPECT_FALSE(r->face_down);
  c.face_down = true;
  ASSERT_TRUE(write_capture(dir, c).ok());
  written = nlohmann::json::parse(std::ifstream(fs::path(dir) / "capture.json"));
  EXPECT_EQ(written.value("face", ""), "down");
  r = read_capture(dir);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  EXPECT_TRUE(r->face_down);
  written["face"] = "up";
  std::ofstream(fs::path(dir) / "capture.json") << written.dump();
  r = read_capture(dir);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  EXPECT_FALSE(r->face_down);
  for (const nlohmann::json& bad : {nlohmann::json("Down"), nlohmann::json(true), nlohmann::json(1)}) {
    const std::string e = error_with(dir, written, [&](nlohmann::json& j) { j["face"] = bad; });
    EXPECT_NE(e.find("face must be \"up\" or \"down\""), std::string::npos) << e;
  }
}

TEST(Capture, BadMeasuredBendingIsAClearError) {
  const std::string dir = fresh_dir("measured_bad");
  ASSERT_TRUE(write_capture(dir, plane_capture()).ok());
  const nlohmann::json good = nlohmann::json::parse(std::ifstream(fs::path(dir) / "capture.json"));
  const std::vector<std::pair<nlohmann::json, std::string>> cases{
      {{{"alpha", {1, 2}}, {"beta", {0, 0, 0}}, {"within_factor", 1.2}}, "alpha must be [warp, bias, weft]"},
      {{{"alpha", {1, 0, 2}}, {"beta", {0, 0, 0}}, {"within_factor", 1.2}}, "alpha must be positive"},
      {{{"alpha", {1, 1, 2}}, {"beta", {0, "x", 0}}, {"within_factor", 1.2}}, "beta must be [warp, bias, weft]"},
      {{{"alpha", {1, 1, 2}}, {"beta", {0, 0, 0}}, {"within_factor", 1.0}},
       "within_factor must be a number in (1, 100]"},
      {{{"alpha", {1, 1, 2}}, {"beta", {0, 0, 0}}}, "needs \"alpha\", \"beta\" and \"within_factor\""},
      {{{"alpha", {1, 1, 2}}, {"beta", {0, 0, 0}}, {"within_factor", 2}, {"method", 3}}, "method must be a string"},
  };
  for (const auto& [measured, expected] : cases) {
    nlohmann::json j = good;
    j["specimen"]["measured_bending"] = measured;
    std::ofstream(fs::path(dir) / "capture.json") << j.dump();
    const std::string e = read_error(dir);
    EXPECT_NE(e.find("specimen.measured_bending"), std::string::npos) << e;
    EXPECT_NE(e.find(expected), std::string::npos) << e;
  }
}

TEST(Capture, MissingViewFile) {
  const std::string dir = fresh_dir("missing");
  ASSERT_TRUE(write_capture(dir, plane_capture()).ok());
  fs::remove(fs::path(dir) / "view2.exr");
  const std::string e = read_error(dir);
  EXPECT_NE(e.find("view 2"), std::string::npos) << e;
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;
}

TEST(Capture, MissingJsonAndWrongViewCount) {
  const std::string dir = fresh_dir("count");
  fs::create_directories(dir);
  EXPECT_NE(read_error(dir).find("capture.json: no such file"), std::string::npos);
  fs::create_directories(fs::path(dir) / "capture.json");
  EXPECT_NE(read_error(dir).find("capture.json: not a regular file"), std::string::npos) << read_error(dir);
  fs::remove(fs::path(dir) / "capture.json");
  ASSERT_TRUE(write_capture(dir, plane_capture()).ok());
  nlohmann::json j = nlohmann::json::parse(std::ifstream(fs::path(dir) / "capture.json"));
  j["views"].erase(3);
  std::ofstream(fs::path(dir) / "capture.json") << j.dump();
  EXPECT_NE(read_error(dir).find("3 views listed"), std::string::npos);
}

// Integers that are not (get<int> truncated 240.7 to 240 and version 1.5 to 1), and a view's missing key named with
// its view.
TEST(Capture, NonIntegersAndAViewsMissingKeyAreClearErrors) {
  const std::string dir = fresh_dir("fields");
  ASSERT_TRUE(write_capture(dir, plane_capture()).ok());
  const nlohmann::json good = nlohmann::json::parse(std::ifstream(fs::path(dir) / "capture.json"));
  const auto with = [&](const std::function<void(nlohmann::json&)>& edit) { return error_with(dir, good, edit); };
  EXPECT_NE(with([](nlohmann::json& j) { j["version"] = 1.5; }).find("unsupported version"), std::string::npos);
  const std::string width =
      with([](nlohmann::json& j) { j["views"][1]["width"] = j["views"][1]["width"].get<double>() + 0.7; });
  EXPECT_NE(width.find("views[1]: width and height must be integers"), std::string::npos) << width;
  const std::string pose = with([](nlohmann::json& j) { j["views"][2].erase("world_to_camera"); });
  EXPECT_NE(pose.find("views[2]: missing \"world_to_camera\""), std::string::npos) << pose;
  // A field of the wrong type is named (before: "missing or malformed field: type must be number, but is string").
  const std::string density = with([](nlohmann::json& j) { j["specimen"]["density_g_per_m2"] = "250"; });
  EXPECT_NE(density.find("specimen.density_g_per_m2 must be a number"), std::string::npos) << density;
  const std::string diameter = with([](nlohmann::json& j) { j["specimen"].erase("cylinder_diameter_mm"); });
  EXPECT_NE(diameter.find("specimen: missing \"cylinder_diameter_mm\""), std::string::npos) << diameter;
  const std::string size = with([](nlohmann::json& j) { j["specimen"]["size_mm"][1] = nullptr; });
  EXPECT_NE(size.find("specimen.size_mm must be [X, Y] numbers"), std::string::npos) << size;
  const std::string source = with([](nlohmann::json& j) { j["source"] = 5; });
  EXPECT_NE(source.find("source must be a string"), std::string::npos) << source;
  const std::string format = with([](nlohmann::json& j) { j["format"] = 1; });
  EXPECT_NE(format.find("not a capture"), std::string::npos) << format;
  std::ofstream(fs::path(dir) / "capture.json") << good.dump();
  EXPECT_TRUE(read_capture(dir).has_value());
}

// A field this format does not define is refused, named with where it sits: a misspelt optional field
// ("measured_bendng") was dropped unseen and the diagnosis ran without it. "notes" holds a tester's own metadata.
TEST(Capture, AnUnknownFieldIsNamedNotDropped) {
  const std::string dir = fresh_dir("unknown");
  ASSERT_TRUE(write_capture(dir, plane_capture()).ok());
  const nlohmann::json good = nlohmann::json::parse(std::ifstream(fs::path(dir) / "capture.json"));
  const auto with = [&](const std::function<void(nlohmann::json&)>& edit) { return error_with(dir, good, edit); };
  const std::string specimen = with([](nlohmann::json& j) {
    j["specimen"]["measured_bendng"] = {{"alpha", {1e4, 1e4, 1e4}}, {"beta", {-1e4, -1e4, -1e4}}};
  });
  EXPECT_NE(specimen.find("specimen: unknown field \"measured_bendng\" (it takes \"size_mm\""), std::string::npos)
      << specimen;
  const std::string top = with([](nlohmann::json& j) { j["sacn"] = "scan.ply"; });
  EXPECT_NE(top.find("capture.json: unknown field \"sacn\""), std::string::npos) << top;
  const std::string view = with([](nlohmann::json& j) { j["views"][3]["k"] = j["views"][3]["K"]; });
  EXPECT_NE(view.find("views[3]: unknown field \"k\""), std::string::npos) << view;
  const std::string measured = with([](nlohmann::json& j) {
    j["specimen"]["measured_bending"] = {
        {"alpha", {1e4, 1e4, 1e4}}, {"beta", {-1e4, -1e4, -1e4}}, {"within_factor", 1.2}, {"metod", "cantilever"}};
  });
  EXPECT_NE(measured.find("measured_bending: unknown field \"metod\""), std::string::npos) << measured;
  const std::string version = with([](nlohmann::json& j) { j["version"] = 2; });
  EXPECT_NE(version.find("unsupported version 2 (this build reads the integer 1)"), std::string::npos) << version;
  const std::string views = with([](nlohmann::json& j) { j["views"] = nlohmann::json::object(); });
  EXPECT_NE(views.find("\"views\" must be an array of 4 views"), std::string::npos) << views;
  nlohmann::json noted = good;
  noted["notes"] = {{"operator", "A. B."}, {"room_temperature_c", 21.5}};
  std::ofstream(fs::path(dir) / "capture.json") << noted.dump();
  EXPECT_TRUE(read_capture(dir).has_value());
}

TEST(Capture, WrongSize) {
  const std::string dir = fresh_dir("size");
  Capture c = plane_capture();
  ASSERT_TRUE(write_capture(dir, c).ok());
  ASSERT_TRUE(write_depth_exr((fs::path(dir) / "view1.exr").string(), renderer::DepthImage(120, 90)).ok());
  const std::string e = read_error(dir);
  EXPECT_NE(e.find("depth is 120x90 but the camera is 240x180"), std::string::npos) << e;
}

TEST(Capture, AllZeroDepth) {
  const std::string dir = fresh_dir("zero");
  Capture c = plane_capture();
  std::fill(c.views[0].depth.depth.begin(), c.views[0].depth.depth.end(), 0.0f);
  ASSERT_TRUE(write_capture(dir, c).ok());
  const std::string e = read_error(dir);
  EXPECT_NE(e.find("all-zero depth"), std::string::npos) << e;
}

TEST(Capture, NaNDepth) {
  const std::string dir = fresh_dir("nan");
  Capture c = plane_capture();
  c.views[3].depth.at(100, 100) = std::numeric_limits<float>::quiet_NaN();
  ASSERT_TRUE(write_capture(dir, c).ok());
  const std::string e = read_error(dir);
  EXPECT_NE(e.find("view 3"), std::string::npos) << e;
  EXPECT_NE(e.find("non-finite depth"), std::string::npos) << e;
}

TEST(Capture, FarDepthIsAClearError) {
  // A sensor's "no return" sentinel (FLT_MAX) rather than 0: beyond any tester, refused before it is back-projected.
  const std::string dir = fresh_dir("far");
  Capture c = plane_capture();
  c.views[2].depth.at(50, 60) = std::numeric_limits<float>::max();
  ASSERT_TRUE(write_capture(dir, c).ok());
  const std::string e = read_error(dir);
  EXPECT_NE(e.find("view 2"), std::string::npos) << e;
  EXPECT_NE(e.find("at pixel (50, 60) is beyond 10 m; use 0 for no return"), std::string::npos) << e;
}

TEST(Capture, ACameraThatIsNoneIsAClearError) {
  // Each camera fault written into capture.json, one at a time: a focal length of 0 (every ray the same: no image)
  // or negative, a pose whose last row is not 0 0 0 1, a camera a kilometre away.
  const std::string dir = fresh_dir("camera");
  ASSERT_TRUE(write_capture(dir, plane_capture()).ok());
  const nlohmann::json good = nlohmann::json::parse(std::ifstream(fs::path(dir) / "capture.json"));
  auto with = [&](const char* field, int row, int col, double value) {
    nlohmann::json j = good;
    j["views"][1][field][row][col] = value;
    std::ofstream(fs::path(dir) / "capture.json") << j.dump();
    return read_error(dir);
  };
  EXPECT_NE(with("K", 0, 0, 0.0).find("views[1].K: the focal lengths K[0][0] and K[1][1] must be positive"),
            std::string::npos);
  EXPECT_NE(with("K", 1, 1, -300.0).find("must be positive"), std::string::npos);
  EXPECT_NE(with("world_to_camera", 3, 0, 0.5).find("last row must be 0 0 0 1"), std::string::npos);
  const std::string far = with("world_to_camera", 0, 3, 1000.0);
  EXPECT_NE(far.find("views[1].world_to_camera: the camera is more than 9.67 m from the specimen (the model renders "
                     "to 10 m)"),
            std::string::npos)
      << far;
  // 20 m: farther than the diagnosis's renderer draws, so its model could never be compared with the capture.
  EXPECT_NE(with("world_to_camera", 0, 3, 20.0).find("the camera is more than 9.67 m"), std::string::npos);
  // A skew that makes K singular: every back-projected ray would be non-finite.
  nlohmann::json singular = good;
  singular["views"][1]["K"][0][1] = good["views"][1]["K"][0][0];
  singular["views"][1]["K"][1][0] = good["views"][1]["K"][1][1];
  std::ofstream(fs::path(dir) / "capture.json") << singular.dump();
  EXPECT_NE(read_error(dir).find("views[1].K: singular"), std::string::npos) << read_error(dir);
  // A mirrored pose (a row of the rotation negated: orthonormal, determinant -1) is named as a reflection.
  nlohmann::json mirrored = good;
  for (int k = 0; k < 4; ++k) {
    mirrored["views"][1]["world_to_camera"][0][k] = -good["views"][1]["world_to_camera"][0][k].get<double>();
  }
  std::ofstream(fs::path(dir) / "capture.json") << mirrored.dump();
  EXPECT_NE(read_error(dir).find("world_to_camera: not a rigid transform (a reflection"), std::string::npos)
      << read_error(dir);
  // One depth file under two poses: a view missing, which the view count alone does not show.
  nlohmann::json twice = good;
  twice["views"][2]["depth"] = good["views"][0]["depth"];
  std::ofstream(fs::path(dir) / "capture.json") << twice.dump();
  EXPECT_NE(read_error(dir).find("views[2]: depth view0.exr is views[0]'s file too"), std::string::npos)
      << read_error(dir);
  std::ofstream(fs::path(dir) / "capture.json") << good.dump();
  EXPECT_TRUE(read_capture(dir).has_value());
}

// K in other units than pixels: normalised by the image size, or in metres, it saw nothing of the model, scored 0 mm
// and read "within the floors"; a huge one crashed the renderer (single precision). The principal point must lie on
// the image and each field of view be 5 .. 170 degrees.
TEST(Capture, AnIntrinsicMatrixNotInPixelsIsAClearError) {
  const std::string dir = fresh_dir("intrinsics");
  ASSERT_TRUE(write_capture(dir, plane_capture()).ok());
  const nlohmann::json good = nlohmann::json::parse(std::ifstream(fs::path(dir) / "capture.json"));
  const auto with = [&](const std::function<void(nlohmann::json&)>& edit) { return error_with(dir, good, edit); };
  const double width = good["views"][0]["width"].get<double>(), height = good["views"][0]["height"].get<double>();
  const std::string normalised = with([&](nlohmann::json& j) {
    auto& K = j["views"][2]["K"];
    K[0][0] = K[0][0].get<double>() / width, K[1][1] = K[1][1].get<double>() / height;
    K[0][2] = K[0][2].get<double>() / width, K[1][2] = K[1][2].get<double>() / height;
  });
  EXPECT_NE(normalised.find("views[2].K: fields of view"), std::string::npos) << normalised;
  EXPECT_NE(normalised.find("(K is in pixels)"), std::string::npos) << normalised;
  const std::string huge = with([](nlohmann::json& j) { j["views"][2]["K"][0][0] = 1e39; });
  EXPECT_NE(huge.find("views[2].K: fields of view"), std::string::npos) << huge;
  const std::string off = with([](nlohmann::json& j) { j["views"][0]["K"][0][2] = -1e6; });
  EXPECT_NE(off.find("views[0].K: the principal point (-1e+06, "), std::string::npos) << off;
  EXPECT_NE(off.find("is off the 240x180 image"), std::string::npos) << off;
  const std::string below = with([&](nlohmann::json& j) { j["views"][1]["K"][1][2] = height + 1.0; });
  EXPECT_NE(below.find("views[1].K: the principal point"), std::string::npos) << below;
  std::ofstream(fs::path(dir) / "capture.json") << good.dump();
  EXPECT_TRUE(read_capture(dir).has_value());
}

// Integers beyond 32 bits wrapped (2^32 + 240 read as 240, 2^32 + 1 as version 1); a listed file must lie inside the
// capture directory (an absolute path or ".." read another capture's view), and be a regular file.
TEST(Capture, WrappedIntegersAndFilesOutsideTheCaptureAreClearErrors) {
  const std::string dir = fresh_dir("outside");
  ASSERT_TRUE(write_capture(dir, plane_capture()).ok());
  const nlohmann::json good = nlohmann::json::parse(std::ifstream(fs::path(dir) / "capture.json"));
  const auto with = [&](const std::function<void(nlohmann::json&)>& edit) { return error_with(dir, good, edit); };
  EXPECT_NE(with([](nlohmann::json& j) { j["version"] = 4294967297LL; }).find("unsupported version"),
            std::string::npos);
  const std::string wide = with([](nlohmann::json& j) { j["views"][1]["width"] = 4294967296LL + 240; });
  EXPECT_NE(wide.find("views[1]: width and height must be 8 .. 8192"), std::string::npos) << wide;
  const std::string absolute = with([&](nlohmann::json& j) { j["views"][3]["depth"] = dir + "/view3.exr"; });
  EXPECT_NE(absolute.find("views[3]: depth " + dir + "/view3.exr must be a path inside the capture directory"),
            std::string::npos)
      << absolute;
  const std::string up = with([](nlohmann::json& j) { j["views"][0]["depth"] = "../elsewhere/view0.exr"; });
  EXPECT_NE(up.find("must be a path inside the capture directory"), std::string::npos) << up;
  const std::string scan = with([](nlohmann::json& j) { j["scan"] = "/etc/passwd"; });
  EXPECT_NE(scan.find("scan /etc/passwd must be a path inside the capture directory"), std::string::npos) << scan;
  fs::create_directory(fs::path(dir) / "folder.exr");
  const std::string folder = with([](nlohmann::json& j) { j["views"][1]["depth"] = "folder.exr"; });
  EXPECT_NE(folder.find("view 1: " + (fs::path(dir) / "folder.exr").string() + " is not a regular file"),
            std::string::npos)
      << folder;
  std::ofstream(fs::path(dir) / "capture.json") << good.dump();
  EXPECT_TRUE(read_capture(dir).has_value());
}

TEST(Capture, NotAnExrAndBadJson) {
  const std::string dir = fresh_dir("garbage");
  ASSERT_TRUE(write_capture(dir, plane_capture()).ok());
  std::ofstream(fs::path(dir) / "view0.exr") << "not an image";
  EXPECT_NE(read_error(dir).find("not a readable OpenEXR"), std::string::npos);
  std::ofstream(fs::path(dir) / "capture.json") << "{ broken";
  EXPECT_NE(read_error(dir).find("malformed JSON"), std::string::npos);
}

// A depth file whose data window is far larger than any image is refused before it is allocated (a 30000 x 30000
// window on a 240 x 180 display window asked for 3.6 GB); here 20000 x 1, written for real.
TEST(Capture, AHugeDataWindowIsRefusedNotAllocated) {
  const std::string dir = fresh_dir("data_window");
  ASSERT_TRUE(write_capture(dir, plane_capture()).ok());
  const std::string path = (fs::path(dir) / "view0.exr").string();
  {
    Imf::Header header(Imath::Box2i({0, 0}, {239, 179}), Imath::Box2i({-10000, 0}, {9999, 0}));
    header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    std::vector<float> row(20000, 0.6f);
    Imf::FrameBuffer fb;
    fb.insert("Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(row.data() + 10000), sizeof(float), 0));
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(1);
  }
  const std::string error = read_error(dir);
  EXPECT_NE(error.find("view 0: " + path + ": bad data window (20000 x 1 pixels)"), std::string::npos) << error;
}

TEST(Capture, NoSkirtIsAClearError) {
  // A capture whose every return lies above the platform top (a plane far above the tester): no drape to diagnose.
  Capture c = plane_capture();
  for (auto& view : c.views) {
    const Eigen::Isometry3d to_specimen = view.camera.world_to_camera.inverse();
    for (int y = 0; y < view.depth.height; ++y) {
      for (int x = 0; x < view.depth.width; ++x) {
        if (view.depth.at(x, y) <= 0.0f) continue;
        const Eigen::Vector3d p = to_specimen * (static_cast<double>(view.depth.at(x, y)) * view.camera.ray(x, y));
        if (p.z() < 0.0) view.depth.at(x, y) = 0.0f;  // keep only what lies above the top
      }
    }
  }
  auto model = ForwardModel::create(c, FitSettings{});
  ASSERT_FALSE(model);
  EXPECT_NE(model.error().message.find("no skirt"), std::string::npos) << model.error().message;
}
