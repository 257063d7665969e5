// SPDX-License-Identifier: MIT
// Whole-file reading, and writing that never leaves a partial output behind. In the core library, so that the
// binary format (hbvh/tree/binary_format.hpp) and hbvh::io read and replace files the same way.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "hbvh/result.hpp"

namespace hbvh {

/// The bytes of the file at `path`, unchanged (text or not). A missing, unreadable or directory path gives an
/// Error whose `file` is `path` and whose message says why (from the operating system).
[[nodiscard]] Result<std::string> read_text_file(const std::filesystem::path& path);

/// Replaces the file at `path` with `content` atomically: the content goes to a new temporary file in
/// the same directory, is flushed to disk (fsync), and is then renamed over `path`. Readers therefore
/// see either the old file or the complete new one. On any failure the temporary file is removed and
/// `path` is left as it was. An existing file's permission bits are kept; a new file gets the usual
/// 0666 & ~umask. A symbolic link to a regular file is followed: the file it names is replaced and the link
/// kept (a dangling link keeps its place too, and the file it names is made); a link to a directory is refused. Two kinds of path are
/// written into instead of replaced, since there is nothing there to replace atomically: the process's own
/// standard output or error, by whatever name (`/dev/stdout`, `/dev/fd/1`, the file the shell redirected it
/// to), through that descriptor; and a device, fifo or socket (`/dev/null`, a pipe). POSIX only.
[[nodiscard]] Status write_file_atomic(const std::filesystem::path& path, std::string_view content);

/// Removes the temporary files of the write_file_atomic calls under way in this process, leaving their targets as
/// they were. For a program's handler of SIGINT, SIGTERM or SIGHUP, which would otherwise leave a hidden
/// `.NAME.tmp-...` file behind when it ends the process in the middle of a write: async-signal-safe (it only reads
/// fixed slots and calls unlink), and after it each interrupted write fails if it resumes. The library installs no
/// signal handler itself; the hbvh CLI does (docs/formats.md, "Writing files safely"). Up to 64 writes at once
/// are tracked; a program with more in flight keeps the old behaviour for the rest.
void remove_pending_temporary_files() noexcept;

}  // namespace hbvh
