// SPDX-License-Identifier: MIT
// Internal: how build reports print numbers, so that auto's portfolio line and the treelet note agree.
#pragma once

#include <cstdio>
#include <string>

namespace hbvh::detail {

/// An Eq. 2 cost in a report note: six significant digits.
inline std::string format_cost(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", value);
    return text;
}

}  // namespace hbvh::detail
