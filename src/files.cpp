// SPDX-License-Identifier: MIT
// read_text_file and write_file_atomic on POSIX file descriptors, so every failure has its errno.
#include "hbvh/files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <optional>
#include <system_error>

#include "memory/huge_pages.hpp"

namespace hbvh {
namespace {

/// The operating system's words for `code` (std::generic_category is thread-safe, strerror is not).
std::string describe(int code) { return std::generic_category().message(code); }

/// Closes `fd` on scope exit unless released, so early returns cannot leak descriptors.
class FileDescriptor {
public:
    explicit FileDescriptor(int fd) : fd_(fd) {}
    FileDescriptor(const FileDescriptor&) = delete;
    FileDescriptor& operator=(const FileDescriptor&) = delete;
    ~FileDescriptor() {
        if (fd_ >= 0) ::close(fd_);
    }
    [[nodiscard]] int get() const { return fd_; }
    /// Closes now and reports close()'s own error: on some file systems that is where a failed write shows.
    int close_checked() {
        const int fd = fd_;
        fd_ = -1;
        return ::close(fd) == 0 ? 0 : errno;
    }

private:
    int fd_;
};

/// Writes all of `data`, resuming after partial writes and signals. Returns 0 or an errno value.
int write_all(int fd, std::string_view data) {
    while (!data.empty()) {
        const ssize_t written = ::write(fd, data.data(), data.size());
        if (written < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        data.remove_prefix(static_cast<std::size_t>(written));
    }
    return 0;
}

/// One read(), resumed after signals: the byte count, 0 at the end of the file, or -1 with errno set.
ssize_t read_some(int fd, char* data, std::size_t size) {
    for (;;) {
        const ssize_t count = ::read(fd, data, size);
        if (count >= 0 || errno != EINTR) return count;
    }
}

/// open(), resumed after signals (a fifo's open blocks until the other end opens, long enough to be interrupted):
/// the descriptor, or -1 with errno set.
int open_retrying(const std::filesystem::path& path, int flags) {
    for (;;) {
        const int fd = ::open(path.c_str(), flags);
        if (fd >= 0 || errno != EINTR) return fd;
    }
}

/// Writes `content` into the existing non-regular file at `path` (a device, fifo or socket), without truncating
/// or replacing it.
Status write_into_stream(const std::filesystem::path& path, std::string_view content) {
    const std::string name = path.string();
    const int fd = open_retrying(path, O_WRONLY | O_CLOEXEC);
    if (fd < 0) return Error("cannot open for writing: " + describe(errno), name);
    FileDescriptor stream(fd);
    if (const int code = write_all(stream.get(), content); code != 0)
        return Error("cannot write: " + describe(code), name);
    if (const int code = stream.close_checked(); code != 0) return Error("cannot write: " + describe(code), name);
    return Ok{};
}

/// The temporary files being written, for remove_pending_temporary_files (a signal handler): fixed slots, so
/// that the handler reads them without locks or allocation. A writer claims a free slot, copies the path in, and
/// only then publishes it; the handler unlinks what is published.
class PendingTemporaries {
public:
    static constexpr std::size_t slots = 64;
    static constexpr std::size_t path_bytes = 4096;  // PATH_MAX on Linux

    /// Records `path`; the slot number to release, or `slots` when none is free or the path is too long.
    std::size_t add(const std::filesystem::path& path) noexcept {
        const std::string& text = path.native();
        if (text.size() >= path_bytes) return slots;
        for (std::size_t i = 0; i < slots; ++i) {
            bool expected = false;
            if (!claimed_[i].compare_exchange_strong(expected, true, std::memory_order_acquire)) continue;
            std::memcpy(paths_[i], text.c_str(), text.size() + 1);
            published_[i].store(true, std::memory_order_release);
            return i;
        }
        return slots;
    }

    /// Forgets slot `i` (after the rename, or after the file was removed).
    void release(std::size_t i) noexcept {
        if (i >= slots) return;
        published_[i].store(false, std::memory_order_release);
        claimed_[i].store(false, std::memory_order_release);
    }

    /// Unlinks every published path. Async-signal-safe: lock-free atomics, reads and unlink only.
    void remove_all() noexcept {
        for (std::size_t i = 0; i < slots; ++i)
            if (published_[i].exchange(false, std::memory_order_acq_rel)) ::unlink(paths_[i]);
    }

private:
    std::atomic<bool> claimed_[slots]{};
    std::atomic<bool> published_[slots]{};
    char paths_[slots][path_bytes]{};
};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs lock-free flags");

/// Constant-initialised (zeros, in .bss), so a handler that runs before any write finds it ready: a function's
/// static would be made on first use, behind a lock no signal handler may take.
constinit PendingTemporaries pending_temporaries_of_the_process;

PendingTemporaries& pending_temporaries() { return pending_temporaries_of_the_process; }

/// Holds a PendingTemporaries slot until done() or scope exit.
class PendingSlot {
public:
    explicit PendingSlot(const std::filesystem::path& path) : slot_(pending_temporaries().add(path)) {}
    PendingSlot(const PendingSlot&) = delete;
    PendingSlot& operator=(const PendingSlot&) = delete;
    ~PendingSlot() { done(); }
    /// The file is renamed or removed: nothing is left for a handler to remove.
    void done() noexcept {
        pending_temporaries().release(slot_);
        slot_ = PendingTemporaries::slots;
    }

private:
    std::size_t slot_;
};

/// A name for the temporary file that no other writer (thread or process) picks at the same time.
/// Hidden (leading dot) so directory listings and globs don't catch a half-written file.
std::filesystem::path temporary_name(const std::filesystem::path& target, unsigned attempt) {
    static std::atomic<unsigned> counter{0};
    const auto ticks = static_cast<unsigned long long>(std::chrono::steady_clock::now().time_since_epoch().count());
    // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on the chain of operator+ this was.
    std::string name(1, '.');
    // At most 100 bytes of the target's name (cut at a UTF-8 character's start), so that a legal name near the
    // file system's 255-byte limit still leaves room for the suffix.
    std::string stem = target.filename().string();
    if (stem.size() > 100) {
        std::size_t cut = 100;
        while (cut > 0 && (static_cast<unsigned char>(stem[cut]) & 0xC0) == 0x80) --cut;
        stem.resize(cut);
    }
    for (const std::string& part : {stem, std::string(".tmp-"), std::to_string(::getpid()),
                                    std::string(1, '-'), std::to_string(counter.fetch_add(1)), std::string(1, '-'),
                                    std::to_string(ticks % 1000000007ULL), std::string(1, '-'), std::to_string(attempt)})
        name += part;
    return target.parent_path() / name;
}

}  // namespace

Result<std::string> read_text_file(const std::filesystem::path& path) {
    const std::string name = path.string();
    const int fd = open_retrying(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return Error("cannot open for reading: " + describe(errno), name);
    FileDescriptor file(fd);

    // A directory opens fine on Linux and fails only at read(); say so plainly instead.
    struct stat info {};
    if (::fstat(file.get(), &info) == 0 && S_ISDIR(info.st_mode)) return Error("is a directory, not a file", name);

    // A regular file is read straight into a string of its size: growing a string chunk by chunk would copy
    // a large file several times over.
    std::string content;
    if (S_ISREG(info.st_mode) && info.st_size > 0)
        detail::resize_on_huge_pages(content, static_cast<std::size_t>(info.st_size));
    std::size_t filled = 0;
    while (filled < content.size()) {
        const ssize_t count = read_some(file.get(), content.data() + filled, content.size() - filled);
        if (count < 0) return Error("cannot read: " + describe(errno), name);
        if (count == 0) break;  // the file shrank meanwhile
        filled += static_cast<std::size_t>(count);
    }
    content.resize(filled);
    // Then on to the end: the file may have grown, and pipes and /proc files report no size.
    char chunk[65536];
    for (;;) {
        const ssize_t count = read_some(file.get(), chunk, sizeof chunk);
        if (count < 0) return Error("cannot read: " + describe(errno), name);
        if (count == 0) break;
        content.append(chunk, static_cast<std::size_t>(count));
    }
    return content;
}

namespace {

/// Replaces the regular file at `path` (or creates it) through a temporary file and rename; errors name `name`.
Status replace_file(const std::filesystem::path& path, std::string_view content, const std::string& name) {
    // A directory cannot be replaced by a file; rename() would say so as EISDIR, or as EBUSY for "." and "..".
    if (struct stat target {}; ::stat(path.c_str(), &target) == 0 && S_ISDIR(target.st_mode))
        return Error("is a directory, not a file: give the output a file name", name);
    // Stage 1: create a fresh temporary file next to the target. Same directory means same file system,
    // which rename() needs to be atomic. O_EXCL guarantees we never write into someone else's file.
    // Each name is registered for a signal handler to remove (remove_pending_temporary_files) before the file
    // exists, so that no moment has the file on disk and unknown to the handler; a name that was taken (EEXIST:
    // it holds this process's id, so hardly ever) is released before the next is tried.
    std::filesystem::path temporary;
    std::optional<PendingSlot> pending;
    int fd = -1;
    for (unsigned attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        temporary = temporary_name(path, attempt);
        pending.emplace(temporary);
        fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0) pending.reset();
        if (fd < 0 && errno != EEXIST && errno != EINTR) break;
    }
    if (fd < 0) return Error("cannot create a temporary file next to it: " + describe(errno), name);
    FileDescriptor file(fd);
    auto fail = [&](std::string what, int code) -> Status {
        ::unlink(temporary.c_str());
        return Error(std::move(what) + ": " + describe(code), name);
    };

    // Stage 2: keep an existing file's permissions (e.g. a group-writable output), then write and flush.
    struct stat existing {};
    if (::stat(path.c_str(), &existing) == 0 && S_ISREG(existing.st_mode))
        ::fchmod(file.get(), existing.st_mode & 07777);
    if (const int code = write_all(file.get(), content); code != 0) return fail("cannot write", code);
    if (::fsync(file.get()) != 0) return fail("cannot flush to disk", errno);
    if (const int code = file.close_checked(); code != 0) return fail("cannot write", code);

    // Stage 3: publish. rename() replaces the target in one step; after it the content is in place.
    if (::rename(temporary.c_str(), path.c_str()) != 0) return fail("cannot replace the file", errno);
    pending->done();

    // Make the rename itself durable. Best effort: the file is already complete and in place, and some
    // file systems refuse fsync on directories, so a failure here is not an error.
    const std::filesystem::path directory = path.parent_path().empty() ? "." : path.parent_path();
    const int directory_fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (directory_fd >= 0) {
        ::fsync(directory_fd);
        ::close(directory_fd);
    }
    return Ok{};
}

}  // namespace

void remove_pending_temporary_files() noexcept { pending_temporaries().remove_all(); }

Status write_file_atomic(const std::filesystem::path& path, std::string_view content) {
    const std::string name = path.string();
    if (path.empty() || !path.has_filename()) return Error("not a file name", name);

    struct stat target {};
    if (::stat(path.c_str(), &target) == 0) {  // symbolic links followed
        // The process's own standard output or error (/dev/stdout, /dev/fd/1, or the file the shell redirected
        // it to): written through that descriptor, with the offset and flags the shell gave it (`>>` appends).
        // Replacing the file would leave the shell's descriptor on the old one; replacing /dev/stdout, as root,
        // would replace the device link itself.
        for (const int descriptor : {STDOUT_FILENO, STDERR_FILENO}) {
            struct stat open_file {};
            if (::fstat(descriptor, &open_file) == 0 && open_file.st_dev == target.st_dev &&
                open_file.st_ino == target.st_ino) {
                if (const int code = write_all(descriptor, content); code != 0)
                    return Error("cannot write: " + describe(code), name);
                return Ok{};
            }
        }
        // A stream rather than a file (a terminal, pipe, fifo, socket or device such as /dev/null): there is
        // nothing to replace atomically, and renaming over it would put a regular file where it was.
        if (!S_ISREG(target.st_mode) && !S_ISDIR(target.st_mode)) return write_into_stream(path, content);
        // A symbolic link to a file: the file it names is replaced and the link kept, as editors do.
        if (struct stat link {}; ::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
            if (S_ISDIR(target.st_mode)) return Error("is a symbolic link to a directory, not a file", name);
            std::error_code error;
            const std::filesystem::path resolved = std::filesystem::canonical(path, error);
            if (error) return Error("cannot follow the symbolic link: " + error.message(), name);
            return replace_file(resolved, content, name);
        }
    }
    // A dangling symbolic link: the file it names is created and the link kept, as a shell's `>` does; replacing
    // the link by a file would cut whatever the link was there for (a configuration's fixed path, say).
    if (struct stat link {}; ::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
        std::filesystem::path resolved = path;
        std::error_code error;
        for (int hops = 0; std::filesystem::is_symlink(resolved, error); ++hops) {
            if (hops == 40) return Error("cannot follow the symbolic link: too many levels of links", name);
            const std::filesystem::path next = std::filesystem::read_symlink(resolved, error);
            if (error) return Error("cannot follow the symbolic link: " + error.message(), name);
            resolved = next.is_absolute() ? next : resolved.parent_path() / next;
        }
        return replace_file(resolved, content, name);
    }
    return replace_file(path, content, name);
}

}  // namespace hbvh
