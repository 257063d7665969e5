// SPDX-License-Identifier: MIT
// Incremental insertion after Haber et al. (survey §2.1): a wider rule set, a search of the whole tree,
// and the two global optimisations the survey names, Successive Re-Insertion and Elimination of
// Ill-formed Groups. The paper itself was not available to us; what follows is built from the survey's
// description and documented as such in docs/algorithms-heuristics.md.
#include "hbvh/builders/insertion_haber.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <queue>
#include <string>

#include "guarded_build.hpp"
#include "insertion_tree.hpp"

namespace hbvh {
namespace {

using detail::InsertionTree;
using detail::no_node;
using detail::Placement;

// Groups expanded per search. Best-first order visits the cheapest regions first, so the cap trims only
// unpromising branches, and keeps an insertion O(cap) fits however large the tree.
constexpr std::uint32_t search_limit = 24;
// A re-insertion is carried out only if the pricing fitter expects it to save this fraction of the
// total cost: the estimates are upper bounds of differing looseness, and a move that is only
// predicted to break even is almost always reverted after its (costly) exact refits.
constexpr double promising_gain = 1e-3;
// A global step must lower the cost by more than this relative amount to be kept (rounding noise).
constexpr double improvement_tolerance = 1e-12;

struct Frontier {
    double bound;   ///< Eq. 2 increase already committed above and at this node (a lower bound while rule 4 is ignored).
    std::uint32_t node;
    double grown;   ///< Estimated weighted volume of the node with the item added.
    bool operator>(const Frontier& other) const {
        return bound != other.bound ? bound > other.bound : node > other.node;
    }
};

// Best-first branch and bound over all groups. Per group g (c children, V, V' = V with the item):
//   rule 1: bound + V'                      rule 2 with child ch: bound + 2 volume(ch + item)
//   rule 4 with k children S:  bound + (1 - k) V' + (k + 1) volume(S + item)
// (g keeps its volume V' but has k - 1 fewer children; the new group holds S and the item).
// Rule 3 pushes each child group with bound + its own growth. Rule 4 can lower the cost, so the bound is
// exact only for rules 1-3; the search is a heuristic for rule 4, which is why it is capped.
// `exclude` (a node still in the tree) is skipped as a partner, so a leaf can be priced for re-insertion
// before it is taken out.
Placement search(const InsertionTree& tree, std::uint32_t item, const InsertionHaberOptions& options,
                 std::uint32_t exclude = no_node) {
    const std::uint32_t root = tree.root();
    const double root_grown = tree.estimate_union(root, item);
    Placement best{Placement::Kind::with_child, root, {}, 2.0 * root_grown};
    const auto& root_node = tree.node(root);
    if (root_node.is_leaf()) return best;

    std::priority_queue<Frontier, std::vector<Frontier>, std::greater<>> frontier;
    frontier.push({static_cast<double>(root_node.children.size()) * (root_grown - root_node.weighted_volume), root,
                   root_grown});
    const std::uint32_t max_partners = std::max<std::uint32_t>(options.max_rule4_children, 2);
    for (std::uint32_t expanded = 0; !frontier.empty() && expanded < search_limit; ++expanded) {
        const Frontier at = frontier.top();
        frontier.pop();
        if (at.bound >= best.cost) break;
        const auto& node = tree.node(at.node);
        if (at.bound + at.grown < best.cost) best = {Placement::Kind::as_child, at.node, {}, at.bound + at.grown};

        std::vector<std::pair<double, std::uint32_t>> closeness;  // (growth of child if item joined it, child)
        for (const std::uint32_t child : node.children) {
            if (child == exclude) continue;
            const auto& ch = tree.node(child);
            const double with_item = tree.estimate_union(child, item);
            if (at.bound + 2.0 * with_item < best.cost)
                best = {Placement::Kind::with_child, child, {}, at.bound + 2.0 * with_item};
            closeness.emplace_back(with_item - ch.weighted_volume, child);
            if (!ch.is_leaf())
                frontier.push({at.bound + static_cast<double>(ch.children.size()) * (with_item - ch.weighted_volume),
                               child, with_item});
        }

        // Rule 4: the item with its k closest children, which lets one insertion create a group wider
        // than two (the survey's complaint about rule 2).
        const std::size_t c = closeness.size();
        if (c < 3) continue;
        std::sort(closeness.begin(), closeness.end());
        std::vector<std::uint32_t> members{item};
        for (std::size_t k = 1; k <= std::min<std::size_t>(c - 1, max_partners); ++k) {
            members.push_back(closeness[k - 1].second);
            if (k < 2) continue;
            const double group_volume = tree.estimate_around(members);
            const double cost = at.bound + (1.0 - static_cast<double>(k)) * at.grown +
                                static_cast<double>(k + 1) * group_volume;
            if (cost < best.cost) best = {Placement::Kind::with_children, at.node, {members.begin() + 1, members.end()}, cost};
        }
    }
    return best;
}

void insert(InsertionTree& tree, std::uint32_t item, const InsertionHaberOptions& options) {
    if (tree.root() == no_node)
        tree.attach(item, {});
    else
        tree.attach(item, search(tree, item, options));
}

bool is_live_group(const InsertionTree& tree, std::uint32_t id) {
    if (tree.node(id).children.empty()) return false;
    std::uint32_t up = id;
    while (tree.node(up).parent != no_node) up = tree.node(up).parent;
    return up == tree.root();
}

// Badness criteria for Elimination of Ill-formed Groups: loose (Eq. 1 tightness above the limit) or
// dominated (one child nearly as big as the group, so the others hang around it rather than belong).
// Returns the tightness for ordering, or 0 when the group is well formed.
double ill_formed_score(const InsertionTree& tree, std::uint32_t id, const InsertionHaberOptions& options) {
    const auto& node = tree.node(id);
    double sum = 0.0, largest = 0.0;
    for (const std::uint32_t c : node.children) {
        sum += tree.node(c).weighted_volume;
        largest = std::max(largest, tree.node(c).weighted_volume);
    }
    const double tightness = sum > 0.0 ? node.weighted_volume / sum : std::numeric_limits<double>::infinity();
    const bool loose = tightness > options.max_tightness;
    const bool dominated = largest >= options.dominant_child_fraction * node.weighted_volume;
    return (loose || dominated) ? std::max(tightness, 1e-300) : 0.0;
}

// Estimated Eq. 2 decrease if `leaf` were removed: its parent loses a child and may shrink.
double removal_gain(const InsertionTree& tree, std::uint32_t leaf) {
    const std::uint32_t parent = tree.node(leaf).parent;
    const auto& group = tree.node(parent);
    const double c = static_cast<double>(group.children.size());
    if (group.children.size() <= 2) return 2.0 * group.weighted_volume;
    std::vector<std::uint32_t> others;
    for (const std::uint32_t ch : group.children)
        if (ch != leaf) others.push_back(ch);
    return c * group.weighted_volume - (c - 1.0) * tree.estimate_around(others);
}

class Optimizer {
public:
    Optimizer(InsertionTree& tree, const InsertionHaberOptions& options)
        : tree_(tree), options_(options), cost_(tree.cost()) {}

    /// Rounds until one gains too little, or the deadline passes (anytime: every kept step lowered the cost).
    void run(const BuildContext& context) {
        for (std::uint32_t round = 0; round < options_.optimization_rounds; ++round) {
            if (context.expired()) {
                context.note_deadline("insertion-haber: time limit reached after " + std::to_string(round) +
                                      " optimisation rounds; returned the tree as optimised so far");
                break;
            }
            context.report_progress(0.5 + 0.5 * round / options_.optimization_rounds);
            const double start = cost_;
            reinsert_leaves();
            eliminate_ill_formed_groups();
            if (!(cost_ < start * (1.0 - improvement_tolerance))) break;
        }
    }

private:
    // Keeps the change if it lowered Eq. 2, else restores the snapshot.
    void settle(InsertionTree&& snapshot) {
        const double after = tree_.cost();
        if (after < cost_ * (1.0 - improvement_tolerance))
            cost_ = after;
        else
            tree_ = std::move(snapshot);
    }

    // Successive Re-Insertion: leaves whose removal would save the most are the worst placed. Each is
    // priced first with the pricing fitter (removal gain against the best new place, found while the
    // leaf is still in the tree); only a promising move is carried out with exact refits and kept if
    // Eq. 2 really dropped.
    void reinsert_leaves() {
        std::vector<std::pair<double, std::uint32_t>> ranked;
        for (const std::uint32_t leaf : tree_.leaves())
            if (tree_.node(leaf).parent != no_node) ranked.emplace_back(-removal_gain(tree_, leaf), leaf);
        std::sort(ranked.begin(), ranked.end());
        if (ranked.size() > options_.max_reinsertions_per_round) ranked.resize(options_.max_reinsertions_per_round);
        for (const auto& [rank, leaf] : ranked) {
            if (tree_.node(leaf).parent == no_node) continue;
            const double gain = removal_gain(tree_, leaf);
            if (!(search(tree_, leaf, options_, leaf).cost < gain - promising_gain * cost_)) continue;
            InsertionTree snapshot = tree_;
            tree_.detach(leaf);
            insert(tree_, leaf, options_);
            settle(std::move(snapshot));
        }
    }

    // Elimination of Ill-formed Groups: dissolve a bad group and insert its children again, largest
    // first so the big pieces lay out the structure the small ones then join.
    void eliminate_ill_formed_groups() {
        std::vector<std::pair<double, std::uint32_t>> ranked;
        for (const std::uint32_t id : tree_.groups())
            if (id != tree_.root())
                if (const double score = ill_formed_score(tree_, id, options_); score > 0.0) ranked.emplace_back(-score, id);
        std::sort(ranked.begin(), ranked.end());
        if (ranked.size() > options_.max_eliminations_per_round) ranked.resize(options_.max_eliminations_per_round);
        for (const auto& [score, id] : ranked) {
            if (!is_live_group(tree_, id) || id == tree_.root() || ill_formed_score(tree_, id, options_) == 0.0)
                continue;
            InsertionTree snapshot = tree_;
            std::vector<std::uint32_t> children = tree_.dissolve(id);
            std::sort(children.begin(), children.end(), [&](std::uint32_t a, std::uint32_t b) {
                const double va = tree_.node(a).weighted_volume, vb = tree_.node(b).weighted_volume;
                return va != vb ? va > vb : a < b;
            });
            for (const std::uint32_t child : children) insert(tree_, child, options_);
            settle(std::move(snapshot));
        }
    }

    InsertionTree& tree_;
    const InsertionHaberOptions& options_;
    double cost_;
};

}  // namespace

Result<Bvh> build_insertion_haber(std::span<const Primitive> primitives, const BuildContext& context,
                                  const InsertionHaberOptions& options) {
    // Insertion is the first half of the progress, the optimisation rounds the second.
    return detail::guarded_build(primitives, context, "insertion-haber", 2.0 * static_cast<double>(primitives.size()),
                                 [&](const detail::Checkpoint& checkpoint) {
        std::vector<std::uint32_t> order(primitives.size());
        std::iota(order.begin(), order.end(), 0u);  // input order is the insertion order
        const detail::PrimitiveSet set(primitives, std::move(order), context.policy);
        InsertionTree tree(set);
        return detail::build_within_refit_budget(primitives, context, "insertion-haber", options.max_refit_primitives,
                                                 tree, [&](InsertionTree& growing) {
            for (std::uint32_t local = 0; local < set.size(); ++local) {
                checkpoint.step(local);
                insert(growing, growing.make_leaf(local), options);
            }
            Optimizer(growing, options).run(context);
            return growing.to_bvh(primitives);
        });
    });
}

}  // namespace hbvh
