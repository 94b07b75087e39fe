#include "drapegen/diagnosis/capture.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <initializer_list>
#include <numbers>
#include <string_view>
#include <nlohmann/json.hpp>
#include <vector>

#include "drapegen/diagnosis/bending_json.hpp"
#include "drapegen/diagnosis/depth_exr.hpp"
#include "drapegen/sim/platform.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/json_text.hpp"

namespace drapegen::diagnosis {
namespace fs = std::filesystem;
namespace {

constexpr const char* kFormat = "drapegen-capture";

nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

/// A file the capture lists: a relative path inside its directory (no "..", not absolute), so that a capture is
/// one directory that can be moved or copied whole.
sim::Status check_listed_file(const nlohmann::json& name, const std::string& what) {
  if (!name.is_string() || name.get<std::string>().empty()) return sim::Error{what + " must be a file name"};
  const fs::path p = name.get<std::string>();
  if (p.is_absolute() || std::any_of(p.begin(), p.end(), [](const fs::path& part) { return part == ".."; })) {
    return sim::Error{fmt::format("{} {} must be a path inside the capture directory", what, p.string())};
  }
  return {};
}

/// `object[key]`, a number (`what` names the field in the error).
sim::Expected<double> number_at(const nlohmann::json& object, const char* key, const std::string& what) {
  if (!object.contains(key)) return sim::Error{fmt::format("{}: missing \"{}\"", what, key)};
  if (!object[key].is_number()) return sim::Error{fmt::format("{}.{} must be a number", what, key)};
  return object[key].get<double>();
}

sim::Expected<Eigen::MatrixXd> matrix_from(const nlohmann::json& j, int rows, int cols, const std::string& what) {
  if (!j.is_array() || static_cast<int>(j.size()) != rows) {
    return sim::Error{fmt::format("{} must be a {}x{} array of rows", what, rows, cols)};
  }
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i) {
    if (!j[i].is_array() || static_cast<int>(j[i].size()) != cols) {
      return sim::Error{fmt::format("{} must be a {}x{} array of rows", what, rows, cols)};
    }
    for (int k = 0; k < cols; ++k) {
      if (!j[i][k].is_number()) return sim::Error{fmt::format("{} has a non-number", what)};
      m(i, k) = j[i][k].get<double>();
      if (!std::isfinite(m(i, k))) return sim::Error{fmt::format("{} has a non-finite entry", what)};
    }
  }
  return m;
}

/// A key of `object` this format does not define (a misspelt optional field would otherwise be dropped unseen):
/// an error naming it and what `where` takes.
sim::Status known_keys_only(const nlohmann::json& object, std::initializer_list<std::string_view> known,
                            const std::string& where) {
  for (const auto& [key, value] : object.items()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string names;
    for (const auto name : known) names += fmt::format("{}\"{}\"", names.empty() ? "" : ", ", name);
    return sim::Error{fmt::format("{}: unknown field \"{}\" (it takes {})", where, key, names)};
  }
  return {};
}

sim::Expected<MeasuredBending> measured_bending_from(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) return sim::Error{where + " must be an object"};
  if (sim::Status st = known_keys_only(j, {"alpha", "beta", "within_factor", "method"}, where); !st) return st.error();
  if (!j.contains("alpha") || !j.contains("beta") || !j.contains("within_factor")) {
    return sim::Error{where + " needs \"alpha\", \"beta\" and \"within_factor\""};
  }
  MeasuredBending m;
  auto bending = bending_from_json(j, where);
  if (!bending) return bending.error();
  m.bending = *bending;
  const auto& factor = j["within_factor"];
  if (!factor.is_number() || !(factor.get<double>() > 1.0 && factor.get<double>() <= 100.0)) {
    return sim::Error{where + ".within_factor must be a number in (1, 100]"};
  }
  m.within_factor = factor.get<double>();
  if (j.contains("method")) {
    if (!j["method"].is_string()) return sim::Error{where + ".method must be a string"};
    m.method = j["method"].get<std::string>();
  }
  return m;
}

/// A view's depth file name in the capture directory: its own file's name, or view<v>.exr.
std::string view_file_name(const CaptureView& view, std::size_t v) {
  return view.file.empty() ? fmt::format("view{}.exr", v) : fs::path(view.file).filename().string();
}

}  // namespace

sim::Status check_view(const CaptureView& view) {
  const auto& d = view.depth;
  const auto& in = view.camera.intrinsics;
  if (d.width != in.width || d.height != in.height) {
    return sim::Error{fmt::format("{}: depth is {}x{} but the camera is {}x{}", view.file, d.width, d.height,
                                  in.width, in.height)};
  }
  int returns = 0;
  for (std::size_t i = 0; i < d.depth.size(); ++i) {
    const float z = d.depth[i];
    if (!std::isfinite(z)) {
      return sim::Error{fmt::format("{}: non-finite depth (NaN or inf) at pixel ({}, {}); use 0 for no return",
                                    view.file, i % d.width, i / d.width)};
    }
    if (z < 0.0f) {
      return sim::Error{fmt::format("{}: negative depth {} at pixel ({}, {})", view.file, z, i % d.width, i / d.width)};
    }
    if (z > kFarthestDepth) {
      return sim::Error{fmt::format("{}: depth {} m at pixel ({}, {}) is beyond {} m; use 0 for no return", view.file,
                                    z, i % d.width, i / d.width, kFarthestDepth)};
    }
    returns += z > 0.0f;
  }
  if (returns == 0) return sim::Error{fmt::format("{}: all-zero depth (no return in the whole view)", view.file)};
  if (returns < 100) return sim::Error{fmt::format("{}: only {} pixels return; not a drape view", view.file, returns)};
  return {};
}

sim::Expected<Capture> read_capture(const std::string& directory) {
  const fs::path dir(directory);
  const fs::path json_path = dir / "capture.json";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return sim::Error{fmt::format("{}: not a directory", directory)};
  if (!fs::is_regular_file(json_path, ec)) {
    return sim::Error{fmt::format("{}: {}", json_path.string(),
                                  fs::exists(json_path, ec) ? "not a regular file" : "no such file")};
  }
  nlohmann::json j;
  std::ifstream in(json_path);
  if (!in) return sim::Error{fmt::format("{}: cannot read: {}", json_path.string(), std::strerror(errno))};
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    return sim::Error{fmt::format("{}: malformed JSON: {}", json_path.string(), e.what())};
  }
  const std::string where = json_path.string();
  try {
    if (!j.is_object() || !j.contains("format") || j["format"] != kFormat) {
      return sim::Error{fmt::format("{}: not a capture (\"format\" must be \"{}\")", where, kFormat)};
    }
    // Integers as integers: 1.5 would pass as 1 (get<int> truncates).
    if (!j.contains("version") || !j["version"].is_number_integer() || j["version"].get<std::int64_t>() != 1) {
      return sim::Error{fmt::format("{}: unsupported version {} (this build reads the integer 1)", where,
                                    j.contains("version") ? j["version"].dump() : std::string("(none)"))};
    }
    // "notes": the tester's own metadata, any JSON, not read.
    if (sim::Status st = known_keys_only(
            j, {"format", "version", "source", "face", "specimen", "views", "scan", "notes"}, where);
        !st) {
      return st.error();
    }
    Capture c;
    c.directory = directory;
    if (j.contains("source") && !j["source"].is_null()) {
      if (!j["source"].is_string()) return sim::Error{fmt::format("{}: source must be a string", where)};
      c.source = j["source"].get<std::string>();
    }
    if (j.contains("face")) {
      if (!j["face"].is_string() || (j["face"] != "up" && j["face"] != "down")) {
        return sim::Error{fmt::format("{}: face must be \"up\" or \"down\" (the specimen turned over), not {}", where,
                                      j["face"].dump())};
      }
      c.face_down = j["face"] == "down";
    }
    if (!j.contains("specimen") || !j["specimen"].is_object()) {
      return sim::Error{fmt::format("{}: missing \"specimen\"", where)};
    }
    const auto& s = j["specimen"];
    if (sim::Status st = known_keys_only(
            s, {"size_mm", "density_g_per_m2", "cylinder_diameter_mm", "measured_bending"}, where + ": specimen");
        !st) {
      return st.error();
    }
    if (!s.contains("size_mm") || !s["size_mm"].is_array() || s["size_mm"].size() != 2 ||
        !s["size_mm"][0].is_number() || !s["size_mm"][1].is_number()) {
      return sim::Error{fmt::format("{}: specimen.size_mm must be [X, Y] numbers", where)};
    }
    c.specimen.size_x = s["size_mm"][0].get<double>() * 1e-3;
    c.specimen.size_y = s["size_mm"][1].get<double>() * 1e-3;
    auto density = number_at(s, "density_g_per_m2", where + ": specimen");
    if (!density) return density.error();
    c.specimen.density = *density;
    auto diameter = number_at(s, "cylinder_diameter_mm", where + ": specimen");
    if (!diameter) return diameter.error();
    c.specimen.cylinder_diameter = *diameter * 1e-3;
    if (!(c.specimen.size_x >= 0.05 && c.specimen.size_x <= 2.0 && c.specimen.size_y >= 0.05 &&
          c.specimen.size_y <= 2.0)) {
      return sim::Error{fmt::format("{}: specimen size must be 50 .. 2000 mm", where)};
    }
    if (!(c.specimen.density >= 1.0 && c.specimen.density <= 1e5)) {
      return sim::Error{fmt::format("{}: density must be 1 .. 100000 g/m^2", where)};
    }
    if (!(c.specimen.cylinder_diameter >= 0.01 &&
          c.specimen.cylinder_diameter < std::min(c.specimen.size_x, c.specimen.size_y))) {
      return sim::Error{fmt::format(
          "{}: cylinder diameter must be at least 10 mm and less than the specimen size (the specimen overhangs it)",
          where)};
    }
    if (s.contains("measured_bending") && !s["measured_bending"].is_null()) {
      auto measured = measured_bending_from(s["measured_bending"], where + ": specimen.measured_bending");
      if (!measured) return measured.error();
      c.specimen.measured_bending = std::move(*measured);
    }
    if (!j.contains("views")) return sim::Error{fmt::format("{}: missing \"views\"", where)};
    if (!j["views"].is_array()) {
      return sim::Error{fmt::format("{}: \"views\" must be an array of {} views", where, kCaptureViews)};
    }
    const auto& views = j["views"];
    if (static_cast<int>(views.size()) != kCaptureViews) {
      return sim::Error{fmt::format("{}: {} views listed, the tester takes {}", where, views.size(), kCaptureViews)};
    }
    for (std::size_t v = 0; v < views.size(); ++v) {
      const auto& jv = views[v];
      const std::string what = fmt::format("{}: views[{}]", where, v);
      if (!jv.is_object()) return sim::Error{what + ": not an object"};
      if (sim::Status st = known_keys_only(jv, {"depth", "width", "height", "K", "world_to_camera"}, what); !st) {
        return st.error();
      }
      for (const char* key : {"depth", "width", "height", "K", "world_to_camera"}) {
        if (!jv.contains(key)) return sim::Error{fmt::format("{}: missing \"{}\"", what, key)};
      }
      if (!jv["width"].is_number_integer() || !jv["height"].is_number_integer()) {
        return sim::Error{what + ": width and height must be integers"};
      }
      if (sim::Status st = check_listed_file(jv["depth"], what + ": depth"); !st) return st.error();
      CaptureView view;
      view.file = jv.at("depth").get<std::string>();
      for (std::size_t u = 0; u < v; ++u) {  // one file under two poses would be a view missing, unnoticed
        if (fs::equivalent(dir / view.file, dir / views[u].at("depth").get<std::string>(), ec)) {
          return sim::Error{fmt::format("{}: depth {} is views[{}]'s file too; each view needs its own", what,
                                        view.file, u)};
        }
      }
      // Compared as 64-bit integers: get<int> would wrap 2^32 + 240 to 240.
      const std::int64_t width = jv.at("width").get<std::int64_t>(), height = jv.at("height").get<std::int64_t>();
      if (width < 8 || height < 8 || width > 8192 || height > 8192) {
        return sim::Error{what + ": width and height must be 8 .. 8192"};
      }
      view.camera.intrinsics.width = static_cast<int>(width);
      view.camera.intrinsics.height = static_cast<int>(height);
      auto K = matrix_from(jv.at("K"), 3, 3, what + ".K");
      if (!K) return K.error();
      if ((*K)(2, 0) != 0.0 || (*K)(2, 1) != 0.0 || (*K)(2, 2) != 1.0)
        return sim::Error{what + ".K: last row must be 0 0 1"};
      if (!((*K)(0, 0) > 0.0 && (*K)(1, 1) > 0.0)) {
        return sim::Error{what + ".K: the focal lengths K[0][0] and K[1][1] must be positive"};
      }
      // With the last row 0 0 1, K is invertible where its upper left 2x2 is (a mistyped skew can make it singular).
      if (std::abs(K->topLeftCorner(2, 2).determinant()) < 1e-9 * (*K)(0, 0) * (*K)(1, 1)) {
        return sim::Error{what +
                          ".K: singular (its upper left 2x2 has no inverse: check the skew K[0][1] and K[1][0])"};
      }
      // K in pixels of this image: the principal point on it, and each axis's field of view 5 .. 170 degrees (a K
      // normalised by the image size or in metres saw nothing of the model, scored 0 mm and read "within the floors";
      // a huge one overflowed the renderer's single precision).
      const double cx = (*K)(0, 2), cy = (*K)(1, 2);
      if (!(cx >= 0.0 && cx <= static_cast<double>(width) && cy >= 0.0 && cy <= static_cast<double>(height))) {
        return sim::Error{fmt::format("{}.K: the principal point ({:g}, {:g}) is off the {}x{} image (K is in pixels)",
                                      what, cx, cy, width, height)};
      }
      constexpr double kDegree = std::numbers::pi / 180.0;
      const auto field_of_view = [](double pixels, double focal) { return 2.0 * std::atan(0.5 * pixels / focal); };
      const double fov_x = field_of_view(static_cast<double>(width), (*K)(0, 0));
      const double fov_y = field_of_view(static_cast<double>(height), (*K)(1, 1));
      if (!(fov_x >= 5.0 * kDegree && fov_x <= 170.0 * kDegree && fov_y >= 5.0 * kDegree &&
            fov_y <= 170.0 * kDegree)) {
        return sim::Error{fmt::format("{}.K: fields of view {:.3g} x {:.3g} degrees; a depth camera's are 5 .. 170 "
                                      "(K is in pixels)",
                                      what, fov_x / kDegree, fov_y / kDegree)};
      }
      view.camera.intrinsics.K = *K;
      auto T = matrix_from(jv.at("world_to_camera"), 4, 4, what + ".world_to_camera");
      if (!T) return T.error();
      const Eigen::Matrix3d R = T->topLeftCorner(3, 3);
      if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-4) {
        return sim::Error{what + ".world_to_camera: not a rigid transform (rotation part not orthonormal)"};
      }
      if (R.determinant() < 0.0) {
        return sim::Error{what + ".world_to_camera: not a rigid transform (a reflection: the rotation part's "
                                 "determinant is -1; a left-handed frame?)"};
      }
      if (T->row(3) != Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0)) {
        return sim::Error{what + ".world_to_camera: not a rigid transform (last row must be 0 0 0 1)"};
      }
      // The model must draw the whole scene: the farthest point of the specimen and the platform under it (half
      // the specimen's diagonal out, the platform's height down) lies within kFarthestDepth of the camera.
      const double reach =
          std::hypot(0.5 * std::hypot(c.specimen.size_x, c.specimen.size_y), sim::PlatformSpec{}.height);
      if (const double farthest = kFarthestDepth - reach; T->topRightCorner(3, 1).norm() > farthest) {
        return sim::Error{fmt::format("{}.world_to_camera: the camera is more than {:.2f} m from the specimen (the "
                                      "model renders to {} m)",
                                      what, farthest, kFarthestDepth)};
      }
      view.camera.world_to_camera.matrix() = *T;
      if (fs::exists(dir / view.file, ec) && !fs::is_regular_file(dir / view.file, ec)) {
        return sim::Error{fmt::format("view {}: {} is not a regular file", v, (dir / view.file).string())};
      }
      auto depth = read_depth_exr((dir / view.file).string());
      if (!depth) return sim::Error{fmt::format("view {}: {}", v, depth.error().message)};
      view.depth = std::move(*depth);
      view.file = (dir / view.file).string();
      if (sim::Status st = check_view(view); !st) return sim::Error{fmt::format("view {}: {}", v, st.error().message)};
      c.views.push_back(std::move(view));
    }
    if (j.contains("scan") && !j["scan"].is_null()) {
      if (sim::Status st = check_listed_file(j["scan"], where + ": scan"); !st) return st.error();
      const std::string scan = j["scan"].get<std::string>();
      if (!fs::is_regular_file(dir / scan, ec)) return sim::Error{fmt::format("{}: scan {} not found", where, scan)};
      c.scan_mesh = scan;
    }
    return c;
  } catch (const nlohmann::json::exception& e) {
    return sim::Error{fmt::format("{}: missing or malformed field: {}", where, e.what())};
  }
}

sim::Status write_capture(const std::string& directory, const Capture& capture) {
  const fs::path dir(directory);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return sim::Error{fmt::format("{}: cannot create directory: {}", directory, ec.message()), /*io=*/true};
  // Every view and capture.json together: a failed write leaves the directory's earlier capture whole.
  std::vector<std::string> bytes;
  std::vector<storage::FileBytes> files;
  for (std::size_t v = 0; v < capture.views.size(); ++v) {
    const std::string path = (dir / view_file_name(capture.views[v], v)).string();
    auto exr = encode_depth_exr(capture.views[v].depth);
    if (!exr) return sim::Error{fmt::format("{}: {}", path, exr.error().message)};
    bytes.push_back(std::move(*exr));
    files.push_back({path, {}});
  }
  bytes.push_back(capture_json_text(capture));
  files.push_back({(dir / "capture.json").string(), {}});
  for (std::size_t i = 0; i < files.size(); ++i) files[i].bytes = bytes[i];
  return storage::write_files_atomic(files);
}

std::string capture_json_text(const Capture& capture) {
  nlohmann::json views = nlohmann::json::array();
  for (std::size_t v = 0; v < capture.views.size(); ++v) {
    const auto& view = capture.views[v];
    views.push_back({{"depth", view_file_name(view, v)},
                     {"width", view.camera.intrinsics.width},
                     {"height", view.camera.intrinsics.height},
                     {"K", matrix_json(view.camera.intrinsics.K)},
                     {"world_to_camera", matrix_json(view.camera.world_to_camera.matrix())}});
  }
  nlohmann::json j = {{"format", kFormat},
                      {"version", 1},
                      {"source", capture.source},
                      {"specimen",
                       {{"size_mm", {capture.specimen.size_x * 1e3, capture.specimen.size_y * 1e3}},
                        {"density_g_per_m2", capture.specimen.density},
                        {"cylinder_diameter_mm", capture.specimen.cylinder_diameter * 1e3}}},
                      {"views", views}};
  if (const auto& m = capture.specimen.measured_bending) {
    nlohmann::json measured = bending_json(m->bending);
    measured["within_factor"] = m->within_factor;
    measured["method"] = m->method;
    j["specimen"]["measured_bending"] = measured;
  }
  if (capture.scan_mesh) j["scan"] = *capture.scan_mesh;
  if (capture.face_down) j["face"] = "down";
  return storage::json_text(j) + "\n";
}

sim::Status write_capture_json(const std::string& directory, const Capture& capture) {
  // Atomically: a reader (or a crash) never sees half a capture.json.
  return storage::write_file_atomic((fs::path(directory) / "capture.json").string(), capture_json_text(capture));
}

}  // namespace drapegen::diagnosis
