// SPDX-License-Identifier: MIT
// Bvh: the hierarchy in one contiguous array of nodes, children adjacent, indices instead of pointers.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hbvh/geometry/primitive.hpp"

namespace hbvh {

/// One node. Inner nodes own the range nodes[first_child, first_child + child_count);
/// a leaf (child_count == 0) stands for exactly one input primitive.
struct Node {
    BoundingVolume volume;
    std::uint32_t first_child = 0;
    std::uint32_t child_count = 0;  ///< 0 for a leaf; >= 2 for an inner node (no single-child chains).
    std::uint32_t primitive = 0;    ///< For a leaf: index into Bvh::primitives (input order).

    [[nodiscard]] bool is_leaf() const { return child_count == 0; }
};

/// A hierarchy over primitives. nodes[0] is the root; nodes are in breadth-first order, so the
/// children of every node are contiguous and every level is a contiguous run.
struct Bvh {
    std::vector<Node> nodes;
    std::vector<Primitive> primitives;  ///< The input, in input order.

    [[nodiscard]] bool empty() const { return nodes.empty(); }
    [[nodiscard]] const Node& root() const { return nodes.front(); }
    [[nodiscard]] std::span<const Node> children(const Node& node) const {
        return {nodes.data() + node.first_child, node.child_count};
    }
};

/// Nodes grouped by depth: levels[d] lists the indices of all nodes at depth d (root at 0).
[[nodiscard]] std::vector<std::vector<std::uint32_t>> levels(const Bvh& bvh);
/// The input primitives under node `index`, ascending. Empty for an index past the nodes; children past the
/// array (a malformed tree: check_structure says which) are skipped.
[[nodiscard]] std::vector<std::uint32_t> covered_primitives(const Bvh& bvh, std::uint32_t index);

/// Assembles a Bvh from groups made in any order, as bottom-up, top-down and incremental builders do.
/// Ids returned by add_leaf/add_group are the builder's own; finish() lays the tree out breadth-first
/// and collapses any single-child group into its child.
class TreeAssembler {
public:
    explicit TreeAssembler(std::span<const Primitive> primitives);

    /// Room for `items` leaves and groups, so that a large tree's items are written once (and on huge pages).
    void reserve(std::size_t items);

    /// The leaf for input primitive `primitive`; its BV is the primitive's own.
    std::uint32_t add_leaf(std::uint32_t primitive);
    /// A group over `children` (ids from earlier calls) with BV `volume`.
    std::uint32_t add_group(std::span<const std::uint32_t> children, BoundingVolume volume);
    /// Replace the BV of group `id` (e.g. after refitting).
    void set_volume(std::uint32_t id, BoundingVolume volume);
    /// The finished hierarchy rooted at `root`. When `id_of_node` is given it receives, for each node, the id
    /// whose volume that node carries (after single-child groups are collapsed into their child).
    [[nodiscard]] Bvh finish(std::uint32_t root, std::vector<std::uint32_t>* id_of_node = nullptr) &&;

private:
    struct Item {
        BoundingVolume volume;
        std::vector<std::uint32_t> children;
        std::uint32_t primitive = 0;
    };
    std::vector<Primitive> primitives_;
    std::vector<Item> items_;
};

}  // namespace hbvh
