// SPDX-License-Identifier: MIT
// Shared by the importer harnesses: the importers read paths (MJCF resolves <include> against the file's folder,
// assimp picks its reader by extension), so each input is written to a fixed name in a private directory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <unistd.h>

namespace hbvh::fuzz {

/// A per-process directory under $TMPDIR (or /tmp), removed at normal exit (libFuzzer exits normally at the
/// end of -max_total_time; a crash leaves it behind on purpose, next to the reproducer).
inline const std::filesystem::path& scratch_directory() {
    static const std::filesystem::path directory = [] {
        const char* base = std::getenv("TMPDIR");
        std::string pattern = std::string(base != nullptr && *base != '\0' ? base : "/tmp") + "/hbvh-fuzz-XXXXXX";
        if (::mkdtemp(pattern.data()) == nullptr) std::abort();
        std::atexit([] {
            std::error_code ignored;
            std::filesystem::remove_all(scratch_directory(), ignored);
        });
        return std::filesystem::path(pattern);
    }();
    return directory;
}

/// Replaces `name` in the scratch directory with the bytes `data[0, size)` and returns its path.
inline std::string write_scratch_file(const std::string& name, const std::uint8_t* data, std::size_t size) {
    const std::string path = (scratch_directory() / name).string();
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (file == nullptr) std::abort();
    const bool complete = size == 0 || std::fwrite(data, 1, size, file) == size;
    if (std::fclose(file) != 0 || !complete) std::abort();
    return path;
}

}  // namespace hbvh::fuzz
