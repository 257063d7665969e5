// SPDX-License-Identifier: MIT
// UTF-8 checks for names: the binary reader's refusal and the writers' repair.
#include "utf8.hpp"

#include <charconv>
#include <cstdint>

namespace hbvh::detail {

std::string utf8_problem(std::string_view text, std::size_t& bad_at) {
    const auto* s = reinterpret_cast<const unsigned char*>(text.data());
    const std::size_t n = text.size();
    for (std::size_t i = 0; i < n;) {
        bad_at = i;
        const unsigned char c = s[i];
        if (c == 0) return "a name holds a NUL byte";
        if (c < 0x80) {
            ++i;
            continue;
        }
        std::size_t length = 0;
        std::uint32_t code = 0, smallest = 0;
        if ((c & 0xE0) == 0xC0) length = 2, code = c & 0x1F, smallest = 0x80;
        else if ((c & 0xF0) == 0xE0) length = 3, code = c & 0x0F, smallest = 0x800;
        else if ((c & 0xF8) == 0xF0) length = 4, code = c & 0x07, smallest = 0x10000;
        else return "a name is not UTF-8 (byte 0x" + [&] {
            char hex[3];
            std::to_chars(hex, hex + 2, c, 16);
            hex[2] = 0;
            return std::string(hex);
        }() + " cannot start a character)";
        if (length > n - i) return "a name is not UTF-8 (a character is cut off at its end)";
        for (std::size_t k = 1; k < length; ++k) {
            if ((s[i + k] & 0xC0) != 0x80) return "a name is not UTF-8 (a character's continuation byte is missing)";
            code = (code << 6) | (s[i + k] & 0x3F);
        }
        if (code < smallest) return "a name is not UTF-8 (overlong encoding)";
        if (code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF))
            return "a name is not UTF-8 (no Unicode character: surrogate or above U+10FFFF)";
        i += length;
    }
    return {};
}

std::string utf8_name(std::string_view name) {
    name = name.substr(0, name.find('\0'));
    std::string out;
    out.reserve(name.size());
    while (!name.empty()) {
        std::size_t bad_at = 0;
        if (utf8_problem(name, bad_at).empty()) {
            out += name;
            break;
        }
        out += name.substr(0, bad_at);
        out += "\xEF\xBF\xBD";  // U+FFFD REPLACEMENT CHARACTER
        name.remove_prefix(bad_at + 1);
    }
    return out;
}

}  // namespace hbvh::detail
