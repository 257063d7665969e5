// SPDX-License-Identifier: MIT
// Files as hbvh::io sees them: read_text_file and write_file_atomic (from the core library's hbvh/files.hpp,
// included here so that code including this header keeps compiling), and formats chosen by extension.
#pragma once

#include <filesystem>
#include <string>

#include "hbvh/files.hpp"

namespace hbvh {

/// The extension of `path` with its dot, in ASCII lower case (".ply" for "Mesh.PLY"); empty when it has none.
/// Formats are chosen by extension case-insensitively, as assimp chooses its readers.
[[nodiscard]] std::string lower_case_extension(const std::filesystem::path& path);

}  // namespace hbvh
