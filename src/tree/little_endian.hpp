// SPDX-License-Identifier: MIT
// Little-endian loads and stores of the .hbvh format's fields, for its reader, writer and checksum.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>

namespace hbvh::detail {

inline std::uint64_t load_u64_le(const unsigned char* p) {
    std::uint64_t value = 0;
    if constexpr (std::endian::native == std::endian::little) {
        std::memcpy(&value, p, sizeof value);  // one load; the byte loop below is its meaning
    } else {
        for (int i = 7; i >= 0; --i) value = (value << 8) | p[i];
    }
    return value;
}
inline std::uint32_t load_u32_le(const unsigned char* p) {
    return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
}
inline void store_u64_le(unsigned char* p, std::uint64_t value) {
    for (int i = 0; i < 8; ++i) p[i] = static_cast<unsigned char>(value >> (8 * i));
}
inline void store_u32_le(unsigned char* p, std::uint32_t value) {
    for (int i = 0; i < 4; ++i) p[i] = static_cast<unsigned char>(value >> (8 * i));
}

}  // namespace hbvh::detail
