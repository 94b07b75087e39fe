// OutputLock: one coordinator per output directory.
#include "drapegen/storage/output_lock.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <optional>
#include <string>

namespace drapegen::storage {
namespace {

namespace fs = std::filesystem;

TEST(OutputLock, IsExclusiveUntilReleasedAndNamesItsHolder) {
  const fs::path dir = fs::temp_directory_path() / "drapegen_output_lock_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::optional<OutputLock> first;
  {
    auto lock = OutputLock::acquire(dir.string());
    ASSERT_TRUE(lock.has_value()) << lock.error().message;
    EXPECT_EQ(lock->path(), (dir / ".lock").string());
    first.emplace(std::move(lock).value());  // moved: still held
  }
  // A second lock (another open of the file, as another process makes) is refused while the first is held.
  auto second = OutputLock::acquire(dir.string());
  ASSERT_FALSE(second.has_value());
  EXPECT_NE(second.error().message.find("is in use by another coordinator (pid " + std::to_string(::getpid()) + ")"),
            std::string::npos)
      << second.error().message;
  first.reset();
  auto third = OutputLock::acquire(dir.string());
  EXPECT_TRUE(third.has_value()) << third.error().message;
  // A directory that does not exist: an error naming the lock file.
  auto missing = OutputLock::acquire((dir / "absent").string());
  ASSERT_FALSE(missing.has_value());
  EXPECT_NE(missing.error().message.find("cannot open " + (dir / "absent" / ".lock").string()), std::string::npos)
      << missing.error().message;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace drapegen::storage
