#pragma once
// One data point (the 4 views of one specimen orientation) as one OpenEXR file, the one OpenEXR's API writes. Layout
// (docs/RENDERER.md, "EXR layout"): a single scan-line part, one channel "viewN.Z" per view (camera-space z in
// metres, 0 = no return), and header attributes for everything a consumer needs.

#include <cstdint>
#include <string>
#include <vector>

#include "drapegen/renderer/camera.hpp"
#include "drapegen/renderer/depth_image.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::renderer {

struct ViewRecord {
  DepthImage depth;
  /// Intrinsics (pinhole with this view's affine image perturbation) and the pose of the camera relative to the
  /// drape's own frame (the PLY's coordinates: platform top in z = 0, axis along z).
  Camera camera;
  double table_angle = 0.0;       // radians: the specimen's turn about the axis for this view
  std::uint64_t noise_seed = 0;
};

struct DataPointRecord {
  int index = 0;                  // orientation index within the drape
  double orientation = 0.0;       // radians
  std::uint64_t seed = 0;         // the data point's seed
  std::string noise = "none";     // NoiseModel::describe()
  std::string source;             // e.g. the mesh file name (free text)
  std::vector<ViewRecord> views;
};

/// How depth is stored: pixel type, OpenEXR compression and an optional storage quantum (depth rounded to a
/// multiple of it before conversion). The default is the measured choice of docs/RENDERER.md.
struct ExrStorage {
  enum class Pixel { kHalf, kFloat };
  Pixel pixel = Pixel::kHalf;
  std::string compression = "zip";  // none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab
  double quantum = 0.0;             // m; 0: none
  int zip_level = 1;                // deflate level for zip/zips, 1..9 (libdeflate's in encode(), zlib's through
                                    // OpenEXR; docs/RENDERER.md, "Storage choice")

  /// Upper bound of the storage error (rounding to the quantum, then to half or float) for depths up to z_max, m.
  [[nodiscard]] double max_error(double z_max) const;
};

class ExrWriter {
 public:
  explicit ExrWriter(ExrStorage storage = {});
  /// Checks the storage settings (compression name, quantum, level).
  [[nodiscard]] sim::Status validate() const;
  /// Encodes to memory (what a worker sends over the network). Compressions none, zips and zip are written by the
  /// library itself (the same bytes as OpenEXR's writer, faster), the others through OpenEXR.
  [[nodiscard]] sim::Expected<std::vector<char>> encode(const DataPointRecord& point) const;
  /// The same file, always through OpenEXR's Imf::OutputFile (the reference for encode()).
  [[nodiscard]] sim::Expected<std::vector<char>> encode_with_openexr(const DataPointRecord& point) const;
  /// Encodes, then writes atomically (storage::write_file_atomic: a temporary of its own, fsync, rename).
  [[nodiscard]] sim::Status write_file(const std::string& path, const DataPointRecord& point) const;
  [[nodiscard]] const ExrStorage& storage() const { return storage_; }

 private:
  [[nodiscard]] sim::Expected<std::vector<char>> encode(const DataPointRecord& point, bool with_openexr) const;

  ExrStorage storage_;
};

/// Reads a file written by ExrWriter (depth, cameras, angles, seeds, noise description). Fails with a message on
/// anything else or a damaged file.
[[nodiscard]] sim::Expected<DataPointRecord> read_exr(const std::string& path);
[[nodiscard]] sim::Expected<DataPointRecord> read_exr(const std::vector<char>& bytes);

}  // namespace drapegen::renderer
