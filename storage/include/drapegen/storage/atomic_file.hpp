#pragma once
// Crash-safe file writes: the bytes go to a temporary file beside `path` (temporary_path), are fsync'ed, and the file
// is renamed over `path`; the directory is fsync'ed (sync_directory) before the manifest transaction that refers to
// the file commits. A crash at any instant leaves either no file, a stray temporary (removed on resume) or the
// complete file; writers racing for one path each rename a complete file, the last one wins.

#include <string>
#include <string_view>

#include "drapegen/sim/expected.hpp"

namespace drapegen::storage {

/// A name beside `path` that no other call of this process returns: `path.tmp.PID.N`. (Another process with the same
/// PID, earlier or on another host, may have used it: write_file_atomic creates it exclusively and moves on if so.)
[[nodiscard]] std::string temporary_path(const std::string& path);
/// An existing device or pipe (a FIFO, /dev/null), or a path under /dev or /proc (/dev/stdout, /proc/self/fd/N,
/// also where it leads to a regular file: a redirected standard output): written in place, no rename, appended.
[[nodiscard]] bool written_in_place(const std::string& path);
/// Writes `bytes` to `path` atomically (tmp, fsync, rename), the file created with `mode` (less the umask) from the
/// start. Errors name the path and the OS error (e.g. "No space left on device", "Permission denied"). Where
/// written_in_place(path), it is written in place instead. A symbolic link elsewhere is replaced, not followed.
[[nodiscard]] sim::Status write_file_atomic(const std::string& path, std::string_view bytes, unsigned mode = 0644);
/// fsync of a directory, so that renames into it are durable.
[[nodiscard]] sim::Status sync_directory(const std::string& directory);

}  // namespace drapegen::storage
