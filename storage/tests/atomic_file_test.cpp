#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>
#include <fcntl.h>
#include <unistd.h>

#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/sha256.hpp"

namespace drapegen::storage {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const auto dir = fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(AtomicFile, WritesAndChecksums) {
  const auto dir = fresh_dir("drapegen_atomic_test");
  const std::string path = (dir / "a.bin").string();
  ASSERT_TRUE(write_file_atomic(path, "hello"));
  ASSERT_TRUE(sync_directory(dir.string()));
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"a.bin"});  // no temporary left
  EXPECT_EQ(*sha256_file(path), sha256_hex("hello"));
  // A path under a regular file cannot be written: a clear error, no file.
  const auto bad = write_file_atomic(path + "/x.bin", "data");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("Not a directory"), std::string::npos) << bad.error().message;
  EXPECT_FALSE(sha256_file((dir / "missing").string()));
  // A private file is private from its first byte.
  const std::string secret = (dir / "s.key").string();
  ASSERT_TRUE(write_file_atomic(secret, "key", 0600));
  EXPECT_EQ(fs::status(secret).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(*sha256_file(secret), sha256_hex("key"));
  // A rename that fails (the path is a directory) says so and leaves no temporary behind.
  fs::create_directories(dir / "d.bin" / "inside");
  const auto blocked = write_file_atomic((dir / "d.bin").string(), "data");
  ASSERT_FALSE(blocked);
  EXPECT_NE(blocked.error().message.find("Is a directory"), std::string::npos) << blocked.error().message;
  EXPECT_EQ(names_in(dir), (std::vector<std::string>{"a.bin", "d.bin", "s.key"}));
  fs::remove_all(dir);
}

TEST(AtomicFile, WritesADeviceOrPipeInPlaceAndReplacesALinkElsewhere) {
  // --out /dev/stdout into a pipe: the bytes go down the pipe; a rename over /proc/self/fd/N would fail (or, for
  // /dev/stdout as root, replace the device link with a file).
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const std::string pipe_path = "/proc/self/fd/" + std::to_string(fds[1]);
  const auto s = write_file_atomic(pipe_path, "through the pipe");
  ASSERT_TRUE(s) << s.error().message;
  char got[32] = {};
  ASSERT_EQ(::read(fds[0], got, sizeof got), 16);
  EXPECT_EQ(std::string(got, 16), "through the pipe");
  ::close(fds[0]);
  ::close(fds[1]);
  const auto dir = std::filesystem::path(::testing::TempDir()) / ("atomic_link_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  // /dev/stdout redirected to a file (here /proc/self/fd/N of a file): appended in place, the file kept.
  std::ofstream(dir / "redirected") << "before ";
  const int fd = ::open((dir / "redirected").c_str(), O_WRONLY);
  ASSERT_GE(fd, 0);
  ASSERT_TRUE(write_file_atomic("/proc/self/fd/" + std::to_string(fd), "after"));
  ::close(fd);
  std::ifstream redirected(dir / "redirected");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(redirected), {}), "before after");
  // A regular file that lives under /dev (the /dev/shm tmpfs) is replaced like any other, not appended to.
  if (std::filesystem::is_directory("/dev/shm")) {
    const std::string shm = "/dev/shm/drapegen_atomic_" + std::to_string(::getpid());
    ASSERT_TRUE(write_file_atomic(shm, "first"));
    EXPECT_FALSE(written_in_place(shm));
    ASSERT_TRUE(write_file_atomic(shm, "second"));
    std::ifstream in(shm);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "second");
    std::filesystem::remove(shm);
  }
  // A symbolic link elsewhere (one planted in a scratch directory): the link is replaced, its target untouched.
  std::ofstream(dir / "target") << "old";
  std::filesystem::remove(dir / "link");
  std::filesystem::create_symlink(dir / "target", dir / "link");
  ASSERT_TRUE(write_file_atomic((dir / "link").string(), "new"));
  EXPECT_FALSE(std::filesystem::is_symlink(dir / "link"));
  std::ifstream target(dir / "target");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(target), {}), "old");
  std::filesystem::remove_all(dir);
}

TEST(AtomicFile, TemporaryNamesAreDistinctAndLeftOnesAreSkipped) {
  const std::string a = temporary_path("/x/y.exr"), b = temporary_path("/x/y.exr");
  EXPECT_NE(a, b);
  EXPECT_EQ(a.rfind("/x/y.exr.tmp.", 0), 0u) << a;
  // Temporaries a crashed process with this PID would have left under the next names: the write still succeeds.
  const auto dir = fresh_dir("drapegen_atomic_left");
  const std::string path = (dir / "e.txt").string();
  const std::string next = temporary_path(path);
  const std::string stem = next.substr(0, next.rfind('.') + 1);
  const std::uint64_t n = std::stoull(next.substr(next.rfind('.') + 1));
  for (std::uint64_t k = n + 1; k < n + 6; ++k) std::ofstream(stem + std::to_string(k)) << "left";
  ASSERT_TRUE(write_file_atomic(path, "fresh"));
  EXPECT_EQ(*sha256_file(path), sha256_hex("fresh"));
  EXPECT_EQ(names_in(dir).size(), 6u);  // e.txt and the five left ones, untouched
  fs::remove_all(dir);
}

TEST(AtomicFile, WritersRacingForOnePathEachLeaveAWholeFile) {
  // Four threads write one path 50 times each, each its own 256 KiB content: after every round the file is one of
  // the contents in full (with one shared temporary name, a writer could rename another's half-written file).
  const auto dir = fresh_dir("drapegen_atomic_race");
  const std::string path = (dir / "r.bin").string();
  std::vector<std::string> contents;
  for (char c : {'a', 'b', 'c', 'd'}) contents.emplace_back(256 * 1024, c);
  for (int round = 0; round < 50; ++round) {
    std::vector<std::thread> writers;
    std::atomic<int> failures{0};
    for (const std::string& content : contents) {
      writers.emplace_back([&] { failures += write_file_atomic(path, content) ? 0 : 1; });
    }
    for (auto& t : writers) t.join();
    ASSERT_EQ(failures.load(), 0);
    std::ifstream in(path, std::ios::binary);
    const std::string got((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_NE(std::find(contents.begin(), contents.end(), got), contents.end()) << "round " << round;
  }
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"r.bin"});
  fs::remove_all(dir);
}

TEST(AtomicFile, ASetOfFilesIsReplacedWholeOrNotAtAll) {
  const auto dir = fresh_dir("drapegen_atomic_set");
  const std::string a = (dir / "p_00.exr").string(), b = (dir / "p_01.exr").string();
  ASSERT_TRUE(write_file_atomic(a, "old a"));
  ASSERT_TRUE(write_file_atomic(b, "old b"));
  // The second file cannot be created (its directory is a file): the first keeps its old bytes, no temporary left.
  const std::string blocked = (dir / "p_00.exr" / "p_02.exr").string();
  const std::vector<FileBytes> failing{{a, "new a"}, {b, "new b"}, {blocked, "new c"}};
  const auto s = write_files_atomic(failing);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("Not a directory"), std::string::npos) << s.error().message;
  EXPECT_TRUE(s.error().io);
  EXPECT_EQ(*sha256_file(a), sha256_hex("old a"));
  EXPECT_EQ(*sha256_file(b), sha256_hex("old b"));
  EXPECT_EQ(names_in(dir), (std::vector<std::string>{"p_00.exr", "p_01.exr"}));
  // Written whole: every file new, no temporary left.
  const std::vector<FileBytes> files{{a, "new a"}, {b, "new b"}, {(dir / "p_02.exr").string(), "new c"}};
  ASSERT_TRUE(write_files_atomic(files));
  EXPECT_EQ(*sha256_file(a), sha256_hex("new a"));
  EXPECT_EQ(*sha256_file(b), sha256_hex("new b"));
  EXPECT_EQ(names_in(dir), (std::vector<std::string>{"p_00.exr", "p_01.exr", "p_02.exr"}));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace drapegen::storage
