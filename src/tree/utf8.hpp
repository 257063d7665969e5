// SPDX-License-Identifier: MIT
// Internal: names as UTF-8, which both file formats promise (the XML declaration, the binary reader's check).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace hbvh::detail {

/// Empty when `text` is well-formed UTF-8 (no overlong forms, no surrogates, nothing above U+10FFFF) without
/// NUL; else the problem and, in `bad_at`, the offset of the offending character's first byte within `text`.
[[nodiscard]] std::string utf8_problem(std::string_view text, std::size_t& bad_at);

/// `name` as the writers store it: up to its first NUL (a C string's end, where pugixml has always cut it), each
/// byte that starts no well-formed character replaced by U+FFFD, as the JSON, glTF and HTML outputs do. A name
/// from a Latin-1 asset was written as it was, and the file it went into could not be read back.
[[nodiscard]] std::string utf8_name(std::string_view name);

}  // namespace hbvh::detail
