// SPDX-License-Identifier: MIT
// The .hbvh reader with the nodes handed to a sink: shared by read_binary (into a Bvh) and QueryTree::read_binary
// (straight into the query layout, with no Bvh in between). Not installed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh::detail {

/// Receives a file's node records in order as they are decoded, before the structure is known to be sound:
/// an implementation must check every index it takes from a node before using it.
class BinaryNodeSink {
public:
    virtual ~BinaryNodeSink() = default;
    /// Once, before the first add(): the counts of the header, already known to fit in the file's size.
    virtual void reserve(std::uint64_t node_count, std::uint64_t primitive_count) = 0;
    virtual void add(const Node& node) = 0;
};

/// What decode_binary found, when it found no Error.
struct DecodedBinary {
    std::uint64_t node_count = 0;
    std::uint64_t primitive_count = 0;
    /// Every check made on the fly passed. When false, check_structure() (or validate_primitives() for a
    /// primitive set) decides, and names the problem.
    bool sound = true;
    std::size_t primitives_at = 0;  ///< Offset of the first primitive record.
};

/// read_binary's decoding: the header, the checksum, the counts and every record, bounds-checked, with the
/// nodes handed to each of `node_sinks` (one decoding pass each, so that sinks filling different arrays work
/// at once) and the primitives appended to `primitives` (or, when it is null, checked and dropped). The Error
/// is the one read_binary reports for the same bytes.
[[nodiscard]] Result<DecodedBinary> decode_binary(std::span<const std::byte> bytes, const std::string& file,
                                                  std::span<BinaryNodeSink* const> node_sinks,
                                                  std::vector<Primitive>* primitives);

/// The bytes of the file at `path` handed to `use` while they are valid: a large regular file mapped, anything
/// else read to its end into one buffer on huge pages. Failing to open or read gives an Error naming the file.
[[nodiscard]] Status with_file_bytes(const std::filesystem::path& path,
                                     const std::function<void(std::span<const std::byte>)>& use);

}  // namespace hbvh::detail
