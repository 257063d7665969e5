// SPDX-License-Identifier: MIT
// libFuzzer harness for the .hbvh binary readers: any bytes must give a hierarchy or an Error, never a crash
// or a huge allocation; whatever is accepted is a sound tree and is exactly what the bytes say. The reader
// into the query layout (QueryTree::read_binary) must accept and refuse the same bytes as read_binary.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string_view>
#include <vector>

#include "hbvh/geometry/validation.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/tree/binary_format.hpp"
#include "hbvh/tree/validate.hpp"

namespace {
/// QueryTree::read_binary on the same bytes: refused with read_binary's words, or (for a tree) the same nodes.
void check_query_tree_reader(std::span<const std::byte> bytes, const hbvh::Result<hbvh::Bvh>& bvh) {
    const hbvh::Result<hbvh::QueryTree> tree = hbvh::QueryTree::read_binary(bytes, "fuzz");
    if (!bvh) {
        if (tree || tree.error().message != bvh.error().message) std::abort();
        return;
    }
    if (bvh->nodes.empty() != !tree) std::abort();  // a primitive set is refused, a tree accepted
    if (tree && tree->nodes().size() != bvh->nodes.size()) std::abort();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
    hbvh::Result<hbvh::Bvh> bvh = hbvh::read_binary(bytes, "fuzz");
    check_query_tree_reader(bytes, bvh);
    // Random bytes rarely pass the checksum; the harness also tries them resealed (the last 8 bytes replaced
    // by the CRC-64 of the rest), so that mutations reach the counts, the records and check_structure.
    if (!bvh && size >= 8) {
        std::vector<std::byte> resealed(bytes.begin(), bytes.end());
        std::uint64_t crc = hbvh::crc64_xz(bytes.first(size - 8));
        for (std::size_t i = 0; i < 8; ++i) resealed[size - 8 + i] = static_cast<std::byte>(crc >> (8 * i));
        bvh = hbvh::read_binary(resealed, "fuzz-resealed");
        check_query_tree_reader(resealed, bvh);
        if (bvh && (bvh->nodes.empty() ? !hbvh::validate_primitives(bvh->primitives) : !hbvh::check_structure(bvh.value())))
            std::abort();
        if (bvh && hbvh::write_binary(bvh.value()) !=
                       std::string_view(reinterpret_cast<const char*>(resealed.data()), resealed.size()))
            std::abort();
        return 0;
    }
    if (!bvh) return 0;
    // Accepted means a tree the queries can use (or usable primitives: the reader decides on the fly and runs
    // these full checks only when something looks wrong, so they must agree), and the encoding is canonical:
    // writing it gives the input back.
    if (!bvh->nodes.empty() && !hbvh::check_structure(bvh.value())) std::abort();
    if (bvh->nodes.empty() && !hbvh::validate_primitives(bvh->primitives)) std::abort();
    if (hbvh::write_binary(bvh.value()) != std::string_view(reinterpret_cast<const char*>(data), size)) std::abort();
    return 0;
}
