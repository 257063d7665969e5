// SPDX-License-Identifier: MIT
// Goldsmith and Salmon's incremental insertion (IEEE CG&A 1987; survey §2.1), with Haines' refinement.
#include "hbvh/builders/insertion.hpp"

#include <numeric>

#include "guarded_build.hpp"
#include "insertion_tree.hpp"

namespace hbvh {
namespace {

using detail::InsertionTree;
using detail::Placement;

// One descent from the root. At every group g with c children, V = volume(g) and V' = the estimated
// volume of g with the item added, the Eq. 2 increases are
//   rule 1 (item joins g):             inherited + c (V' - V) + V'
//   rule 2 (item pairs with child ch): inherited + c (V' - V) + 2 volume(ch + item)
// where `inherited` sums the growth terms of the ancestors. Rule 3 descends into the child group whose
// own term c_ch (volume(ch + item) - volume(ch)) grows least, as Goldsmith and Salmon do; Haines
// (Ray Tracing News 1988) showed it pays to keep the best rule 1/2 seen anywhere on the path.
Placement choose_placement(const InsertionTree& tree, std::uint32_t item) {
    const std::uint32_t root = tree.root();
    // Rule 2 above the root: a new root over the old root and the item.
    Placement best{Placement::Kind::with_child, root, {}, 2.0 * tree.estimate_union(root, item)};
    const Vec3 item_centre = world_aabb(tree.node(item).volume).center();
    double inherited = 0.0;
    double grown = best.cost / 2.0;  // estimated volume of the current node with the item added
    for (std::uint32_t g = root; g != detail::no_node && !tree.node(g).is_leaf();) {
        const auto& node = tree.node(g);
        const double c = static_cast<double>(node.children.size());
        const double growth = c * (grown - node.weighted_volume);
        if (inherited + growth + grown < best.cost) best = {Placement::Kind::as_child, g, {}, inherited + growth + grown};
        std::uint32_t next = detail::no_node;
        double next_increase = 0.0, next_grown = 0.0, next_distance = 0.0;
        for (const std::uint32_t child : node.children) {
            const double with_item = tree.estimate_union(child, item);
            const double pair_cost = inherited + growth + 2.0 * with_item;
            if (pair_cost < best.cost) best = {Placement::Kind::with_child, child, {}, pair_cost};
            const auto& ch = tree.node(child);
            if (ch.is_leaf()) continue;
            const double increase = static_cast<double>(ch.children.size()) * (with_item - ch.weighted_volume);
            // Goldsmith and Salmon break ties by the nearest centre.
            const double distance = (world_aabb(ch.volume).center() - item_centre).squaredNorm();
            if (next == detail::no_node || increase < next_increase ||
                (increase == next_increase && distance < next_distance)) {
                next = child;
                next_increase = increase;
                next_grown = with_item;
                next_distance = distance;
            }
        }
        inherited += growth;
        g = next;
        grown = next_grown;
    }
    return best;
}

}  // namespace

Result<Bvh> build_insertion(std::span<const Primitive> primitives, const BuildContext& context,
                            const InsertionOptions& options) {
    return detail::guarded_build(primitives, context, "insertion", static_cast<double>(primitives.size()),
                                 [&](const detail::Checkpoint& checkpoint) {
        // Input order is the insertion order: the identity permutation.
        std::vector<std::uint32_t> order(primitives.size());
        std::iota(order.begin(), order.end(), 0u);
        const detail::PrimitiveSet set(primitives, std::move(order), context.policy);
        InsertionTree tree(set);
        return detail::build_within_refit_budget(primitives, context, "insertion", options.max_refit_primitives, tree,
                                                 [&](InsertionTree& growing) {
            for (std::uint32_t local = 0; local < set.size(); ++local) {
                checkpoint.step(local);
                const std::uint32_t leaf = growing.make_leaf(local);
                if (growing.root() == detail::no_node)
                    growing.attach(leaf, {});
                else
                    growing.attach(leaf, choose_placement(growing, leaf));
            }
            return growing.to_bvh(primitives);
        });
    });
}

}  // namespace hbvh
