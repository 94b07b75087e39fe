#include "drapegen/sim/ply.hpp"

#include <sys/stat.h>  // stat: a device or pipe is written in place
#include <unistd.h>    // fsync, getpid

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace drapegen::sim {
namespace {

// ---------------------------------------------------------------------------------------------------------------------
// Scalar types and little-endian encoding.

enum class Scalar { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

/// The scalar type called `name` (classic or sized spelling), or nullopt.
std::optional<Scalar> parse_scalar(std::string_view name) {
  static constexpr std::array<std::pair<std::string_view, Scalar>, 16> kNames = {{
      {"char", Scalar::kInt8},     {"int8", Scalar::kInt8},     {"uchar", Scalar::kUint8},
      {"uint8", Scalar::kUint8},   {"short", Scalar::kInt16},   {"int16", Scalar::kInt16},
      {"ushort", Scalar::kUint16}, {"uint16", Scalar::kUint16}, {"int", Scalar::kInt32},
      {"int32", Scalar::kInt32},   {"uint", Scalar::kUint32},   {"uint32", Scalar::kUint32},
      {"float", Scalar::kFloat32}, {"float32", Scalar::kFloat32}, {"double", Scalar::kFloat64},
      {"float64", Scalar::kFloat64},
  }};
  for (const auto& [spelling, scalar] : kNames) {
    if (spelling == name) return scalar;
  }
  return std::nullopt;
}

std::size_t scalar_bytes(Scalar s) {
  switch (s) {
    case Scalar::kInt8:
    case Scalar::kUint8: return 1;
    case Scalar::kInt16:
    case Scalar::kUint16: return 2;
    case Scalar::kInt32:
    case Scalar::kUint32:
    case Scalar::kFloat32: return 4;
    case Scalar::kFloat64: return 8;
  }
  return 8;
}

bool is_integer(Scalar s) { return s != Scalar::kFloat32 && s != Scalar::kFloat64; }

/// The closed range of an integer type.
std::pair<std::int64_t, std::int64_t> integer_range(Scalar s) {
  switch (s) {
    case Scalar::kInt8: return {INT8_MIN, INT8_MAX};
    case Scalar::kUint8: return {0, UINT8_MAX};
    case Scalar::kInt16: return {INT16_MIN, INT16_MAX};
    case Scalar::kUint16: return {0, UINT16_MAX};
    case Scalar::kInt32: return {INT32_MIN, INT32_MAX};
    case Scalar::kUint32: return {0, UINT32_MAX};
    default: return {0, 0};
  }
}

/// Reinterprets little-endian bytes as a T.
template <class T>
T load_le(const char* bytes) {
  std::array<char, sizeof(T)> raw;
  std::copy_n(bytes, sizeof(T), raw.begin());
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw.begin(), raw.end());
  return std::bit_cast<T>(raw);
}

/// Appends the little-endian bytes of `value`.
template <class T>
void append_le(std::string& out, T value) {
  auto raw = std::bit_cast<std::array<char, sizeof(T)>>(value);
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw.begin(), raw.end());
  out.append(raw.data(), raw.size());
}

/// Parses all of `text` as a double (a leading '+' is allowed); nullopt if anything is left over or out of range.
std::optional<double> parse_double(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

/// Parses all of `text` as a decimal integer (a leading '+' is allowed).
std::optional<std::int64_t> parse_integer(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// ---------------------------------------------------------------------------------------------------------------------
// Header.

struct Property {
  std::string name;
  Scalar type = Scalar::kFloat64;  // the item type for lists
  bool is_list = false;
  Scalar count_type = Scalar::kUint8;  // lists only
};

struct Element {
  std::string name;
  std::int64_t count = 0;
  std::vector<Property> properties;
};

enum class Format { kAscii, kBinaryLittleEndian };

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  double material_angle = 0.0;
  std::size_t data_offset = 0;  // first byte after the end_header line
};

Error header_error(int line_number, const std::string& what) {
  return Error{"bad header: line " + std::to_string(line_number) + ": " + what};
}

/// Parses one `property` line into the last element.
std::optional<Error> parse_property(const std::vector<std::string_view>& words, int line_number, Element& element) {
  Property property;
  if (words.size() == 5 && words[1] == "list") {
    const auto count_type = parse_scalar(words[2]);
    const auto item_type = parse_scalar(words[3]);
    if (!count_type || !item_type) return header_error(line_number, "unknown type in list property");
    if (!is_integer(*count_type)) return header_error(line_number, "a list's length type must be an integer type");
    property = Property{std::string(words[4]), *item_type, true, *count_type};
  } else if (words.size() == 3 && words[1] != "list") {
    const auto type = parse_scalar(words[1]);
    if (!type) return header_error(line_number, "unknown property type '" + std::string(words[1]) + "'");
    property = Property{std::string(words[2]), *type, false, Scalar::kUint8};
  } else {
    return header_error(line_number, "expected 'property <type> <name>' or 'property list <type> <type> <name>'");
  }
  for (const Property& existing : element.properties) {
    if (existing.name == property.name) return header_error(line_number, "duplicate property '" + property.name + "'");
  }
  element.properties.push_back(std::move(property));
  return std::nullopt;
}

/// Parses the header at the start of `file`.
Expected<Header> parse_header(std::string_view file) {
  Header header;
  bool have_format = false;
  std::size_t pos = 0;
  int line_number = 0;
  auto next_line = [&]() -> std::optional<std::string_view> {
    if (pos >= file.size()) return std::nullopt;
    const std::size_t end = file.find('\n', pos);
    std::string_view line = file.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos);
    pos = end == std::string_view::npos ? file.size() : end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return line;
  };

  const auto magic = next_line();
  if (!magic || *magic != "ply") return Error{"bad header: not a PLY file (the first line is not 'ply')"};
  while (true) {
    const auto line = next_line();
    // The last line of a header cut short has no line break.
    if (!line || (pos == file.size() && file.back() != '\n' && *line != "end_header")) {
      return Error{"bad header: the file ends before 'end_header' (truncated?)"};
    }
    const std::vector<std::string_view> words = split_words(*line);
    if (words.empty()) continue;
    const std::string_view keyword = words[0];
    if (keyword == "end_header") {
      header.data_offset = pos;
      break;
    }
    if (keyword == "comment") {
      if (words.size() >= 2 && words[1] == "material_angle") {
        const auto angle = words.size() == 3 ? parse_double(words[2]) : std::nullopt;
        if (!angle || !std::isfinite(*angle)) {
          return header_error(line_number, "material_angle comment must hold one finite number (radians)");
        }
        header.material_angle = *angle;
      }
    } else if (keyword == "obj_info") {
      // Free text; ignored.
    } else if (keyword == "format") {
      if (words.size() != 3) return header_error(line_number, "expected 'format <type> 1.0'");
      if (words[1] == "ascii") {
        header.format = Format::kAscii;
      } else if (words[1] == "binary_little_endian") {
        header.format = Format::kBinaryLittleEndian;
      } else if (words[1] == "binary_big_endian") {
        return Error{"unsupported format binary_big_endian; convert the file to binary_little_endian or ascii"};
      } else {
        return header_error(line_number, "unknown format '" + std::string(words[1]) + "'");
      }
      have_format = true;
    } else if (keyword == "element") {
      const auto count = words.size() == 3 ? parse_integer(words[2]) : std::nullopt;
      if (!count || *count < 0) return header_error(line_number, "expected 'element <name> <count>' with count >= 0");
      header.elements.push_back(Element{std::string(words[1]), *count, {}});
    } else if (keyword == "property") {
      if (header.elements.empty()) return header_error(line_number, "property before any element");
      if (auto error = parse_property(words, line_number, header.elements.back())) return *error;
    } else {
      return header_error(line_number, "unknown keyword '" + std::string(keyword) + "'");
    }
  }
  if (!have_format) return Error{"bad header: no 'format' line"};
  return header;
}

// ---------------------------------------------------------------------------------------------------------------------
// Where the mesh lives in the file.

/// What a vertex property is used for.
enum class Slot { kNone, kX, kY, kZ, kU, kV };

struct Layout {
  int vertex_element = -1;
  int face_element = -1;
  int face_indices = -1;         // property index of the face list
  std::vector<Slot> vertex_slots;  // per vertex property
  bool has_uv = false;
};

int find_element(const Header& header, std::string_view name, int& duplicates) {
  int found = -1;
  duplicates = 0;
  for (int e = 0; e < static_cast<int>(header.elements.size()); ++e) {
    if (header.elements[e].name != name) continue;
    if (found >= 0) ++duplicates;
    found = e;
  }
  return found;
}

/// Locates the vertex coordinates and face indices, and checks the element counts against the data size.
Expected<Layout> find_layout(const Header& header, std::size_t data_bytes) {
  Layout layout;
  int duplicates = 0;
  layout.vertex_element = find_element(header, "vertex", duplicates);
  if (layout.vertex_element < 0) return Error{"bad header: no 'vertex' element"};
  if (duplicates > 0) return Error{"bad header: more than one 'vertex' element"};
  layout.face_element = find_element(header, "face", duplicates);
  if (layout.face_element < 0) return Error{"bad header: no 'face' element (the file has no faces)"};
  if (duplicates > 0) return Error{"bad header: more than one 'face' element"};

  const Element& vertex = header.elements[layout.vertex_element];
  bool seen[5] = {false, false, false, false, false};
  for (const Property& p : vertex.properties) {
    static constexpr std::array<std::pair<std::string_view, Slot>, 5> kSlots = {
        {{"x", Slot::kX}, {"y", Slot::kY}, {"z", Slot::kZ}, {"u", Slot::kU}, {"v", Slot::kV}}};
    Slot slot = Slot::kNone;
    for (const auto& [name, s] : kSlots) {
      if (p.name == name) slot = s;
    }
    if (slot != Slot::kNone) {
      if (p.is_list) return Error{"bad header: vertex property '" + p.name + "' must be a scalar, not a list"};
      seen[static_cast<int>(slot) - 1] = true;
    }
    layout.vertex_slots.push_back(slot);
  }
  if (!seen[0] || !seen[1] || !seen[2]) return Error{"bad header: the vertex element needs properties x, y and z"};
  if (seen[3] != seen[4]) return Error{"bad header: the vertex element has only one of the properties u and v"};
  layout.has_uv = seen[3];

  const Element& face = header.elements[layout.face_element];
  for (int p = 0; p < static_cast<int>(face.properties.size()); ++p) {
    const Property& property = face.properties[p];
    if (property.name == "vertex_indices" || property.name == "vertex_index") layout.face_indices = p;
  }
  if (layout.face_indices < 0) return Error{"bad header: the face element has no 'vertex_indices' list"};
  const Property& indices = face.properties[layout.face_indices];
  if (!indices.is_list || !is_integer(indices.type)) {
    return Error{"bad header: 'vertex_indices' must be a list of an integer type"};
  }

  constexpr std::int64_t kMaxCount = std::numeric_limits<int>::max();
  if (vertex.count == 0) return Error{"the file has no vertices"};
  if (face.count == 0) return Error{"the file has no faces"};
  if (vertex.count > kMaxCount || face.count > kMaxCount) return Error{"bad header: too many vertices or faces"};
  // Every item of an element with properties takes at least one byte; this bounds the allocations below.
  for (const Element& element : header.elements) {
    if (element.properties.empty() && element.count > kMaxCount) {  // nothing to read, but one loop turn each
      return Error{"bad header: the '" + element.name + "' element declares " + std::to_string(element.count) +
                   " items"};
    }
    if (!element.properties.empty() && static_cast<std::uint64_t>(element.count) > data_bytes) {
      return Error{"truncated data: the header declares " + std::to_string(element.count) + " '" + element.name +
                   "' items but only " + std::to_string(data_bytes) + " bytes of data follow"};
    }
  }
  return layout;
}

// ---------------------------------------------------------------------------------------------------------------------
// Data.

/// Reads binary_little_endian values in sequence.
class BinaryReader {
 public:
  explicit BinaryReader(std::string_view data) : data_(data) {}

  /// The next value, or nullopt (see problem()) when the data end first.
  std::optional<double> next(Scalar type) {
    const std::size_t n = scalar_bytes(type);
    if (data_.size() - pos_ < n) {
      problem_ = "truncated data: the file ends early";
      return std::nullopt;
    }
    const char* p = data_.data() + pos_;
    pos_ += n;
    switch (type) {
      case Scalar::kInt8: return load_le<std::int8_t>(p);
      case Scalar::kUint8: return load_le<std::uint8_t>(p);
      case Scalar::kInt16: return load_le<std::int16_t>(p);
      case Scalar::kUint16: return load_le<std::uint16_t>(p);
      case Scalar::kInt32: return load_le<std::int32_t>(p);
      case Scalar::kUint32: return load_le<std::uint32_t>(p);
      case Scalar::kFloat32: return load_le<float>(p);
      case Scalar::kFloat64: return load_le<double>(p);
    }
    return std::nullopt;
  }

  [[nodiscard]] const std::string& problem() const { return problem_; }
  /// Bytes after the last value read.
  [[nodiscard]] std::size_t unread() const { return data_.size() - pos_; }

 private:
  std::string_view data_;
  std::size_t pos_ = 0;
  std::string problem_;
};

/// Reads whitespace-separated ascii values in sequence.
class AsciiReader {
 public:
  explicit AsciiReader(std::string_view data) : data_(data) {}

  /// The next value, or nullopt (see problem()) at the end of the data or on a malformed number.
  std::optional<double> next(Scalar type) {
    auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    while (pos_ < data_.size() && is_space(data_[pos_])) ++pos_;
    if (pos_ == data_.size()) {
      problem_ = "truncated data: the file ends early";
      return std::nullopt;
    }
    const std::size_t start = pos_;
    while (pos_ < data_.size() && !is_space(data_[pos_])) ++pos_;
    const std::string_view token = data_.substr(start, pos_ - start);
    if (is_integer(type)) {
      const auto value = parse_integer(token);
      const auto [lo, hi] = integer_range(type);
      if (value && *value >= lo && *value <= hi) return static_cast<double>(*value);
    } else if (const auto value = parse_double(token)) {
      return type == Scalar::kFloat32 ? static_cast<double>(static_cast<float>(*value)) : *value;
    }
    problem_ = "malformed value '" + std::string(token.substr(0, 32)) + "'";
    return std::nullopt;
  }

  [[nodiscard]] const std::string& problem() const { return problem_; }
  /// Bytes after the last value read other than whitespace.
  [[nodiscard]] std::size_t unread() const {
    std::size_t n = 0;
    for (std::size_t i = pos_; i < data_.size(); ++i) {
      const char c = data_[i];
      n += !(c == ' ' || c == '\t' || c == '\n' || c == '\r');
    }
    return n;
  }

 private:
  std::string_view data_;
  std::size_t pos_ = 0;
  std::string problem_;
};

Error data_error(const Element& element, std::int64_t item, const std::string& what) {
  return Error{what + " (in '" + element.name + "' item " + std::to_string(item) + " of " +
               std::to_string(element.count) + ")"};
}

/// Reads every element in file order, keeping the vertex coordinates and the triangles.
template <class Reader>
Expected<ClothMesh> read_body(const Header& header, const Layout& layout, Reader& reader) {
  const auto nv = static_cast<int>(header.elements[layout.vertex_element].count);
  const auto nf = static_cast<int>(header.elements[layout.face_element].count);
  ClothMesh mesh;
  mesh.material_angle = header.material_angle;
  mesh.positions.resize(3, nv);
  mesh.rest.resize(2, nv);
  mesh.triangles.resize(3, nf);

  for (int e = 0; e < static_cast<int>(header.elements.size()); ++e) {
    const Element& element = header.elements[e];
    const bool is_vertex = e == layout.vertex_element;
    const bool is_face = e == layout.face_element;
    if (element.properties.empty()) continue;  // nothing to read, however many items it declares
    for (std::int64_t item = 0; item < element.count; ++item) {
      for (int p = 0; p < static_cast<int>(element.properties.size()); ++p) {
        const Property& property = element.properties[p];
        if (!property.is_list) {
          const auto value = reader.next(property.type);
          if (!value) return data_error(element, item, reader.problem());
          if (!is_vertex) continue;
          switch (layout.vertex_slots[p]) {
            case Slot::kX: mesh.positions(0, item) = *value; break;
            case Slot::kY: mesh.positions(1, item) = *value; break;
            case Slot::kZ: mesh.positions(2, item) = *value; break;
            case Slot::kU: mesh.rest(0, item) = *value; break;
            case Slot::kV: mesh.rest(1, item) = *value; break;
            case Slot::kNone: break;
          }
          continue;
        }
        const auto length = reader.next(property.count_type);
        if (!length) return data_error(element, item, reader.problem());
        if (*length < 0) return data_error(element, item, "negative list length");
        const bool is_triangle_list = is_face && p == layout.face_indices;
        if (is_triangle_list && *length != 3) {
          return data_error(element, item,
                            "face has " + std::to_string(static_cast<std::int64_t>(*length)) +
                                " vertices; only triangles are supported (triangulate the mesh first)");
        }
        for (std::int64_t k = 0; k < static_cast<std::int64_t>(*length); ++k) {
          const auto value = reader.next(property.type);
          if (!value) return data_error(element, item, reader.problem());
          if (!is_triangle_list) continue;
          if (*value < 0 || *value >= nv) {
            return data_error(element, item,
                              "vertex index " + std::to_string(static_cast<std::int64_t>(*value)) +
                                  " is out of range (the file has " + std::to_string(nv) + " vertices)");
          }
          mesh.triangles(k, item) = static_cast<int>(*value);
        }
      }
      if (is_vertex && !layout.has_uv) mesh.rest.col(item) = mesh.positions.col(item).head<2>();
      if (is_vertex && !(mesh.positions.col(item).allFinite() && mesh.rest.col(item).allFinite())) {
        return data_error(element, item, "non-finite vertex coordinate");
      }
    }
  }
  return mesh;
}

// ---------------------------------------------------------------------------------------------------------------------
// Files.

std::string system_reason(int error_number) { return std::generic_category().message(error_number); }

/// The whole content of the file at `path`.
Expected<std::string> read_file(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return Error{"cannot open: " + system_reason(errno)};
  std::string content;
  std::array<char, 1 << 16> chunk;
  std::size_t got = 0;
  while ((got = std::fread(chunk.data(), 1, chunk.size(), file)) > 0) content.append(chunk.data(), got);
  const int error_number = errno;
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) return Error{"cannot read: " + system_reason(error_number)};
  return content;
}

/// Writes `bytes` to a temporary file of its own beside `path` (`path.tmp.PID.N`: writers racing for one path never
/// share it), syncs it and renames it over `path`.
Status write_file_atomically(const std::string& path, const std::string& bytes) {
  // An existing device or pipe (a FIFO, /dev/null), or a path under /dev or /proc (/dev/stdout, also redirected to a
  // file): written in place and appended, as storage::write_file_atomic does; a rename would replace the device or
  // the system's link with a file. A symbolic link elsewhere is replaced, not followed.
  struct stat st {};
  std::error_code ec;
  const std::string absolute = std::filesystem::absolute(path, ec).lexically_normal().string();
  if (::stat(path.c_str(), &st) == 0 && !S_ISDIR(st.st_mode) &&
      (!S_ISREG(st.st_mode) || absolute.rfind("/dev/", 0) == 0 || absolute.rfind("/proc/", 0) == 0)) {
    std::FILE* out = std::fopen(path.c_str(), "ab");
    if (out == nullptr) return Error{"write_ply: '" + path + "': cannot open: " + system_reason(errno)};
    const bool written = std::fwrite(bytes.data(), 1, bytes.size(), out) == bytes.size();
    const int write_errno = errno;
    if (std::fclose(out) != 0 || !written)
      return Error{"write_ply: '" + path + "': cannot write: " + system_reason(written ? errno : write_errno)};
    return {};
  }
  static std::atomic<std::uint64_t> counter{0};
  const std::string temporary = path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
  auto fail = [&](const std::string& what, int error_number) {
    std::remove(temporary.c_str());
    return Error{"write_ply: '" + path + "': " + what + ": " + system_reason(error_number)};
  };
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr) return Error{"write_ply: '" + path + "': cannot create '" + temporary + "': " +
                                    system_reason(errno)};
  const bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size() && std::fflush(file) == 0 &&
                       fsync(fileno(file)) == 0;
  const int write_errno = errno;
  if (std::fclose(file) != 0 || !written)
    return fail("cannot write '" + temporary + "'", written ? errno : write_errno);
  if (std::rename(temporary.c_str(), path.c_str()) != 0) return fail("cannot rename '" + temporary + "'", errno);
  return {};
}

/// Why `mesh` cannot be written, if it cannot.
std::optional<std::string> invalid_for_writing(const ClothMesh& mesh) {
  const Eigen::Index nv = mesh.positions.cols();
  if (mesh.rest.cols() != nv) return "positions and rest coordinates have different vertex counts";
  if (nv == 0) return "the mesh has no vertices";
  if (mesh.triangles.cols() == 0) return "the mesh has no triangles";
  if (mesh.triangles.size() > 0 && (mesh.triangles.minCoeff() < 0 || mesh.triangles.maxCoeff() >= nv)) {
    return "a triangle refers to a vertex out of range";
  }
  if (!mesh.positions.allFinite() || !mesh.rest.allFinite()) return "the mesh has a non-finite coordinate";
  if (!std::isfinite(mesh.material_angle)) return "the material angle is not finite";
  return std::nullopt;
}

/// The shortest decimal text that reads back as exactly `value`.
std::string shortest_text(double value) {
  std::array<char, 32> buffer;
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return ec == std::errc() ? std::string(buffer.data(), end) : std::string("0");
}

}  // namespace

Status write_ply(const std::string& path, const ClothMesh& mesh) {
  if (const auto problem = invalid_for_writing(mesh)) return Error{"write_ply: '" + path + "': " + *problem};
  const auto nv = static_cast<int>(mesh.positions.cols());
  const int nt = mesh.triangle_count();

  std::string bytes =
      "ply\n"
      "format binary_little_endian 1.0\n"
      "comment drapegen cloth mesh: x y z world positions, u v rest coordinates (metres)\n"
      "comment material_angle " + shortest_text(mesh.material_angle) + "\n" +
      "element vertex " + std::to_string(nv) + "\n" +
      "property double x\nproperty double y\nproperty double z\nproperty double u\nproperty double v\n"
      "element face " + std::to_string(nt) + "\n" +
      "property list uchar int vertex_indices\n"
      "end_header\n";
  bytes.reserve(bytes.size() + 40 * static_cast<std::size_t>(nv) + 13 * static_cast<std::size_t>(nt));
  for (int i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) append_le(bytes, mesh.positions(k, i));
    for (int k = 0; k < 2; ++k) append_le(bytes, mesh.rest(k, i));
  }
  for (int t = 0; t < nt; ++t) {
    append_le(bytes, std::uint8_t{3});
    for (int k = 0; k < 3; ++k) append_le(bytes, static_cast<std::int32_t>(mesh.triangles(k, t)));
  }
  return write_file_atomically(path, bytes);
}

Expected<ClothMesh> read_ply(const std::string& path) {
  auto prefixed = [&](const Error& error) { return Error{"read_ply: '" + path + "': " + error.message}; };
  const Expected<std::string> file = read_file(path);
  if (!file) return prefixed(file.error());
  const std::string_view content = *file;

  const Expected<Header> header = parse_header(content);
  if (!header) return prefixed(header.error());
  const std::string_view data = content.substr(header->data_offset);
  const Expected<Layout> layout = find_layout(*header, data.size());
  if (!layout) return prefixed(layout.error());

  // The data must end where the header's counts say: more (a count too small) would drop part of the mesh unseen.
  auto read_all = [&](auto& reader) -> Expected<ClothMesh> {
    Expected<ClothMesh> body = read_body(*header, *layout, reader);
    if (body && reader.unread() > 0) {
      return Error{"trailing data: " + std::to_string(reader.unread()) +
                   " bytes follow the last item the header declares (an element count too small?)"};
    }
    return body;
  };
  Expected<ClothMesh> mesh = Error{};
  if (header->format == Format::kAscii) {
    AsciiReader reader(data);
    mesh = read_all(reader);
  } else {
    BinaryReader reader(data);
    mesh = read_all(reader);
  }
  if (!mesh) return prefixed(mesh.error());
  return mesh;
}

}  // namespace drapegen::sim
