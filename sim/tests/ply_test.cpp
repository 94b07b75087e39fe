#include "drapegen/sim/ply.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "drapegen/sim/specimen.hpp"

namespace drapegen::sim {
namespace {

std::string temp_path(const std::string& name) { return ::testing::TempDir() + "drapegen_ply_" + name; }

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool file_exists(const std::string& path) { return std::ifstream(path).good(); }

/// A small irregular specimen whose positions differ from its rest coordinates.
ClothMesh sample_mesh() {
  ClothMesh mesh = make_specimen(SpecimenSpec{.size_x = 0.3, .size_y = 0.2, .vertices_x = 7, .vertices_y = 5,
                                              .jitter = 0.3, .triangulation = Triangulation::kRandom, .seed = 7,
                                              .material_angle = 0.1 + 1.0 / 3.0});
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    mesh.positions(2, i) = -0.05 * std::sin(17.0 * i) / 3.0;
    mesh.positions(0, i) *= 0.9 + 1e-3 * std::cos(5.0 * i);
  }
  return mesh;
}

template <class Matrix>
bool bit_equal(const Matrix& a, const Matrix& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(typename Matrix::Scalar) * a.size()) == 0;
}

/// Expects read_ply to fail on `text` with a message mentioning `fragment` and the path.
void expect_read_error(const std::string& name, const std::string& text, const std::string& fragment) {
  const std::string path = temp_path(name);
  write_text(path, text);
  const Expected<ClothMesh> mesh = read_ply(path);
  ASSERT_FALSE(mesh.has_value()) << name;
  EXPECT_NE(mesh.error().message.find(fragment), std::string::npos) << mesh.error().message;
  EXPECT_NE(mesh.error().message.find(path), std::string::npos) << mesh.error().message;
}

constexpr const char* kAsciiHeader =
    "ply\n"
    "format ascii 1.0\n"
    "element vertex 4\n"
    "property float x\nproperty float y\nproperty float z\n"
    "element face 2\n"
    "property list uchar int vertex_indices\n"
    "end_header\n";

TEST(Ply, BinaryRoundTripIsBitExact) {
  const ClothMesh mesh = sample_mesh();
  const std::string path = temp_path("round_trip.ply");
  ASSERT_TRUE(write_ply(path, mesh).ok());
  const std::string own_temporaries = path + ".tmp." + std::to_string(::getpid()) + ".";
  for (const auto& entry : std::filesystem::directory_iterator(::testing::TempDir())) {  // none of ours left
    EXPECT_NE(entry.path().string().rfind(own_temporaries, 0), 0u) << entry.path();
  }

  const Expected<ClothMesh> read = read_ply(path);
  ASSERT_TRUE(read.has_value()) << read.error().message;
  EXPECT_TRUE(bit_equal(read->positions, mesh.positions));
  EXPECT_TRUE(bit_equal(read->rest, mesh.rest));
  EXPECT_TRUE(bit_equal(read->triangles, mesh.triangles));
  EXPECT_EQ(std::memcmp(&read->material_angle, &mesh.material_angle, sizeof(double)), 0);

  // The header is the documented one.
  const std::string text = read_text(path);
  EXPECT_EQ(text.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(text.find("property list uchar int vertex_indices\n"), std::string::npos);
  EXPECT_NE(text.find("comment material_angle 0.43333333333333335\n"), std::string::npos);
}

TEST(Ply, WriteReplacesAnExistingFile) {
  const std::string path = temp_path("replace.ply");
  write_text(path, "old content");
  ClothMesh mesh = sample_mesh();
  mesh.material_angle = -0.0;
  ASSERT_TRUE(write_ply(path, mesh).ok());
  const Expected<ClothMesh> read = read_ply(path);
  ASSERT_TRUE(read.has_value()) << read.error().message;
  EXPECT_TRUE(std::signbit(read->material_angle));
  EXPECT_EQ(read->triangle_count(), mesh.triangle_count());
}

TEST(Ply, WritesAPipeInPlace) {
  // `simulate --out /dev/stdout` into a pipe: the PLY goes down the pipe, no file is renamed over it.
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const std::string pipe_path = "/proc/self/fd/" + std::to_string(fds[1]);
  const Status s = write_ply(pipe_path, sample_mesh());  // a few hundred bytes: within the pipe's buffer
  ASSERT_TRUE(s.ok()) << s.error().message;
  ::close(fds[1]);
  std::string got;
  char chunk[4096];
  for (ssize_t n; (n = ::read(fds[0], chunk, sizeof chunk)) > 0;) got.append(chunk, static_cast<std::size_t>(n));
  ::close(fds[0]);
  EXPECT_EQ(got.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
}

TEST(Ply, ReadsAsciiWithoutRestCoordinates) {
  const std::string path = temp_path("ascii.ply");
  write_text(path,
             "ply\r\n"
             "format ascii 1.0\r\n"
             "comment made by hand\r\n"
             "comment material_angle 0.5\r\n"
             "element vertex 4\r\n"
             "property float x\r\nproperty float y\r\nproperty float z\r\nproperty uchar red\r\n"
             "element face 2\r\n"
             "property list uchar int vertex_indices\r\nproperty int flags\r\n"
             "element edge 1\r\n"
             "property int vertex1\r\nproperty int vertex2\r\n"
             "end_header\r\n"
             "0 0 0 255\r\n1 0 0 0\r\n1 1 0.25 0\r\n0 1 -1.5e-1 7\r\n"
             "3 0 1 2 9\r\n3 0 2 3 9\r\n"
             "0 1\r\n");
  const Expected<ClothMesh> mesh = read_ply(path);
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
  ASSERT_EQ(mesh->vertex_count(), 4);
  ASSERT_EQ(mesh->triangle_count(), 2);
  EXPECT_EQ(mesh->positions.col(2), Eigen::Vector3d(1.0, 1.0, 0.25));
  EXPECT_EQ(mesh->positions(2, 3), static_cast<double>(-0.15f));  // float properties are rounded to float
  EXPECT_EQ(mesh->rest, mesh->positions.topRows<2>());              // no u v: rest = (x, y)
  EXPECT_EQ(mesh->triangles.col(1), Eigen::Vector3i(0, 2, 3));
  EXPECT_EQ(mesh->material_angle, 0.5);
}

TEST(Ply, ReadsAsciiWithRestCoordinates) {
  const std::string path = temp_path("ascii_uv.ply");
  write_text(path,
             "ply\nformat ascii 1.0\nelement vertex 3\n"
             "property double u\nproperty double x\nproperty double y\nproperty double z\nproperty double v\n"
             "element face 1\nproperty list int uint vertex_index\nend_header\n"
             "0.5 1 2 3 0.25\n1.5 4 5 6 0.75\n2.5 7 8 9 -0.5\n3 2 1 0\n");
  const Expected<ClothMesh> mesh = read_ply(path);
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
  EXPECT_EQ(mesh->rest.col(2), Eigen::Vector2d(2.5, -0.5));
  EXPECT_EQ(mesh->positions.col(1), Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(mesh->triangles.col(0), Eigen::Vector3i(2, 1, 0));
  EXPECT_EQ(mesh->material_angle, 0.0);
}

TEST(Ply, ReadsBinaryFloats) {
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const float coords[9] = {0.1f, 0.2f, 0.3f, 1.0f, 0.0f, -2.5f, 0.0f, 1.0f, 0.0f};
  for (const float c : coords) {
    std::uint32_t word = 0;
    std::memcpy(&word, &c, 4);
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<char>((word >> (8 * k)) & 0xff));
  }
  bytes.push_back(3);
  for (const std::uint32_t index : {0u, 1u, 2u}) {
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<char>((index >> (8 * k)) & 0xff));
  }
  const std::string path = temp_path("binary_float.ply");
  write_text(path, bytes);
  const Expected<ClothMesh> mesh = read_ply(path);
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
  EXPECT_EQ(mesh->positions(0, 0), static_cast<double>(0.1f));
  EXPECT_EQ(mesh->positions(2, 1), -2.5);
  EXPECT_EQ(mesh->rest.col(0), Eigen::Vector2d(static_cast<double>(0.1f), static_cast<double>(0.2f)));
  EXPECT_EQ(mesh->triangles.col(0), Eigen::Vector3i(0, 1, 2));
}

TEST(Ply, MissingFileIsAnError) {
  const std::string path = temp_path("does_not_exist.ply");
  std::remove(path.c_str());
  const Expected<ClothMesh> mesh = read_ply(path);
  ASSERT_FALSE(mesh.has_value());
  EXPECT_NE(mesh.error().message.find(path), std::string::npos);
  EXPECT_NE(mesh.error().message.find("No such file"), std::string::npos) << mesh.error().message;
}

TEST(Ply, DirectoryIsAnError) {
  const Expected<ClothMesh> mesh = read_ply(::testing::TempDir());
  ASSERT_FALSE(mesh.has_value());
}

TEST(Ply, TruncatedBinaryFileIsAnError) {
  const std::string path = temp_path("truncated_source.ply");
  ASSERT_TRUE(write_ply(path, sample_mesh()).ok());
  const std::string full = read_text(path);
  for (const std::size_t drop : {std::size_t{1}, std::size_t{13}, std::size_t{200}, full.size() / 2}) {
    expect_read_error("truncated.ply", full.substr(0, full.size() - drop), "truncated");
  }
  // Cut inside the header.
  expect_read_error("truncated_header.ply", full.substr(0, 40), "end_header");
}

TEST(Ply, TruncatedAsciiFileIsAnError) {
  expect_read_error("truncated_ascii.ply", std::string(kAsciiHeader) + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2",
                    "truncated");
}

TEST(Ply, DataBeyondTheDeclaredCountsIsAnError) {
  // A face count too small (a hand-edited file): the second face would be dropped unseen, a hole in the drape.
  std::string one_face = kAsciiHeader;
  one_face.replace(one_face.find("element face 2"), 14, "element face 1");
  expect_read_error("face_count_small.ply", one_face + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
                    "trailing data");
  // An element without properties whose count no loop should run through.
  std::string junk = kAsciiHeader;
  junk.replace(junk.find("end_header"), 10, "element junk 9223372036854775807\nend_header");
  expect_read_error("junk_count.ply", junk + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n", "bad header");
}

TEST(Ply, BinaryDataBeyondTheDeclaredCountsIsAnError) {
  const std::string path = temp_path("binary_trailing.ply");
  ASSERT_TRUE(write_ply(path, sample_mesh()).ok());
  std::ofstream(path, std::ios::app | std::ios::binary) << 'x';
  const Expected<ClothMesh> read = read_ply(path);
  ASSERT_FALSE(read.has_value());
  EXPECT_NE(read.error().message.find("trailing data: 1 bytes"), std::string::npos) << read.error().message;
}

TEST(Ply, IndexOutOfRangeIsAnError) {
  expect_read_error("bad_index.ply", std::string(kAsciiHeader) + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 4\n",
                    "out of range");
  expect_read_error("negative_index.ply",
                    std::string(kAsciiHeader) + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 -1 3\n", "out of range");
}

TEST(Ply, NonTriangleIsAnError) {
  expect_read_error("quad.ply", std::string(kAsciiHeader) + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 2 3\n",
                    "only triangles");
}

TEST(Ply, NonFiniteCoordinateIsAnError) {
  expect_read_error("nan.ply", std::string(kAsciiHeader) + "0 0 0\n1 nan 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
                    "non-finite");
  expect_read_error("inf.ply", std::string(kAsciiHeader) + "0 0 0\n1 0 0\n1 1 1e999\n0 1 0\n3 0 1 2\n3 0 2 3\n",
                    "malformed value");
}

TEST(Ply, MalformedValueIsAnError) {
  expect_read_error("word.ply", std::string(kAsciiHeader) + "0 0 0\n1 zero 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
                    "malformed value 'zero'");
}

TEST(Ply, NoFacesIsAnError) {
  expect_read_error("no_faces.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n",
                    "no faces");
  expect_read_error("no_face_element.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                    "end_header\n0 0 0\n",
                    "no faces");
}

TEST(Ply, BadHeadersAreErrors) {
  expect_read_error("not_ply.ply", "solid cube\nfacet normal 0 0 1\n", "not a PLY file");
  expect_read_error("empty.ply", "", "not a PLY file");
  expect_read_error("big_endian.ply", "ply\nformat binary_big_endian 1.0\nend_header\n", "binary_big_endian");
  expect_read_error("no_format.ply", "ply\nelement vertex 0\nend_header\n", "format");
  expect_read_error("bad_keyword.ply", "ply\nformat ascii 1.0\nelemnt vertex 3\nend_header\n", "line 3");
  expect_read_error("bad_type.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty real x\nend_header\n",
                    "unknown property type 'real'");
  expect_read_error("no_z.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0\n3 0 0 0\n",
                    "x, y and z");
  expect_read_error("bad_angle.ply",
                    "ply\nformat ascii 1.0\ncomment material_angle north\nelement vertex 1\nend_header\n",
                    "material_angle");
  expect_read_error("huge_count.ply",
                    "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n",
                    "too many");
  expect_read_error("count_beyond_data.ply",
                    "ply\nformat binary_little_endian 1.0\nelement vertex 1000000\nproperty double x\n"
                    "property double y\nproperty double z\nelement face 1\n"
                    "property list uchar int vertex_indices\nend_header\nxyz",
                    "truncated");
}

TEST(Ply, UnwritablePathIsAnError) {
  const ClothMesh mesh = sample_mesh();
  const std::string in_missing_directory = temp_path("no_such_directory/mesh.ply");
  const Status missing = write_ply(in_missing_directory, mesh);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find(in_missing_directory), std::string::npos);
  EXPECT_NE(missing.error().message.find("No such file or directory"), std::string::npos) << missing.error().message;

  // A regular file where a directory should be (fails even for root, unlike permission bits).
  const std::string blocker = temp_path("blocker");
  write_text(blocker, "x");
  const Status not_directory = write_ply(blocker + "/mesh.ply", mesh);
  ASSERT_FALSE(not_directory.ok());
  EXPECT_NE(not_directory.error().message.find("Not a directory"), std::string::npos) << not_directory.error().message;
}

TEST(Ply, InvalidMeshIsNotWritten) {
  const std::string path = temp_path("invalid.ply");
  std::remove(path.c_str());
  ClothMesh mesh = sample_mesh();
  mesh.triangles(1, 3) = mesh.vertex_count();
  EXPECT_FALSE(write_ply(path, mesh).ok());
  mesh = sample_mesh();
  mesh.positions(0, 2) = NAN;
  EXPECT_FALSE(write_ply(path, mesh).ok());
  mesh = sample_mesh();
  mesh.rest.conservativeResize(2, mesh.vertex_count() - 1);
  EXPECT_FALSE(write_ply(path, mesh).ok());
  EXPECT_FALSE(file_exists(path));
}

}  // namespace
}  // namespace drapegen::sim
