#pragma once
// Crash-safe file writes: the bytes go to a temporary file beside `path` (temporary_path), are fsync'ed, and the file
// is renamed over `path`; the directory is fsync'ed (sync_directory) before the manifest transaction that refers to
// the file commits. A crash at any instant leaves either no file, a stray temporary (removed on resume) or the
// complete file; writers racing for one path each rename a complete file, the last one wins.

#include <span>
#include <string>
#include <string_view>

#include "drapegen/sim/expected.hpp"

namespace drapegen::storage {

/// A name beside `path` that no other call of this process returns: `path.tmp.PID.N`. (Another process with the same
/// PID, earlier or on another host, may have used it: write_file_atomic creates it exclusively and moves on if so.)
[[nodiscard]] std::string temporary_path(const std::string& path);
/// An existing device or pipe (a FIFO, /dev/null, /dev/stdout on a terminal or pipe), or a link under /dev or /proc
/// that leads to a regular file (/dev/stdout, /proc/self/fd/N of a redirected standard output): written in place, no
/// rename, appended. A regular file that lives under /dev (/dev/shm) is not: it is replaced atomically.
[[nodiscard]] bool written_in_place(const std::string& path);
/// Writes `bytes` to `path` atomically (tmp, fsync, rename), the file created with `mode` (less the umask) from the
/// start. Errors name the path and the OS error (e.g. "No space left on device", "Permission denied"). Where
/// written_in_place(path), it is written in place instead. A symbolic link elsewhere is replaced, not followed.
[[nodiscard]] sim::Status write_file_atomic(const std::string& path, std::string_view bytes, unsigned mode = 0644);
/// One file of write_files_atomic: its path and its bytes (which must outlive the call).
struct FileBytes {
  std::string path;
  std::string_view bytes;
};
/// Writes a set of files that belong together (a data point's EXRs) so that a failure leaves none of them replaced:
/// every file's temporary is written and synced first, and any error removes them all, every path as it was; only
/// then is each renamed over its path (files written in place, as write_file_atomic does, are written then). A rename
/// that fails (a directory now at the path) stops there: the files before it are the new ones.
[[nodiscard]] sim::Status write_files_atomic(std::span<const FileBytes> files, unsigned mode = 0644);
/// fsync of a directory, so that renames into it are durable.
[[nodiscard]] sim::Status sync_directory(const std::string& directory);

}  // namespace drapegen::storage
