// SPDX-License-Identifier: MIT
// The .hbvh format on files: a large file mapped rather than read, and the atomic write (temporary file, fsync,
// rename) of the core library, which cannot use hbvh::io's write_file_atomic.
#include "hbvh/tree/binary_format.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <system_error>

#include "../memory/huge_pages.hpp"
#include "binary_decoding.hpp"

namespace hbvh {
namespace {

std::string describe_errno(int code) { return std::generic_category().message(code); }

/// Files from this size on are mapped rather than read (below it, one read() is as fast and needs no mapping).
constexpr std::uint64_t mapped_read_bytes = std::uint64_t{1} << 20;

}  // namespace

namespace detail {

Status with_file_bytes(const std::filesystem::path& path, const std::function<void(std::span<const std::byte>)>& use) {
    const std::string name = path.string();
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return Error{"cannot open for reading: " + describe_errno(errno), name};
    struct stat info {};
    // An uninitialised buffer (a vector would zero it first, one more pass over a large file), sized from
    // st_size and advised into huge pages like the Bvh; st_size is only a hint (a pipe has none, a file can
    // grow), so the loop reads to the end whatever it says and grows the buffer when it must.
    std::unique_ptr<std::byte[]> bytes;
    std::size_t capacity = 0, filled = 0;
    int failure = 0;
    if (::fstat(fd, &info) != 0) failure = errno;
    else if (S_ISDIR(info.st_mode)) failure = EISDIR;
    else if (S_ISREG(info.st_mode) && static_cast<std::uint64_t>(info.st_size) >= mapped_read_bytes) {
        // A large regular file is mapped instead: its pages are the page cache's own, so there is no buffer to
        // clear and fill (at 10^6 primitives, 153 MB: about a quarter of the whole load). MAP_POPULATE maps them
        // all at once rather than one fault per page. A file of the wrong kind or size is refused as before.
        const auto length = static_cast<std::size_t>(info.st_size);
        void* mapped = ::mmap(nullptr, length, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
        if (mapped != MAP_FAILED) {
            ::close(fd);
            use(std::span<const std::byte>(static_cast<const std::byte*>(mapped), length));
            ::munmap(mapped, length);
            return Ok{};
        }
        // Where mapping is refused (some file systems), read it.
    }
    if (failure == 0 && !S_ISDIR(info.st_mode)) {
        capacity = S_ISREG(info.st_mode) && info.st_size > 0 ? static_cast<std::size_t>(info.st_size) : 65536;
        bytes.reset(new std::byte[capacity]);
        detail::advise_huge_pages(bytes.get(), capacity);
        for (;;) {
            if (filled == capacity) {
                // Full: look for more in a small buffer before doubling, so that a file of exactly st_size bytes
                // (the usual case) is not copied into twice the memory just to find its end.
                std::byte probe[4096];
                ssize_t got = ::read(fd, probe, sizeof probe);
                if (got < 0 && errno == EINTR) continue;
                if (got < 0) {
                    failure = errno;
                    break;
                }
                if (got == 0) break;
                capacity = std::max(2 * capacity, filled + sizeof probe + 65536);
                std::unique_ptr<std::byte[]> larger(new std::byte[capacity]);
                std::memcpy(larger.get(), bytes.get(), filled);
                std::memcpy(larger.get() + filled, probe, static_cast<std::size_t>(got));
                bytes = std::move(larger);
                filled += static_cast<std::size_t>(got);
                continue;
            }
            const ssize_t got = ::read(fd, bytes.get() + filled, capacity - filled);
            if (got < 0 && errno == EINTR) continue;
            if (got < 0) {
                failure = errno;
                break;
            }
            if (got == 0) break;
            filled += static_cast<std::size_t>(got);
        }
    }
    ::close(fd);
    if (failure != 0) return Error{"cannot read: " + describe_errno(failure), name};
    use(std::span<const std::byte>(bytes.get(), filled));
    return Ok{};
}

}  // namespace detail

Result<Bvh> read_binary_file(const std::filesystem::path& path) {
    std::optional<Result<Bvh>> bvh;
    const Status read = detail::with_file_bytes(path, [&](std::span<const std::byte> bytes) { bvh = read_binary(bytes, path.string()); });
    if (!read) return read.error();
    return std::move(*bvh);
}

Status write_binary_file(const std::filesystem::path& path, const Bvh& bvh) {
    const std::string name = path.string();
    if (path.empty() || !path.has_filename()) return Error{"not a file name", name};
    const std::string content = write_binary(bvh);
    // A hidden temporary next to the target (same file system, so rename() is atomic); O_EXCL never
    // opens someone else's file. The io library's write_file_atomic does the same; core cannot use it.
    static std::atomic<unsigned> counter{0};
    std::filesystem::path temporary;
    int fd = -1;
    for (unsigned attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        std::string hidden(1, '.');
        hidden += path.filename().string();
        hidden += ".tmp-";
        hidden += std::to_string(::getpid());
        hidden += '-';
        hidden += std::to_string(counter.fetch_add(1));
        temporary = path.parent_path() / hidden;
        fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST && errno != EINTR) break;
    }
    if (fd < 0) return Error{"cannot create a temporary file next to it: " + describe_errno(errno), name};
    auto fail = [&](const std::string& what, int code) -> Status {
        ::close(fd);
        ::unlink(temporary.c_str());
        return Error{what + ": " + describe_errno(code), name};
    };
    // An existing file keeps its permission bits.
    struct stat existing {};
    if (::stat(path.c_str(), &existing) == 0 && S_ISREG(existing.st_mode) && ::fchmod(fd, existing.st_mode & 07777) != 0)
        return fail("cannot set permissions", errno);
    for (std::string_view rest = content; !rest.empty();) {
        const ssize_t written = ::write(fd, rest.data(), rest.size());
        if (written < 0 && errno == EINTR) continue;
        if (written < 0) return fail("cannot write", errno);
        rest.remove_prefix(static_cast<std::size_t>(written));
    }
    if (::fsync(fd) != 0) return fail("cannot flush to disk", errno);
    if (::close(fd) != 0) {
        const int code = errno;
        ::unlink(temporary.c_str());
        return Error{"cannot write: " + describe_errno(code), name};
    }
    if (::rename(temporary.c_str(), path.c_str()) != 0) {
        const int code = errno;
        ::unlink(temporary.c_str());
        return Error{"cannot rename the temporary file over it: " + describe_errno(code), name};
    }
    return Ok{};
}

}  // namespace hbvh
