#pragma once
// OpenEXR streams over memory: for files encoded to bytes (sent over the network, or written atomically by
// storage::write_file_atomic) and decoded from bytes.

#include <ImfIO.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace drapegen::renderer {

/// Collects what Imf::OutputFile writes in `data`.
class MemoryOStream final : public Imf::OStream {
 public:
  MemoryOStream() : Imf::OStream("<memory>") {}
  void write(const char c[], int n) override {
    if (position_ + n > data.size()) data.resize(position_ + n);
    std::memcpy(data.data() + position_, c, static_cast<std::size_t>(n));
    position_ += n;
  }
  std::uint64_t tellp() override { return position_; }
  void seekp(std::uint64_t pos) override { position_ = pos; }
  std::vector<char> data;

 private:
  std::uint64_t position_ = 0;
};

/// Reads a file's bytes; `bytes` must outlive the stream.
class MemoryIStream final : public Imf::IStream {
 public:
  explicit MemoryIStream(const std::vector<char>& bytes) : Imf::IStream("<memory>"), bytes_(bytes) {}
  explicit MemoryIStream(std::vector<char>&&) = delete;  // it would outlive the bytes
  bool read(char c[], int n) override {
    if (position_ + n > bytes_.size()) throw std::runtime_error("unexpected end of EXR data");
    std::memcpy(c, bytes_.data() + position_, static_cast<std::size_t>(n));
    position_ += n;
    return position_ < bytes_.size();
  }
  std::uint64_t tellg() override { return position_; }
  void seekg(std::uint64_t pos) override { position_ = pos; }

 private:
  const std::vector<char>& bytes_;
  std::uint64_t position_ = 0;
};

}  // namespace drapegen::renderer
