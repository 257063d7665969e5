// SPDX-License-Identifier: MIT
// The mutable tree of the incremental-insertion builders: attach, detach, refit, Eq. 2.
#include "insertion_tree.hpp"

#include <algorithm>

#include "hbvh/assert.hpp"

namespace hbvh::detail {

std::uint32_t InsertionTree::make_leaf(std::uint32_t local) {
    const auto id = static_cast<std::uint32_t>(nodes_.size());
    Node leaf;
    leaf.volume = set_->volume_of(local);
    leaf.weighted_volume = set_->primitive_volume(local);
    leaf.primitive = local;
    nodes_.push_back(std::move(leaf));
    return id;
}

std::uint32_t InsertionTree::new_group() {
    if (!free_.empty()) {
        const std::uint32_t id = free_.back();
        free_.pop_back();
        nodes_[id] = Node{};
        return id;
    }
    nodes_.emplace_back();
    return static_cast<std::uint32_t>(nodes_.size() - 1);
}

double InsertionTree::estimate_union(std::uint32_t a, std::uint32_t b) const {
    const BoundingVolume both[2] = {nodes_[a].volume, nodes_[b].volume};
    return detail::estimate_around(both, set_->policy());
}

double InsertionTree::estimate_around(std::span<const std::uint32_t> ids) const {
    std::vector<BoundingVolume> volumes;
    volumes.reserve(ids.size());
    for (const std::uint32_t id : ids) volumes.push_back(nodes_[id].volume);
    return detail::estimate_around(volumes, set_->policy());
}

void InsertionTree::collect_primitives(std::uint32_t id, std::vector<std::uint32_t>& out) const {
    std::vector<std::uint32_t> stack{id};
    while (!stack.empty()) {
        const Node& n = nodes_[stack.back()];
        stack.pop_back();
        if (n.is_leaf())
            out.push_back(n.primitive);
        else
            stack.insert(stack.end(), n.children.begin(), n.children.end());
    }
}

void InsertionTree::refit(std::uint32_t id) {
    std::vector<std::uint32_t> covered;
    collect_primitives(id, covered);
    refits_->fitted += covered.size();
    if (refits_->budget != 0 && refits_->fitted > refits_->budget) throw RefitBudgetSpent{};
    std::sort(covered.begin(), covered.end());
    nodes_[id].volume = fits_->fit(*set_, std::move(covered));
    nodes_[id].weighted_volume = set_->weighted_volume(nodes_[id].volume);
}

void InsertionTree::refit_upward(std::uint32_t id, std::uint32_t grown_by) {
    std::vector<Sphere> added;
    if (grown_by != no_node) added = generating_spheres(nodes_[grown_by].volume);
    for (; id != no_node; id = nodes_[id].parent) {
        const BoundingVolume& current = nodes_[id].volume;
        const bool still_valid = grown_by != no_node && !nodes_[id].children.empty() &&
                                 std::all_of(added.begin(), added.end(), [&](const Sphere& s) {
                                     return contains(current, s);
                                 });
        // A freshly made group has no valid BV yet (its weighted volume is 0), so it is always fit.
        if (!still_valid || nodes_[id].weighted_volume == 0.0) refit(id);
    }
}

void InsertionTree::replace_child(std::uint32_t parent, std::uint32_t old_child, std::uint32_t new_child) {
    nodes_[new_child].parent = parent;
    if (parent == no_node) {
        root_ = new_child;
        return;
    }
    auto& children = nodes_[parent].children;
    *std::find(children.begin(), children.end(), old_child) = new_child;
}

void InsertionTree::attach(std::uint32_t item, const Placement& placement) {
    HBVH_ASSERT(nodes_[item].parent == no_node && item != root_);
    if (root_ == no_node) {
        root_ = item;
        return;
    }
    const std::uint32_t target = placement.target;
    switch (placement.kind) {
        case Placement::Kind::as_child: {
            HBVH_ASSERT(!nodes_[target].is_leaf());
            nodes_[target].children.push_back(item);
            nodes_[item].parent = target;
            refit_upward(target, item);
            return;
        }
        case Placement::Kind::with_child: {
            const std::uint32_t group = new_group();
            replace_child(nodes_[target].parent, target, group);
            nodes_[group].children = {target, item};
            nodes_[target].parent = group;
            nodes_[item].parent = group;
            refit_upward(group, item);
            return;
        }
        case Placement::Kind::with_children: {
            HBVH_ASSERT(placement.partners.size() >= 2 &&
                        placement.partners.size() < nodes_[target].children.size());
            const std::uint32_t group = new_group();
            auto& siblings = nodes_[target].children;
            std::erase_if(siblings, [&](std::uint32_t c) {
                return std::find(placement.partners.begin(), placement.partners.end(), c) != placement.partners.end();
            });
            siblings.push_back(group);
            nodes_[group].parent = target;
            nodes_[group].children = placement.partners;
            nodes_[group].children.push_back(item);
            for (const std::uint32_t c : nodes_[group].children) nodes_[c].parent = group;
            refit(group);
            refit_upward(target, item);
            return;
        }
    }
}

void InsertionTree::detach(std::uint32_t item) {
    const std::uint32_t parent = nodes_[item].parent;
    nodes_[item].parent = no_node;
    if (parent == no_node) {
        HBVH_ASSERT(root_ == item);
        root_ = no_node;
        return;
    }
    auto& siblings = nodes_[parent].children;
    std::erase(siblings, item);
    if (siblings.size() == 1) {
        // No single-child groups: the lone sibling takes the parent's place.
        const std::uint32_t only = siblings.front();
        const std::uint32_t grandparent = nodes_[parent].parent;
        replace_child(grandparent, parent, only);
        nodes_[parent] = Node{};
        free_.push_back(parent);
        refit_upward(grandparent);
        return;
    }
    refit_upward(parent);
}

std::vector<std::uint32_t> InsertionTree::dissolve(std::uint32_t id) {
    HBVH_ASSERT(!nodes_[id].is_leaf());
    detach(id);
    std::vector<std::uint32_t> children = std::move(nodes_[id].children);
    for (const std::uint32_t c : children) nodes_[c].parent = no_node;
    nodes_[id] = Node{};
    free_.push_back(id);
    return children;
}

double InsertionTree::cost() const {
    double total = 0.0;
    for (const std::uint32_t id : groups())
        total += static_cast<double>(nodes_[id].children.size()) * nodes_[id].weighted_volume;
    return total;
}

std::vector<std::uint32_t> InsertionTree::groups() const {
    std::vector<std::uint32_t> out;
    if (root_ == no_node || nodes_[root_].is_leaf()) return out;
    out.push_back(root_);
    for (std::size_t i = 0; i < out.size(); ++i)
        for (const std::uint32_t c : nodes_[out[i]].children)
            if (!nodes_[c].is_leaf()) out.push_back(c);
    return out;
}

std::vector<std::uint32_t> InsertionTree::leaves() const {
    std::vector<std::uint32_t> out;
    if (root_ == no_node) return out;
    std::vector<std::uint32_t> queue{root_};
    for (std::size_t i = 0; i < queue.size(); ++i) {
        const Node& n = nodes_[queue[i]];
        if (n.is_leaf())
            out.push_back(queue[i]);
        else
            queue.insert(queue.end(), n.children.begin(), n.children.end());
    }
    return out;
}

Bvh InsertionTree::to_bvh(std::span<const Primitive> primitives) const {
    HBVH_ASSERT(root_ != no_node);
    TreeAssembler assembler(primitives);
    // Post-order with an explicit stack: insertion trees can be deep.
    std::vector<std::uint32_t> assembled(nodes_.size(), no_node);
    std::vector<std::pair<std::uint32_t, bool>> stack{{root_, false}};
    while (!stack.empty()) {
        const auto [id, expanded] = stack.back();
        stack.pop_back();
        const Node& n = nodes_[id];
        if (n.is_leaf()) {
            assembled[id] = assembler.add_leaf(set_->input_index(n.primitive));
        } else if (!expanded) {
            stack.emplace_back(id, true);
            for (const std::uint32_t c : n.children) stack.emplace_back(c, false);
        } else {
            std::vector<std::uint32_t> children;
            for (const std::uint32_t c : n.children) children.push_back(assembled[c]);
            assembled[id] = assembler.add_group(children, n.volume);
        }
    }
    return std::move(assembler).finish(assembled[root_]);
}

}  // namespace hbvh::detail
