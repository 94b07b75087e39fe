#include "drapegen/storage/read_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace drapegen::storage {

sim::Expected<std::string> read_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return sim::Error{"cannot read " + path + ": it is a directory"};
  std::ifstream in(path, std::ios::binary);
  if (!in) return sim::Error{"cannot read " + path + ": " + std::strerror(errno)};
  std::string bytes;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) bytes.append(buffer, static_cast<std::size_t>(in.gcount()));
  if (in.bad()) return sim::Error{"cannot read " + path + ": " + std::strerror(errno)};  // not a shorter file
  return bytes;
}

}  // namespace drapegen::storage
