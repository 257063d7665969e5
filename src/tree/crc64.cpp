// SPDX-License-Identifier: MIT
// crc64_xz, the .hbvh format's checksum: CRC-64/XZ by tables everywhere and by carry-less multiplication where
// the CPU has it (docs/formats.md, "Checksum").
#include "hbvh/tree/binary_format.hpp"

#include <array>
#include <cstdint>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "little_endian.hpp"

namespace hbvh {
namespace {

using detail::load_u64_le;

// CRC-64/XZ by slicing-by-8 (Kounavis & Berry's table method): eight tables let the loop fold 8 input bytes
// per step instead of one. It runs where the carry-less multiply below does not, and for the short ends.
constexpr std::uint64_t crc64_polynomial = 0x42F0E1EBA9EA3693ULL;
constexpr std::uint64_t crc64_reflected_polynomial = 0xC96C5795D7870F42ULL;  // the same, bit-reversed

using Crc64Tables = std::array<std::array<std::uint64_t, 256>, 8>;
constexpr Crc64Tables make_crc64_tables() {
    Crc64Tables tables{};
    for (std::uint64_t i = 0; i < 256; ++i) {
        std::uint64_t crc = i;
        for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) != 0 ? (crc >> 1) ^ crc64_reflected_polynomial : crc >> 1;
        tables[0][i] = crc;
    }
    // tables[k][i]: the CRC of byte i followed by k zero bytes.
    for (std::size_t k = 1; k < 8; ++k)
        for (std::size_t i = 0; i < 256; ++i)
            tables[k][i] = (tables[k - 1][i] >> 8) ^ tables[0][tables[k - 1][i] & 0xFF];
    return tables;
}
constexpr Crc64Tables crc64_tables = make_crc64_tables();

/// The CRC register after `n` more bytes at `p`, by the tables (no initial value or final xor applied).
std::uint64_t crc64_update_by_table(std::uint64_t crc, const unsigned char* p, std::size_t n) {
    const Crc64Tables& t = crc64_tables;
    for (; n >= 8; n -= 8, p += 8) {
        crc ^= load_u64_le(p);
        crc = t[7][crc & 0xFF] ^ t[6][(crc >> 8) & 0xFF] ^ t[5][(crc >> 16) & 0xFF] ^ t[4][(crc >> 24) & 0xFF] ^
              t[3][(crc >> 32) & 0xFF] ^ t[2][(crc >> 40) & 0xFF] ^ t[1][(crc >> 48) & 0xFF] ^ t[0][crc >> 56];
    }
    for (; n > 0; --n, ++p) crc = (crc >> 8) ^ t[0][(crc ^ *p) & 0xFF];
    return crc;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define HBVH_CRC64_CLMUL 1
// CRC-64/XZ by carry-less multiplication (Gopal et al., "Fast CRC computation for generic polynomials using
// PCLMULQDQ", Intel 2009): four 16-byte accumulators are folded 64 bytes forward per step, each by two
// 64 x 64-bit carry-less products with x^k mod P, which keeps the checksum near memory speed (a 150 MB file
// in about 11 ms instead of 78 ms by the tables). The folded 16 bytes and the tail go through the tables,
// which replaces the Barrett reduction. Bit-reflected throughout: bit 0 of a little-endian word is the
// highest power of x, and the 127-bit product of two reflected words is one power of x short, hence the
// exponent - 1 below. Checked against the tables for every length up to thousands of bytes (the unit test).

constexpr std::uint64_t reflect_bits(std::uint64_t value) {
    std::uint64_t reflected = 0;
    for (int i = 0; i < 64; ++i)
        if ((value >> i & 1) != 0) reflected |= std::uint64_t{1} << (63 - i);
    return reflected;
}
/// x^(exponent - 1) mod P, bit-reflected: multiplying a reflected word by it moves that word `exponent`
/// bits (exponent / 8 bytes) further along the message.
constexpr std::uint64_t crc64_fold_constant(unsigned exponent) {
    std::uint64_t remainder = 1;
    for (unsigned i = 0; i + 1 < exponent; ++i) remainder = (remainder << 1) ^ ((remainder >> 63) != 0 ? crc64_polynomial : 0);
    return reflect_bits(remainder);
}

// Folding by 64 bytes (4 accumulators) and by 16 (one): [0] for an accumulator's first 8 bytes, [1] for the next 8.
constexpr std::array<std::uint64_t, 2> crc64_fold_by_64{crc64_fold_constant(512 + 64), crc64_fold_constant(512)};
constexpr std::array<std::uint64_t, 2> crc64_fold_by_16{crc64_fold_constant(128 + 64), crc64_fold_constant(128)};

__attribute__((target("pclmul"))) inline __m128i crc64_fold(__m128i x, __m128i constants) {
    return _mm_xor_si128(_mm_clmulepi64_si128(x, constants, 0x00), _mm_clmulepi64_si128(x, constants, 0x11));
}

/// The CRC register after `n` >= 64 bytes at `p`, starting from `crc`.
__attribute__((target("pclmul"))) std::uint64_t crc64_update_by_clmul(std::uint64_t crc, const unsigned char* p,
                                                                         std::size_t n) {
    auto constants = [](const std::array<std::uint64_t, 2>& c) {
        return _mm_set_epi64x(static_cast<long long>(c[1]), static_cast<long long>(c[0]));
    };
    const __m128i by_64_bytes = constants(crc64_fold_by_64), by_16_bytes = constants(crc64_fold_by_16);
    auto load = [](const unsigned char* at) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(at)); };
    // The register is xored into the first 8 bytes, as the tables' loop does.
    __m128i x0 = _mm_xor_si128(load(p), _mm_set_epi64x(0, static_cast<long long>(crc)));
    __m128i x1 = load(p + 16), x2 = load(p + 32), x3 = load(p + 48);
    p += 64;
    n -= 64;
    for (; n >= 64; n -= 64, p += 64) {
        x0 = _mm_xor_si128(crc64_fold(x0, by_64_bytes), load(p));
        x1 = _mm_xor_si128(crc64_fold(x1, by_64_bytes), load(p + 16));
        x2 = _mm_xor_si128(crc64_fold(x2, by_64_bytes), load(p + 32));
        x3 = _mm_xor_si128(crc64_fold(x3, by_64_bytes), load(p + 48));
    }
    x1 = _mm_xor_si128(x1, crc64_fold(x0, by_16_bytes));
    x2 = _mm_xor_si128(x2, crc64_fold(x1, by_16_bytes));
    x3 = _mm_xor_si128(x3, crc64_fold(x2, by_16_bytes));
    for (; n >= 16; n -= 16, p += 16) x3 = _mm_xor_si128(crc64_fold(x3, by_16_bytes), load(p));
    unsigned char folded[16];
    _mm_storeu_si128(reinterpret_cast<__m128i*>(folded), x3);
    return crc64_update_by_table(crc64_update_by_table(0, folded, sizeof folded), p, n);
}
#endif

}  // namespace

std::uint64_t crc64_xz(std::span<const std::byte> bytes) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
    const std::uint64_t initial = ~std::uint64_t{0};
#ifdef HBVH_CRC64_CLMUL
    // Below a few hundred bytes the tables are as fast; the CPU check reads a flag the runtime set at start-up.
    if (bytes.size() >= 256 && __builtin_cpu_supports("pclmul")) return ~crc64_update_by_clmul(initial, p, bytes.size());
#endif
    return ~crc64_update_by_table(initial, p, bytes.size());
}

}  // namespace hbvh
