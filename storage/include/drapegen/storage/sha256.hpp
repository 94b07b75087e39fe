#pragma once
// SHA-256 (FIPS 180-4) of byte strings and files: the checksum the manifest records for every result file.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "drapegen/sim/expected.hpp"

namespace drapegen::storage {

class Sha256 {
 public:
  Sha256();
  void update(const void* data, std::size_t size);
  void update(std::string_view bytes) { update(bytes.data(), bytes.size()); }
  /// The digest as 64 lowercase hex digits (the object is spent afterwards).
  [[nodiscard]] std::string hex_digest();

 private:
  void block(const std::uint8_t* p);
  std::array<std::uint32_t, 8> h_;
  std::array<std::uint8_t, 64> buffer_{};
  std::size_t buffered_ = 0;
  std::uint64_t length_ = 0;
};

[[nodiscard]] std::string sha256_hex(std::string_view bytes);
[[nodiscard]] sim::Expected<std::string> sha256_file(const std::string& path);

}  // namespace drapegen::storage
