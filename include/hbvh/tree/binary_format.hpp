// SPDX-License-Identifier: MIT
// The .hbvh binary format: a Bvh (or a primitive set) as versioned little-endian bytes, for fast loading at start-up.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// The 8 bytes every .hbvh file starts with: 0x89 'H' 'B' 'V' 'H' '\r' '\n' 0x1A (like PNG's, the non-ASCII
/// first byte and the line ending catch a text-mode transfer).
inline constexpr std::array<unsigned char, 8> binary_magic{0x89, 'H', 'B', 'V', 'H', '\r', '\n', 0x1A};
/// The format version this build writes, and the only one it reads (docs/formats.md, "Version policy").
inline constexpr std::uint32_t binary_format_version = 1;

/// CRC-64/XZ (ECMA-182 polynomial 0x42F0E1EBA9EA3693, reflected, initial value and final xor all ones) of
/// `bytes`: the checksum in the last 8 bytes of a .hbvh file. Its check value, of "123456789", is
/// 0x995DC9BBDF1939FA. Computed by carry-less multiplication where the CPU has it (x86-64 with PCLMULQDQ, checked
/// at run time), else by slicing-by-8 tables; both give the same value.
[[nodiscard]] std::uint64_t crc64_xz(std::span<const std::byte> bytes);

/// `bvh` as a .hbvh file (docs/formats.md has the layout): every field written little-endian one by one,
/// doubles as their IEEE-754 bit patterns, so the bytes are the same on every platform. A Bvh without nodes
/// and with primitives is a primitive set and is written as one (node count 0). Nothing is checked: an
/// empty Bvh, NaN or a malformed tree are written as they are, and read_binary refuses them.
/// The encoding is canonical: read_binary of the result, written again, gives the same bytes.
[[nodiscard]] std::string write_binary(const Bvh& bvh);

/// Parses a .hbvh file. `source_name` goes into every Error's `file`; the message starts with the byte
/// offset of the problem ("offset 40: ..."), line is 0. Every read is bounds-checked and every count is
/// compared with the bytes left before anything is allocated. Refused: a wrong magic, another version,
/// non-zero reserved bits, a truncated file or bytes after its end, a checksum mismatch, counts the file
/// cannot hold, an unknown volume kind, a name that is not UTF-8 (or holds a NUL), no primitives, and then,
/// through check_structure() (nodes) or validate_primitives() (a primitive set), a malformed tree or
/// unusable geometry (NaN, negative sizes, a matrix that is no rotation). Those checks are made on the fly
/// while decoding; the full functions run (for their messages) only when something fails. A primitive set
/// comes back as a Bvh with no nodes. Containment is not checked: run validate() for that, as for XML.
[[nodiscard]] Result<Bvh> read_binary(std::span<const std::byte> bytes, std::string_view source_name);

/// Reads the file at `path` (a regular file of 1 MiB or more mapped; anything else read into one buffer sized from
/// the file, in huge pages where Linux offers them, pipes and growing files to their end) and parses it with
/// read_binary; errors name the file as given. To query the tree, QueryTree::read_binary_file loads it straight
/// into the query layout instead.
[[nodiscard]] Result<Bvh> read_binary_file(const std::filesystem::path& path);

/// Writes write_binary(bvh) to `path` atomically: a new temporary file in the same directory, fsync, then
/// rename over `path`, so readers see the old file or the whole new one. On failure the temporary file is
/// removed and `path` is untouched. POSIX only.
[[nodiscard]] Status write_binary_file(const std::filesystem::path& path, const Bvh& bvh);

/// True when `bytes` starts with binary_magic (how a reader tells a .hbvh file from XML without its name).
[[nodiscard]] bool has_binary_magic(std::span<const std::byte> bytes);

}  // namespace hbvh
