#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>

#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/read_file.hpp"

namespace drapegen::storage {
namespace {

TEST(ReadFile, ReadsEveryByteAndSaysWhyItCannot) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("drapegen_read_file_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string bytes(200000, '\0');  // longer than one read, with zero bytes inside
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7);
  const std::string path = (dir / "f.bin").string();
  ASSERT_TRUE(write_file_atomic(path, bytes));
  auto read = read_file(path);
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(*read, bytes);
  ASSERT_TRUE(write_file_atomic(path, ""));
  EXPECT_EQ(read_file(path).value(), "");

  const auto missing = read_file((dir / "missing").string());
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message, "cannot read " + (dir / "missing").string() + ": No such file or directory");
  const auto directory = read_file(dir.string());
  ASSERT_FALSE(directory);
  EXPECT_EQ(directory.error().message, "cannot read " + dir.string() + ": it is a directory");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace drapegen::storage
