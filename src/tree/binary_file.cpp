// SPDX-License-Identifier: MIT
// The .hbvh format on files: a large file mapped rather than read (a smaller one read by read_text_file), written
// by write_file_atomic (hbvh/files.hpp).
#include "hbvh/tree/binary_format.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <optional>
#include <string>

#include "binary_decoding.hpp"
#include "hbvh/files.hpp"

namespace hbvh {
namespace {

/// Files from this size on are mapped rather than read (below it, one read() is as fast and needs no mapping).
constexpr std::uint64_t mapped_read_bytes = std::uint64_t{1} << 20;

}  // namespace

namespace detail {

Status with_file_bytes(const std::filesystem::path& path, const std::function<void(std::span<const std::byte>)>& use) {
    // The path is looked at (stat) before it is opened, and only a large regular file is opened here: opening a
    // pipe and closing it again to read it through read_text_file would leave its writer, for that moment,
    // without a reader, and kill it with SIGPIPE.
    struct stat info {};
    if (::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode) &&
        static_cast<std::uint64_t>(info.st_size) >= mapped_read_bytes) {
        const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        // fstat again: the file may have been replaced since.
        if (fd >= 0 && ::fstat(fd, &info) == 0 && S_ISREG(info.st_mode) &&
            static_cast<std::uint64_t>(info.st_size) >= mapped_read_bytes) {
            // A large regular file is mapped: its pages are the page cache's own, so there is no buffer to clear
            // and fill (at 10^6 primitives, 153 MB: about a quarter of the whole load). MAP_POPULATE maps them
            // all at once rather than one fault per page.
            const auto length = static_cast<std::size_t>(info.st_size);
            void* mapped = ::mmap(nullptr, length, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
            if (mapped != MAP_FAILED) {
                ::close(fd);
                use(std::span<const std::byte>(static_cast<const std::byte*>(mapped), length));
                ::munmap(mapped, length);
                return Ok{};
            }
        }
        if (fd >= 0) ::close(fd);
    }
    // Anything else (a small file, a pipe, a file system that refuses the mapping, or a path that does not
    // open, whose error read_text_file words) is read whole.
    const Result<std::string> bytes = read_text_file(path);
    if (!bytes) return bytes.error();
    use(std::as_bytes(std::span<const char>(bytes->data(), bytes->size())));
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
    return write_file_atomic(path, write_binary(bvh));
}

}  // namespace hbvh
