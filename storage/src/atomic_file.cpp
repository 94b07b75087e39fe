#include "drapegen/storage/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

namespace drapegen::storage {
namespace {

sim::Error os_error(const std::string& what, const std::string& path) {
  return sim::Error{what + " " + path + ": " + std::strerror(errno), /*io=*/true};
}

}  // namespace

bool written_in_place(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return false;  // a new file
  if (!S_ISREG(st.st_mode)) return !S_ISDIR(st.st_mode);
  // A regular file: in place only where the system's link under /dev or /proc leads to it (/dev/stdout,
  // /proc/self/fd/N of a redirected output). A file that lives there (/dev/shm/x.csv) is replaced like any other.
  struct stat link {};
  if (::lstat(path.c_str(), &link) != 0 || !S_ISLNK(link.st_mode)) return false;
  std::error_code ec;
  const std::string absolute = std::filesystem::absolute(path, ec).lexically_normal().string();
  return absolute.rfind("/dev/", 0) == 0 || absolute.rfind("/proc/", 0) == 0;
}

std::string temporary_path(const std::string& path) {
  static std::atomic<std::uint64_t> counter{0};
  return fmt::format("{}.tmp.{}.{}", path, ::getpid(), counter.fetch_add(1));
}

namespace {

/// Writes `bytes` to an existing device or pipe, or through /dev or /proc (/dev/stdout), as it is: no temporary, no
/// rename (it would replace the device or the system's link with a file), no sync (/dev/null takes none); appended
/// where the link leads to a regular file (a redirected standard output).
sim::Status write_in_place(const std::string& path, std::string_view bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) return os_error("cannot open", path);
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      sim::Error e = os_error("cannot write", path);
      ::close(fd);
      return e;
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) return os_error("cannot close", path);
  return {};
}

}  // namespace

namespace {

/// `bytes` in a new temporary beside `path`, synced and closed: its name, or the error (nothing left behind).
sim::Expected<std::string> write_temporary(const std::string& path, std::string_view bytes, unsigned mode) {
  // O_EXCL: the file is new, this call's alone, and has `mode` from its first byte. A name can still exist: left by
  // a crashed process that had this PID (a restarted container), or by one on another host sharing the directory;
  // the next name is tried then.
  std::string tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    tmp = temporary_path(path);
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, static_cast<mode_t>(mode));
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) return os_error("cannot create", tmp);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      sim::Error e = os_error("cannot write", tmp);
      ::close(fd);
      ::unlink(tmp.c_str());
      return e;
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    sim::Error e = os_error("cannot sync", tmp);
    ::close(fd);
    ::unlink(tmp.c_str());
    return e;
  }
  if (::close(fd) != 0) {
    sim::Error e = os_error("cannot close", tmp);
    ::unlink(tmp.c_str());
    return e;
  }
  return tmp;
}

sim::Status rename_over(const std::string& tmp, const std::string& path) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    sim::Error e = os_error("cannot rename to", path);
    ::unlink(tmp.c_str());
    return e;
  }
  return {};
}

}  // namespace

sim::Status write_files_atomic(std::span<const FileBytes> files, unsigned mode) {
  std::vector<std::string> temporaries(files.size());  // empty: written in place at the end
  const auto remove_temporaries = [&](std::size_t from) {
    for (std::size_t i = from; i < temporaries.size(); ++i) {
      if (!temporaries[i].empty()) ::unlink(temporaries[i].c_str());
    }
  };
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (written_in_place(files[i].path)) continue;
    auto tmp = write_temporary(files[i].path, files[i].bytes, mode);
    if (!tmp) {
      remove_temporaries(0);
      return tmp.error();
    }
    temporaries[i] = std::move(*tmp);
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    sim::Status s = temporaries[i].empty() ? write_in_place(files[i].path, files[i].bytes)
                                           : rename_over(temporaries[i], files[i].path);
    if (!s) {
      remove_temporaries(i + 1);
      return s;
    }
  }
  return {};
}

sim::Status write_file_atomic(const std::string& path, std::string_view bytes, unsigned mode) {
  const FileBytes file{path, bytes};
  return write_files_atomic({&file, 1}, mode);
}

sim::Status sync_directory(const std::string& directory) {
  const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return os_error("cannot open directory", directory);
  if (::fsync(fd) != 0) {
    sim::Error e = os_error("cannot sync directory", directory);
    ::close(fd);
    return e;
  }
  ::close(fd);
  return {};
}

}  // namespace drapegen::storage
