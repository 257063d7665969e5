// SPDX-License-Identifier: MIT
// JSON text for standard output.
#pragma once

#include <string>

namespace hbvh::cli {

/// `value` as JSON text (`indent` -1: one line). Names come from files and may hold bytes that are no UTF-8 (a
/// Latin-1 file name, a primitive named in an old asset): each such byte is written as U+FFFD, as the glTF and
/// HTML exports do, where a plain dump() throws and the command ended in std::terminate.
template <class Json>
[[nodiscard]] std::string json_text(const Json& value, int indent = -1) {
    return value.dump(indent, ' ', false, Json::error_handler_t::replace);
}

}  // namespace hbvh::cli
