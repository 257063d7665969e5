// SPDX-License-Identifier: MIT
#include "collapse.hpp"

#include <cstdint>
#include <vector>

namespace hbvh::detail {

// For a node v and the weight W of its nearest kept ancestor, f(v, W) is the least Eq. 2 that v's subtree adds,
// counting the slot v (or, dissolved, each of its pieces) takes in that ancestor at W per child:
//   a leaf:   f = W;
//   a kept v: W + sum over children u of f(u, weight(v));
//   dissolved: sum over children u of f(u, W).
// The root is kept, so the tree's cost is the sum of f(u, weight(root)) over its children. W is the weight of one
// of v's ancestors, so f is tabulated per node over its ancestors: entry j for the ancestor at depth j.
Bvh collapse_optimally(const Bvh& bvh, const VolumePolicy& policy) {
    const auto n = static_cast<std::uint32_t>(bvh.nodes.size());
    if (n < 2 || bvh.nodes[0].is_leaf()) return bvh;
    // Breadth-first order: a parent comes before its children, so depths are filled in one pass and a reverse
    // pass visits children before parents.
    // The parents too: a node's ancestor at depth j is found by climbing.
    std::vector<std::uint32_t> depth(n, 0), parent(n, 0);
    std::vector<double> weight(n, 0.0);
    std::vector<std::uint64_t> offset(n + 1, 0);  // node v's table is table[offset[v], offset[v] + depth[v])
    for (std::uint32_t v = 0; v < n; ++v) {
        const Node& node = bvh.nodes[v];
        if (!node.is_leaf()) weight[v] = policy.weighted_volume(node.volume);
        for (std::uint32_t c = node.first_child; c < node.first_child + node.child_count; ++c) {
            depth[c] = depth[v] + 1;
            parent[c] = v;
        }
        offset[v + 1] = offset[v] + depth[v];
    }
    std::vector<double> table(offset[n], 0.0);
    std::vector<std::uint8_t> kept(offset[n], 1);  // the choice for v under the ancestor at depth j
    std::vector<double> ancestor_weight;
    for (std::uint32_t v = n; v-- > 1;) {
        const Node& node = bvh.nodes[v];
        const std::uint32_t d = depth[v];
        ancestor_weight.assign(d, 0.0);
        for (std::uint32_t a = parent[v], j = d; j-- > 0; a = parent[a]) ancestor_weight[j] = weight[a];
        double* f = table.data() + offset[v];
        if (node.is_leaf()) {
            for (std::uint32_t j = 0; j < d; ++j) f[j] = ancestor_weight[j];
            continue;
        }
        // A child u of v has depth d + 1: its entry j < d is "v dissolved, ancestor j kept", entry d is "v kept".
        double under_v = 0.0;
        for (std::uint32_t u = node.first_child; u < node.first_child + node.child_count; ++u) under_v += table[offset[u] + d];
        for (std::uint32_t j = 0; j < d; ++j) {
            double dissolved = 0.0;
            for (std::uint32_t u = node.first_child; u < node.first_child + node.child_count; ++u) dissolved += table[offset[u] + j];
            const double keep = ancestor_weight[j] + under_v;
            f[j] = keep <= dissolved ? keep : dissolved;  // ties keep the node
            kept[offset[v] + j] = keep <= dissolved ? 1 : 0;
        }
    }

    // Rebuild top-down: a kept node's children are its own children, each dissolved one replaced by its pieces.
    TreeAssembler assembler(bvh.primitives);
    assembler.reserve(n);
    std::vector<std::uint32_t> id_of(n, 0);
    // Children before parents for the assembler: collect the kept nodes top-down, then add them bottom-up.
    struct Kept {
        std::uint32_t node;
        std::vector<std::uint32_t> pieces;
    };
    std::vector<Kept> order;
    std::vector<std::uint32_t> to_visit{0};
    while (!to_visit.empty()) {
        const std::uint32_t v = to_visit.back();
        to_visit.pop_back();
        Kept entry{v, {}};
        const std::uint32_t j = depth[v];  // v is the kept ancestor of what lies below until the next kept node
        std::vector<std::uint32_t> pending;
        for (std::uint32_t c = bvh.nodes[v].first_child + bvh.nodes[v].child_count; c-- > bvh.nodes[v].first_child;)
            pending.push_back(c);
        while (!pending.empty()) {
            const std::uint32_t u = pending.back();
            pending.pop_back();
            const Node& child = bvh.nodes[u];
            if (child.is_leaf() || kept[offset[u] + j] != 0) {
                entry.pieces.push_back(u);
                if (!child.is_leaf()) to_visit.push_back(u);
                continue;
            }
            for (std::uint32_t c = child.first_child + child.child_count; c-- > child.first_child;) pending.push_back(c);
        }
        order.push_back(std::move(entry));
    }
    for (auto it = order.rbegin(); it != order.rend(); ++it) {
        std::vector<std::uint32_t> children;
        children.reserve(it->pieces.size());
        for (const std::uint32_t u : it->pieces)
            children.push_back(bvh.nodes[u].is_leaf() ? assembler.add_leaf(bvh.nodes[u].primitive) : id_of[u]);
        id_of[it->node] = assembler.add_group(children, bvh.nodes[it->node].volume);
    }
    return std::move(assembler).finish(id_of[0]);
}

}  // namespace hbvh::detail
