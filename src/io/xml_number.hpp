// SPDX-License-Identifier: MIT
// Shortest round-trip decimal text of a double, for the XML writer and the reader's messages.
#pragma once

#include <array>
#include <charconv>
#include <system_error>

namespace hbvh::detail {

/// Shortest decimal text that reads back as exactly `value` (std::to_chars' round-trip guarantee).
template <class Out>
void append_number(Out& out, double value) {
    std::array<char, 32> digits{};
    const auto [end, ec] = std::to_chars(digits.data(), digits.data() + digits.size(), value);
    out.append(digits.data(), ec == std::errc{} ? end : digits.data());
}

}  // namespace hbvh::detail
