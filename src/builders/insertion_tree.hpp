// SPDX-License-Identifier: MIT
// Internal: the mutable tree behind the incremental-insertion builders (survey §2.1), with Eq. 2 bookkeeping.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "covered_set_fits.hpp"
#include "guarded_build.hpp"
#include "heuristic_support.hpp"
#include "hbvh/builders/context.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh::detail {

inline constexpr std::uint32_t no_node = std::numeric_limits<std::uint32_t>::max();

/// Thrown by InsertionTree's exact refits once they have fitted more primitives than its refit budget allows.
struct RefitBudgetSpent {};

/// Where an item (a leaf or a detached subtree) goes. Costs are Eq. 2 increases.
struct Placement {
    enum class Kind {
        as_child,       ///< Rule 1: the item becomes a child of `target`.
        with_child,     ///< Rule 2: the item and `target` (any node, the root included) form a new group.
        with_children,  ///< Haber-style rule 4: the item and `partners` (children of `target`) form a new group under `target`.
    };
    Kind kind = Kind::with_child;
    std::uint32_t target = no_node;
    std::vector<std::uint32_t> partners;
    double cost = std::numeric_limits<double>::infinity();
};

/// A tree of leaves (one primitive each) and groups, with every group's BV fit_best over its covered
/// primitives. Ids are stable; nodes of dissolved groups are recycled.
class InsertionTree {
public:
    struct Node {
        BoundingVolume volume;
        double weighted_volume = 0.0;  ///< policy-weighted volume of `volume`.
        std::vector<std::uint32_t> children;
        std::uint32_t parent = no_node;
        std::uint32_t primitive = no_node;  ///< Local primitive index for a leaf.
        [[nodiscard]] bool is_leaf() const { return primitive != no_node; }
    };

    explicit InsertionTree(const PrimitiveSet& set) : set_(&set) {}

    /// Caps the exact refits' work: once they have fitted more than `primitives` primitives in all (summed over
    /// every refit, this tree's snapshots included), the next refit throws RefitBudgetSpent. 0: no cap. Input
    /// sorted along a line makes the insertion a chain whose every ancestor grows with each new leaf, and the
    /// refits then fit O(n^2) primitives per insertion (a rope of 200 capsules: 1.6 s, against 0.02 s shuffled).
    void set_refit_budget(std::uint64_t primitives) { refits_->budget = primitives; }
    /// The primitives the exact refits have fitted so far, in all.
    [[nodiscard]] std::uint64_t refitted_primitives() const { return refits_->fitted; }

    /// A detached leaf for local primitive `local`.
    std::uint32_t make_leaf(std::uint32_t local);
    [[nodiscard]] const Node& node(std::uint32_t id) const { return nodes_[id]; }
    [[nodiscard]] std::uint32_t root() const { return root_; }
    [[nodiscard]] const PrimitiveSet& primitives() const { return *set_; }

    /// Weighted volume of the pricing fitter (estimate_weighted_volume) around the BVs of `a` and `b`:
    /// the cheap estimate of "a with b added".
    [[nodiscard]] double estimate_union(std::uint32_t a, std::uint32_t b) const;
    /// As estimate_union, around the BVs of `ids`.
    [[nodiscard]] double estimate_around(std::span<const std::uint32_t> ids) const;

    /// Attaches the detached `item` as `placement` says, or makes it the root of an empty tree; then
    /// refits the BVs from the change up to the root.
    void attach(std::uint32_t item, const Placement& placement);
    /// Removes the subtree `item` from the tree (it keeps its own BVs); a parent left with one child is
    /// replaced by that child; BVs above are refit.
    void detach(std::uint32_t item);
    /// Detaches group `id` and frees it; returns its children, now detached subtrees.
    std::vector<std::uint32_t> dissolve(std::uint32_t id);

    /// Eq. 2 with the policy's weights over the current tree.
    [[nodiscard]] double cost() const;
    /// Live group ids (root first, breadth-first).
    [[nodiscard]] std::vector<std::uint32_t> groups() const;
    /// Live leaf ids (breadth-first).
    [[nodiscard]] std::vector<std::uint32_t> leaves() const;
    /// The finished hierarchy. Precondition: the tree is not empty.
    [[nodiscard]] Bvh to_bvh(std::span<const Primitive> primitives) const;

private:
    std::uint32_t new_group();
    void collect_primitives(std::uint32_t id, std::vector<std::uint32_t>& out) const;
    /// Exact fit_best of `id` over its covered primitives.
    void refit(std::uint32_t id);
    /// refit from `id` up to the root; when `grown_by` is a node, a BV that already contains that node's
    /// BV is kept (insertion only grows a node, so the old BV is still valid and the costly refit of
    /// large nodes near the root is skipped).
    void refit_upward(std::uint32_t id, std::uint32_t grown_by = no_node);
    void replace_child(std::uint32_t parent, std::uint32_t old_child, std::uint32_t new_child);

    const PrimitiveSet* set_;
    /// Shared by the snapshots the builders take of the tree (a fit depends on its covered set alone).
    std::shared_ptr<CoveredSetFits> fits_ = std::make_shared<CoveredSetFits>();
    /// The refits' work so far and its cap, shared by the snapshots too.
    struct RefitWork {
        std::uint64_t fitted = 0;
        std::uint64_t budget = 0;
    };
    std::shared_ptr<RefitWork> refits_ = std::make_shared<RefitWork>();
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> free_;
    std::uint32_t root_ = no_node;
};

/// `build(tree)` over an InsertionTree whose refits may fit `budget` primitives (0: no cap); once they have, the
/// two-level tree, noted in the report as `builder`'s with budget_hit.
template <class Build>
Bvh build_within_refit_budget(std::span<const Primitive> primitives, const BuildContext& context,
                              std::string_view builder, std::uint64_t budget, InsertionTree& tree, Build&& build) {
    tree.set_refit_budget(budget);
    try {
        return build(tree);
    } catch (const RefitBudgetSpent&) {
        if (context.report != nullptr) {
            context.report->budget_hit = true;
            context.report->notes.push_back(std::string(builder) + ": the exact refits fitted more than " +
                                            std::to_string(budget) +
                                            " primitives (input in a sorted order builds a chain); returned the "
                                            "two-level tree");
        }
        return two_level_tree(primitives, context.policy);
    }
}

}  // namespace hbvh::detail
