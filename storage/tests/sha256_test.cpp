#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/sha256.hpp"

namespace drapegen::storage {
namespace {

TEST(Sha256, KnownVectors) {  // FIPS 180-4 examples
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  Sha256 million;
  const std::string chunk(1000, 'a');
  for (int i = 0; i < 1000; ++i) million.update(chunk);
  EXPECT_EQ(million.hex_digest(), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(AtomicFile, WritesAndChecksums) {
  const auto dir = std::filesystem::temp_directory_path() / ("drapegen_atomic_test_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "a.bin").string();
  ASSERT_TRUE(write_file_atomic(path, "hello"));
  ASSERT_TRUE(sync_directory(dir.string()));
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  EXPECT_EQ(*sha256_file(path), sha256_hex("hello"));
  // A path under a regular file cannot be written: a clear error, no file.
  const auto bad = write_file_atomic(path + "/x.bin", "data");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("Not a directory"), std::string::npos) << bad.error().message;
  EXPECT_FALSE(sha256_file((dir / "missing").string()));
  // A private file is private from its first byte, even where a stale temporary of a wider mode is left.
  namespace fs = std::filesystem;
  const std::string secret = (dir / "s.key").string();
  std::ofstream(secret + ".tmp") << "stale";
  fs::permissions(secret + ".tmp",
                  fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read | fs::perms::others_read);
  ASSERT_TRUE(write_file_atomic(secret, "key", 0600));
  EXPECT_EQ(fs::status(secret).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(*sha256_file(secret), sha256_hex("key"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace drapegen::storage
