// SPDX-License-Identifier: MIT
#include "hbvh/tree/validate.hpp"

#include <string>

namespace hbvh {
namespace {
Error node_error(std::uint32_t index, const std::string& problem) {
    return Error{"node " + std::to_string(index) + ": " + problem};
}
}  // namespace

Status validate(const Bvh& bvh, double relative_tolerance) {
    if (bvh.nodes.empty()) return bvh.primitives.empty() ? Status{Ok{}} : Status{Error{"hierarchy has no nodes"}};
    const auto node_count = static_cast<std::uint32_t>(bvh.nodes.size());
    std::vector<std::uint32_t> leaf_of(bvh.primitives.size(), node_count);  // node_count = not seen yet
    std::vector<std::uint32_t> parent_count(node_count, 0);

    for (std::uint32_t i = 0; i < node_count; ++i) {
        const Node& node = bvh.nodes[i];
        if (node.is_leaf()) {
            if (node.primitive >= bvh.primitives.size()) return node_error(i, "leaf refers to a missing primitive");
            if (leaf_of[node.primitive] != node_count)
                return node_error(i, "primitive " + std::to_string(node.primitive) + " appears in two leaves");
            leaf_of[node.primitive] = i;
            continue;
        }
        if (node.child_count < 2) return node_error(i, "inner node with a single child");
        // Breadth-first order puts children after their parent; this also rules out cycles.
        if (node.first_child <= i || node.first_child + node.child_count > node_count)
            return node_error(i, "child range out of order or out of bounds");
        for (std::uint32_t c = 0; c < node.child_count; ++c) ++parent_count[node.first_child + c];
    }
    for (std::uint32_t i = 1; i < node_count; ++i)
        if (parent_count[i] != 1) return node_error(i, "has " + std::to_string(parent_count[i]) + " parents");
    for (std::uint32_t p = 0; p < bvh.primitives.size(); ++p)
        if (leaf_of[p] == node_count) return Error{"primitive " + std::to_string(p) + " is in no leaf"};

    // Containment: a node's BV must hold every covered primitive, i.e. all their generating spheres.
    std::vector<Sphere> spheres;
    for (std::uint32_t i = 0; i < node_count; ++i) {
        const Node& node = bvh.nodes[i];
        const double tolerance = relative_tolerance * std::max(1.0, size_scale(node.volume));
        for (std::uint32_t p : covered_primitives(bvh, i)) {
            spheres.clear();
            append_generating_spheres(bvh.primitives[p].volume, spheres);
            for (const Sphere& s : spheres)
                if (!contains(node.volume, s, tolerance))
                    return node_error(i, "its " + std::string(to_string(type_of(node.volume))) +
                                             " does not contain primitive " + std::to_string(p));
        }
    }
    return Ok{};
}

}  // namespace hbvh
