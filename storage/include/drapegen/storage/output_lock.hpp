#pragma once
// One coordinator per output directory: an exclusive advisory lock (flock) on OUTPUT/.lock, held for the
// coordinator's lifetime and released by the kernel when the process ends however it ends (no stale lock to clear
// after a crash). A second coordinator on the same output, a `--resume` while the run is live included, is refused
// before it touches anything: resume removes the result files the manifest does not record, which for a live run
// are files it is still writing or about to commit.

#include <string>
#include <utility>

#include "drapegen/sim/expected.hpp"

namespace drapegen::storage {

class OutputLock {
 public:
  /// Locks `directory` (which must exist), or an error naming the directory and, where it recorded one, the
  /// process that holds it.
  [[nodiscard]] static sim::Expected<OutputLock> acquire(const std::string& directory);

  OutputLock(OutputLock&& other) noexcept;
  OutputLock& operator=(OutputLock&& other) noexcept;
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  ~OutputLock();

  /// The lock file, OUTPUT/.lock.
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  OutputLock(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  int fd_ = -1;
  std::string path_;
};

}  // namespace drapegen::storage
