// SPDX-License-Identifier: MIT
// Internal: the check every PLY file passes before assimp reads it (assimp 5.2's PLY reader hangs or reads out
// of bounds on malformed headers, and trusts the header's element counts).
#pragma once

#include <string>

#include "hbvh/result.hpp"

namespace hbvh::detail {

/// Ok for a file assimp would not take as PLY, and for a PLY file whose header follows the PLY 1.0 grammar
/// (magic line, format line, then element, property, comment and obj_info lines, then end_header alone on
/// its line) and whose declared elements fit in the bytes that follow it. Otherwise an Error naming the file,
/// the header line and the problem.
[[nodiscard]] Status check_ply_header(const std::string& path);

}  // namespace hbvh::detail
