// SPDX-License-Identifier: MIT
#include "hbvh/tree/bvh.hpp"

#include <algorithm>
#include <deque>

#include "hbvh/assert.hpp"
#include "../memory/huge_pages.hpp"

namespace hbvh {

std::vector<std::vector<std::uint32_t>> levels(const Bvh& bvh) {
    std::vector<std::vector<std::uint32_t>> result;
    if (bvh.empty()) return result;
    std::vector<std::uint32_t> current{0};
    while (!current.empty()) {
        std::vector<std::uint32_t> next;
        for (std::uint32_t index : current) {
            const Node& node = bvh.nodes[index];
            for (std::uint32_t c = 0; c < node.child_count; ++c) next.push_back(node.first_child + c);
        }
        result.push_back(std::move(current));
        current = std::move(next);
    }
    return result;
}

std::vector<std::uint32_t> covered_primitives(const Bvh& bvh, std::uint32_t index) {
    std::vector<std::uint32_t> out;
    if (index >= bvh.nodes.size()) return out;  // no such node covers nothing (it read past the array)
    std::vector<std::uint32_t> stack{index};
    while (!stack.empty()) {
        const std::uint32_t at = stack.back();
        stack.pop_back();
        if (at >= bvh.nodes.size()) continue;  // a malformed tree's child range (check_structure says which)
        const Node& node = bvh.nodes[at];
        if (node.is_leaf()) out.push_back(node.primitive);
        for (std::uint32_t c = 0; c < node.child_count; ++c) stack.push_back(node.first_child + c);
    }
    std::sort(out.begin(), out.end());
    return out;
}

// The arrays over every primitive and node are on huge pages (memory/huge_pages.hpp): a tree read from a file
// of 10^6 primitives first-touches about 0.7 GB here.
TreeAssembler::TreeAssembler(std::span<const Primitive> primitives) {
    detail::reserve_on_huge_pages(primitives_, primitives.size());
    primitives_.assign(primitives.begin(), primitives.end());
}

void TreeAssembler::reserve(std::size_t items) { detail::reserve_on_huge_pages(items_, items); }

std::uint32_t TreeAssembler::add_leaf(std::uint32_t primitive) {
    HBVH_ASSERT(primitive < primitives_.size());
    items_.push_back({primitives_[primitive].volume, {}, primitive});
    return static_cast<std::uint32_t>(items_.size() - 1);
}

std::uint32_t TreeAssembler::add_group(std::span<const std::uint32_t> children, BoundingVolume volume) {
    HBVH_ASSERT(!children.empty());
    for (std::uint32_t child : children) HBVH_ASSERT(child < items_.size());
    items_.push_back({std::move(volume), {children.begin(), children.end()}, 0});
    return static_cast<std::uint32_t>(items_.size() - 1);
}

void TreeAssembler::set_volume(std::uint32_t id, BoundingVolume volume) { items_.at(id).volume = std::move(volume); }

Bvh TreeAssembler::finish(std::uint32_t root, std::vector<std::uint32_t>* id_of_node) && {
    // A group with one child adds a level without adding a choice: replace it by its child.
    auto skip_single = [&](std::uint32_t id) {
        while (items_[id].children.size() == 1) id = items_[id].children.front();
        return id;
    };
    Bvh bvh;
    bvh.primitives = std::move(primitives_);
    if (items_.empty()) return bvh;
    detail::reserve_on_huge_pages(bvh.nodes, items_.size());  // each item is placed at most once

    // Breadth-first layout: a node's children are appended together, so they are contiguous.
    std::deque<std::pair<std::uint32_t, std::uint32_t>> queue;  // (item id, node index)
    root = skip_single(root);
    bvh.nodes.push_back({items_[root].volume, 0, 0, items_[root].primitive});
    queue.emplace_back(root, 0);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> placed;  // (item id, node index), for id_of_node
    if (id_of_node != nullptr) detail::reserve_on_huge_pages(placed, items_.size());
    while (!queue.empty()) {
        const auto [id, index] = queue.front();
        queue.pop_front();
        if (id_of_node != nullptr) placed.emplace_back(id, index);
        const Item& item = items_[id];
        if (item.children.empty()) continue;
        bvh.nodes[index].first_child = static_cast<std::uint32_t>(bvh.nodes.size());
        bvh.nodes[index].child_count = static_cast<std::uint32_t>(item.children.size());
        for (std::uint32_t child : item.children) {
            const std::uint32_t real = skip_single(child);
            bvh.nodes.push_back({items_[real].volume, 0, 0, items_[real].primitive});
            queue.emplace_back(real, static_cast<std::uint32_t>(bvh.nodes.size() - 1));
        }
    }
    if (id_of_node != nullptr) {
        detail::reserve_on_huge_pages(*id_of_node, bvh.nodes.size());
        id_of_node->resize(bvh.nodes.size());
        for (const auto& [id, index] : placed) (*id_of_node)[index] = id;
    }
    return bvh;
}

}  // namespace hbvh
