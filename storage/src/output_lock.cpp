#include "drapegen/storage/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fmt/format.h>
#include <string>
#include <utility>

namespace drapegen::storage {

sim::Expected<OutputLock> OutputLock::acquire(const std::string& directory) {
  std::string path = directory + "/.lock";
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return sim::Error{fmt::format("cannot open {}: {}", path, std::strerror(errno)), true};
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    std::string holder;
    char text[32] = {};
    if (error == EWOULDBLOCK && ::pread(fd, text, sizeof(text) - 1, 0) > 0) holder = fmt::format(" (pid {})", text);
    ::close(fd);
    if (error == EWOULDBLOCK) {
      return sim::Error{fmt::format("{} is in use by another coordinator{}: one run per output directory; stop "
                                    "that one first",
                                    directory, holder)};
    }
    return sim::Error{fmt::format("cannot lock {}: {}", path, std::strerror(error)), true};
  }
  // The holder's pid, for the message above (informational: the lock is the flock, not the file's content).
  const std::string pid = std::to_string(::getpid());
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
    const int error = errno;
    ::close(fd);
    return sim::Error{fmt::format("cannot write {}: {}", path, std::strerror(error)), true};
  }
  return OutputLock(fd, std::move(path));
}

OutputLock::OutputLock(OutputLock&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), path_(std::move(other.path_)) {}

OutputLock& OutputLock::operator=(OutputLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
  }
  return *this;
}

OutputLock::~OutputLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the last descriptor releases the flock
}

}  // namespace drapegen::storage
