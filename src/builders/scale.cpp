// SPDX-License-Identifier: MIT
// build_scale: bottom-up levels with local candidates and an exact set partition per spatial window.
//
// The survey's level-by-level scheme (§3, Algorithm 1) needs candidates from every node and one
// set-partition solve per level; both are super-linear in the level size. Here both stay local: nodes are
// ordered along a Morton curve, the order is cut into windows of a few dozen nodes, and each window is an
// independent instance for solve_exact over candidates that lie inside it. A level is then O(n) window
// solves of bounded size, and a build O(n log n) (the Morton sort). docs/scale.md has the argument and the
// measured numbers.
#include "hbvh/builders/scale.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

#include "guarded_build.hpp"
#include "set_partition.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/fit/fit_fast.hpp"
#include "hbvh/fit/fit.hpp"
#include "../fit/staged_fit.hpp"

namespace hbvh {
namespace {

using Clock = std::chrono::steady_clock;

/// One node of the current level. Its primitives are a contiguous run of the level's primitive array,
/// so a group's primitives are the concatenation of its members' runs.
struct ScaleNode {
    BoundingVolume volume;
    double weighted_volume = 0.0;
    Vec3 centre = Vec3::Zero();
    std::uint32_t id = 0;             ///< TreeAssembler id.
    std::uint32_t first = 0;          ///< Run in the level's primitive array.
    std::uint32_t primitive_count = 0;
};

/// A chosen group of one window: level node indices and its fitted BV.
struct Group {
    std::vector<std::uint32_t> members;
    BoundingVolume volume;
    double weighted_volume = 0.0;
};

/// Everything one window produces; windows write only their own slot (the determinism argument).
struct WindowResult {
    /// The deadline had passed when the window's turn came: it made no groups, and its nodes go on as they are.
    bool passed_through = false;
    std::vector<Group> groups;
    std::uint32_t candidates = 0;
    std::uint64_t solver_nodes = 0;
    bool budget_hit = false;
};

/// Spreads the bits of a 21-bit integer to every third bit of a 64-bit word.
std::uint64_t spread_bits(std::uint64_t v) {
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
}

/// Reorders `nodes` along a Morton curve of their centres within the level's bounds. Ties (equal codes)
/// keep the previous order, which is itself a function of the input alone.
void sort_morton(std::vector<ScaleNode>& nodes) {
    Aabb bounds = Aabb::empty();
    for (const ScaleNode& node : nodes) bounds = bounds.merged({node.centre, node.centre});
    const Vec3 extent = (bounds.max - bounds.min).cwiseMax(Vec3::Constant(1e-300));
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(nodes.size());
    for (std::uint32_t i = 0; i < nodes.size(); ++i) {
        const Vec3 unit = (nodes[i].centre - bounds.min).cwiseQuotient(extent);
        std::uint64_t code = 0;
        for (int axis = 0; axis < 3; ++axis) {
            const double scaled = std::clamp(unit[axis], 0.0, 1.0) * 2097151.0;
            code |= spread_bits(static_cast<std::uint64_t>(scaled)) << axis;
        }
        keys[i] = {code, i};
    }
    std::sort(keys.begin(), keys.end());
    std::vector<ScaleNode> sorted;
    sorted.reserve(nodes.size());
    for (const auto& key : keys) sorted.push_back(std::move(nodes[key.second]));
    nodes = std::move(sorted);
}

/// Window boundaries over n Morton-ordered nodes: about `size` nodes each; on odd levels shifted by half
/// a window so that nodes cut apart at a boundary meet inside a window on the next level. Every window
/// has at least 2 nodes (n >= 2).
std::vector<std::uint32_t> window_bounds(std::uint32_t n, std::uint32_t size, bool shifted) {
    const std::uint32_t count = std::max<std::uint32_t>(1, (n + size / 2) / size);
    std::vector<std::uint32_t> bounds{0};
    for (std::uint32_t w = 1; w <= count; ++w) {
        const double position = (static_cast<double>(w) - (shifted ? 0.5 : 0.0)) * n / count;
        bounds.push_back(std::min(n, static_cast<std::uint32_t>(position)));
    }
    if (bounds.back() != n) bounds.push_back(n);
    // Drop boundaries that leave a window of fewer than two nodes (merging it into its neighbour).
    std::vector<std::uint32_t> kept{0};
    for (std::size_t b = 1; b + 1 < bounds.size(); ++b)
        if (bounds[b] - kept.back() >= 2 && n - bounds[b] >= 2) kept.push_back(bounds[b]);
    kept.push_back(n);
    return kept;
}

/// The state one level shares read-only with its window tasks.
struct LevelContext {
    std::span<const Primitive> primitives;
    const VolumePolicy& policy;
    const ScaleOptions& options;
    std::uint32_t exact_fit_max_primitives = 0;  ///< Groups up to this size use fit_best.
    bool exact_final_fit = false;                ///< Chosen groups are refitted with fit_best too.
    std::span<const ScaleNode> nodes;
    std::span<const std::uint32_t> level_primitives;  ///< Input indices; node runs index into it.
    Clock::time_point deadline;
    bool has_deadline = false;
};

/// Generating spheres (and box frames as hints) of every primitive the `members` cover.
FitInput primitive_input(const LevelContext& level, std::span<const std::uint32_t> members) {
    FitInput input;
    for (std::uint32_t m : members) {
        const ScaleNode& node = level.nodes[m];
        for (std::uint32_t k = 0; k < node.primitive_count; ++k)
            input.add(level.primitives[level.level_primitives[node.first + k]].volume);
    }
    return input;
}

/// The BV of a group over the primitives it covers. Small groups get fit_best. Big ones get fit_fast:
/// for pricing around the members' BVs (at most 8 spheres each, and a quick sphere), which ranks groups
/// about as well at a fraction of the cost; for the chosen groups around the primitives themselves.
BoundingVolume fit_group(const LevelContext& level, std::span<const std::uint32_t> members, std::uint32_t primitive_count,
                         bool pricing) {
    if (primitive_count <= level.exact_fit_max_primitives) {
        const FitInput input = primitive_input(level, members);
        return fit_best(input.spheres, level.policy, input.hint_axes);
    }
    std::vector<BoundingVolume> hints;
    std::vector<Sphere> spheres;
    for (std::uint32_t m : members) hints.push_back(level.nodes[m].volume);
    if (pricing) {
        for (std::uint32_t m : members) append_generating_spheres(level.nodes[m].volume, spheres);
        return fit_fast(spheres, hints, level.policy, FastFitMode::quick_sphere);
    }
    for (std::uint32_t m : members) {
        const ScaleNode& node = level.nodes[m];
        for (std::uint32_t k = 0; k < node.primitive_count; ++k)
            append_generating_spheres(level.primitives[level.level_primitives[node.first + k]].volume, spheres);
    }
    return fit_fast(spheres, hints, level.policy, FastFitMode::exact_sphere);
}

/// The fallback cover of a window of s >= 2 nodes: consecutive pairs along the curve, the last three
/// together when s is odd.
std::vector<std::vector<std::uint32_t>> fallback_sets(std::uint32_t s) {
    std::vector<std::vector<std::uint32_t>> sets;
    for (std::uint32_t i = 0; i + 1 < s; i += 2) {
        if (s % 2 == 1 && i + 3 == s) {
            sets.push_back({i, i + 1, i + 2});
            break;
        }
        sets.push_back({i, i + 1});
    }
    return sets;
}

bool shorter_then_lexicographic(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;
}

/// Member sets of one window, in window-local indices: each node with subsets of its nearest neighbours,
/// plus consecutive pairs (and a closing triple) so that an exact cover always exists.
std::vector<std::vector<std::uint32_t>> window_member_sets(const LevelContext& level, std::uint32_t begin,
                                                           std::uint32_t end) {
    const std::uint32_t s = end - begin;
    const std::uint32_t k = std::min(level.options.nearest_neighbours, s - 1);
    const std::uint32_t max_size = std::clamp<std::uint32_t>(level.options.max_group_size, 2, 4);
    std::vector<std::vector<std::uint32_t>> sets;
    std::vector<std::uint32_t> order;
    for (std::uint32_t i = 0; i < s; ++i) {
        // Brute-force k nearest centres inside the window: s is a few dozen, and every candidate must lie
        // in the window anyway, so a global kd-tree would only find neighbours that could not be used.
        order.resize(s);
        std::iota(order.begin(), order.end(), 0u);
        order.erase(order.begin() + i);
        const Vec3& c = level.nodes[begin + i].centre;
        const auto distance = [&](std::uint32_t j) { return (level.nodes[begin + j].centre - c).squaredNorm(); };
        std::partial_sort(order.begin(), order.begin() + k, order.end(), [&](std::uint32_t a, std::uint32_t b) {
            const double da = distance(a), db = distance(b);
            return da < db || (da == db && a < b);
        });
        for (std::uint32_t t = 0; t < k; ++t) sets.push_back({i, order[t]});
        // Triples from the 3 nearest, the quadruple of the 3 nearest: groups of near nodes are where the
        // cheap covers are; farther combinations rarely win and would multiply the fitting work.
        if (max_size >= 3)
            for (std::uint32_t a = 0; a < std::min(k, 3u); ++a)
                for (std::uint32_t b = a + 1; b < std::min(k, 3u); ++b) sets.push_back({i, order[a], order[b]});
        if (max_size >= 4 && k >= 3) sets.push_back({i, order[0], order[1], order[2]});
    }
    for (auto& members : fallback_sets(s)) sets.push_back(std::move(members));
    if (s <= max_size) {
        sets.emplace_back(s);
        std::iota(sets.back().begin(), sets.back().end(), 0u);
    }
    for (auto& members : sets) std::sort(members.begin(), members.end());
    std::sort(sets.begin(), sets.end(), shorter_then_lexicographic);
    sets.erase(std::unique(sets.begin(), sets.end()), sets.end());
    return sets;
}

/// fit_group's pricing fit of a small group (fit_best), short of its capsule step where that could still win:
/// the volume found so far, its weighted volume (a lower bound of the answer while the step waits), the step.
struct SmallGroupPrice {
    BoundingVolume volume;
    double weighted = 0.0;
    std::optional<detail::OwnedFit> waiting;
};

SmallGroupPrice price_small_group(const LevelContext& level, std::span<const std::uint32_t> members) {
    FitInput input = primitive_input(level, members);
    detail::OwnedFit fit = detail::start_owned_fit(std::move(input.spheres), level.policy, input.hint_axes);
    SmallGroupPrice price{*fit.stages.best, fit.stages.lower_bound(), std::nullopt};
    if (fit.stages.capsule_pending) price.waiting = std::move(fit);
    return price;
}

/// Solves one window [begin, end) of the level: candidates, prices, exact cover, fitted groups.
WindowResult solve_window(const LevelContext& level, std::uint32_t begin, std::uint32_t end) {
    WindowResult result;
    std::vector<std::vector<std::uint32_t>> sets = window_member_sets(level, begin, end);
    std::vector<Candidate> candidates;
    std::vector<BoundingVolume> volumes;
    // The capsule on demand, as in the treelets (docs/scale.md, "The capsule on demand"): a small group's price
    // stops short of a capsule step that could still win, and the cover is solved with its lower bound; the
    // step runs only for a chosen group, and the cover is solved again, until the chosen groups are all priced
    // exactly. That cover is optimal over the exact prices too, so it is the one of pricing every group exactly.
    std::vector<std::optional<detail::OwnedFit>> waiting(sets.size());
    std::vector<std::uint32_t> global;
    candidates.reserve(sets.size());
    for (std::size_t c = 0; c < sets.size(); ++c) {
        std::vector<std::uint32_t>& members = sets[c];
        global.clear();
        std::uint32_t primitive_count = 0;
        for (std::uint32_t m : members) {
            global.push_back(begin + m);
            primitive_count += level.nodes[begin + m].primitive_count;
        }
        double weighted = 0.0;
        BoundingVolume bv;
        if (primitive_count <= level.exact_fit_max_primitives) {
            SmallGroupPrice price = price_small_group(level, global);
            bv = std::move(price.volume);
            weighted = price.weighted;
            waiting[c] = std::move(price.waiting);
        } else {
            bv = fit_group(level, global, primitive_count, true);
            weighted = level.policy.weighted_volume(bv);
        }
        const double cost = static_cast<double>(members.size()) * weighted;
        candidates.push_back({std::move(members), cost});
        volumes.push_back(std::move(bv));
    }
    result.candidates = static_cast<std::uint32_t>(candidates.size());
    const auto finish = [&](std::uint32_t c) {
        detail::OwnedFit& fit = *waiting[c];
        fit.finish(level.policy);
        candidates[c].cost = static_cast<double>(candidates[c].members.size()) * fit.stages.best_cost;
        volumes[c] = std::move(*fit.stages.best);
        waiting[c].reset();
    };
    if (!level.options.capsule_on_demand)
        for (std::uint32_t c = 0; c < waiting.size(); ++c)
            if (waiting[c]) finish(c);

    // Past the deadline, only the solver's initial cover (greedy + local search) is used.
    SolverBudget budget = level.options.window_budget;
    if (level.has_deadline && Clock::now() >= level.deadline) {
        budget.max_nodes = 1;
        result.budget_hit = true;
    }
    std::optional<Partition> partition = solve_exact(end - begin, candidates, budget);
    for (;;) {
        result.solver_nodes += partition ? partition->nodes_explored : 0;
        std::vector<std::uint32_t> unfinished;
        if (partition && !partition->budget_hit) {
            for (std::uint32_t c : partition->chosen)
                if (waiting[c]) unfinished.push_back(c);
        } else {
            // No proof that the cover is optimal: price every candidate exactly and solve once more, as without
            // the steps on demand.
            for (std::uint32_t c = 0; c < waiting.size(); ++c)
                if (waiting[c]) unfinished.push_back(c);
        }
        if (unfinished.empty()) break;
        for (std::uint32_t c : unfinished) finish(c);
        partition = solve_exact(end - begin, candidates, budget);
    }
    std::vector<std::uint32_t> chosen;
    if (partition) {
        chosen = partition->chosen;
        result.budget_hit = result.budget_hit || partition->budget_hit;
    } else {
        // Only when the budget stopped the search before any cover: the consecutive fallback cover, whose
        // sets are among the candidates (sorted, so a binary search finds them).
        result.budget_hit = true;
        for (const auto& members : fallback_sets(end - begin)) {
            const auto found = std::lower_bound(candidates.begin(), candidates.end(), members,
                                                [](const Candidate& c, const std::vector<std::uint32_t>& m) {
                                                    return shorter_then_lexicographic(c.members, m);
                                                });
            HBVH_ASSERT(found != candidates.end() && found->members == members);
            chosen.push_back(static_cast<std::uint32_t>(found - candidates.begin()));
        }
    }

    for (std::uint32_t c : chosen) {
        Group group;
        std::uint32_t primitive_count = 0;
        for (std::uint32_t m : candidates[c].members) {
            group.members.push_back(begin + m);
            primitive_count += level.nodes[begin + m].primitive_count;
        }
        // The priced BV encloses the members' BVs, hence the primitives, so the smaller of the two is valid.
        group.volume = volumes[c];
        if (primitive_count > level.exact_fit_max_primitives) {
            BoundingVolume tight = fit_group(level, group.members, primitive_count, false);
            if (level.policy.weighted_volume(tight) <= level.policy.weighted_volume(group.volume))
                group.volume = std::move(tight);
            if (level.exact_final_fit) {
                const FitInput input = primitive_input(level, group.members);
                BoundingVolume best = fit_best(input.spheres, level.policy, input.hint_axes);
                if (level.policy.weighted_volume(best) < level.policy.weighted_volume(group.volume))
                    group.volume = std::move(best);
            }
        }
        group.weighted_volume = level.policy.weighted_volume(group.volume);
        result.groups.push_back(std::move(group));
    }
    return result;
}

}  // namespace

namespace {
Bvh scale_tree(std::span<const Primitive> primitives, const BuildContext& context, const ScaleOptions& options) {
    const VolumePolicy& policy = context.policy;
    BuildReport* report = context.report;
    const std::uint32_t n0 = static_cast<std::uint32_t>(primitives.size());
    TreeAssembler assembler(primitives);

    // Level 0: one node per primitive.
    std::vector<ScaleNode> nodes(n0);
    std::vector<std::uint32_t> level_primitives(n0);
    for (std::uint32_t p = 0; p < n0; ++p) {
        const BoundingVolume& bv = primitives[p].volume;
        nodes[p] = {bv, policy.weighted_volume(bv), world_aabb(bv).center(), assembler.add_leaf(p), p, 1};
        level_primitives[p] = p;
    }

    std::uint64_t work_done = 0;
    std::uint32_t level_index = 0;
    while (nodes.size() > 1) {
        const auto level_start = Clock::now();
        sort_morton(nodes);
        const std::uint32_t n = static_cast<std::uint32_t>(nodes.size());
        const std::vector<std::uint32_t> bounds =
            window_bounds(n, std::max<std::uint32_t>(options.window_size, 4), level_index % 2 == 1);
        const std::size_t window_count = bounds.size() - 1;

        const std::uint32_t exact_limit = n0 <= options.exact_fit_all_up_to ? n0 : options.exact_fit_max_primitives;
        const bool refit_level = n <= options.exact_fit_level_nodes && n0 <= options.exact_fit_level_max_input;
        LevelContext level{primitives, policy, options, exact_limit, refit_level, nodes, level_primitives, {}, false};
        if (context.has_deadline()) {
            level.has_deadline = true;
            level.deadline = context.deadline;
        }

        // Stage 1: every window on its own (parallel), each into its own slot. A window whose turn comes after the
        // deadline makes no groups: its candidates' fits are most of a level's time (100 000 primitives took 4.6 s
        // under a 0.5 s limit when every window still fitted its candidates for its initial cover).
        std::vector<WindowResult> slots(window_count);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, window_count, 1), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t w = r.begin(); w != r.end(); ++w) {
                if (level.has_deadline && Clock::now() >= level.deadline)
                    slots[w].passed_through = true;
                else
                    slots[w] = solve_window(level, bounds[w], bounds[w + 1]);
            }
        });

        // Stage 2: combine in window order, so ids and the next level do not depend on scheduling.
        LevelReport row;
        row.nodes = n;
        std::vector<ScaleNode> next;
        std::vector<std::uint32_t> next_primitives;
        next_primitives.reserve(level_primitives.size());
        std::vector<std::uint32_t> children;
        bool passed_through = false;
        for (std::size_t w = 0; w < window_count; ++w) {
            WindowResult& slot = slots[w];
            if (slot.passed_through) {
                passed_through = true;
                for (std::uint32_t m = bounds[w]; m < bounds[w + 1]; ++m) {
                    ScaleNode node = nodes[m];
                    node.first = static_cast<std::uint32_t>(next_primitives.size());
                    next_primitives.insert(next_primitives.end(), level_primitives.begin() + nodes[m].first,
                                           level_primitives.begin() + nodes[m].first + nodes[m].primitive_count);
                    next.push_back(std::move(node));
                }
                continue;
            }
            row.candidates += slot.candidates;
            row.solver_nodes += slot.solver_nodes;
            row.budget_hit = row.budget_hit || slot.budget_hit;
            for (Group& group : slot.groups) {
                HBVH_ASSERT(group.members.size() >= 2);
                ScaleNode node;
                node.first = static_cast<std::uint32_t>(next_primitives.size());
                children.clear();
                for (std::uint32_t m : group.members) {
                    const ScaleNode& member = nodes[m];
                    next_primitives.insert(next_primitives.end(), level_primitives.begin() + member.first,
                                           level_primitives.begin() + member.first + member.primitive_count);
                    node.primitive_count += member.primitive_count;
                    children.push_back(member.id);
                }
                node.centre = world_aabb(group.volume).center();
                node.weighted_volume = group.weighted_volume;
                node.id = assembler.add_group(children, group.volume);
                node.volume = std::move(group.volume);
                next.push_back(std::move(node));
            }
        }
        HBVH_ASSERT(passed_through || next.size() < n);
        row.groups = static_cast<std::uint32_t>(next.size());
        row.budget_hit = row.budget_hit || passed_through;
        row.seconds = std::chrono::duration<double>(Clock::now() - level_start).count();
        if (report != nullptr) {
            report->levels.push_back(row);
            report->total_candidates += row.candidates;
            report->budget_hit = report->budget_hit || row.budget_hit;
        }
        nodes = std::move(next);
        level_primitives = std::move(next_primitives);
        ++level_index;
        if (passed_through && nodes.size() > 1) {
            // Anytime: the levels built so far stay, and one root, quickly fitted, takes the rest.
            std::vector<std::uint32_t> ids;
            for (const ScaleNode& node : nodes) ids.push_back(node.id);
            const std::uint32_t root =
                assembler.add_group(ids, detail::root_volume(primitives, policy, detail::RootFit::quick));
            context.note_deadline("scale: the time limit passed during level " + std::to_string(level_index - 1) +
                                  "; one root over the " + std::to_string(nodes.size()) + " nodes left");
            return std::move(assembler).finish(root);
        }

        // Work per level is about proportional to its node count and levels shrink geometrically (by
        // ~2.5), so the levels still to come are worth about 1.7 x the next one.
        work_done += n;
        const double remaining = nodes.size() > 1 ? 1.7 * static_cast<double>(nodes.size()) : 0.0;
        context.report_progress(static_cast<double>(work_done) / (static_cast<double>(work_done) + remaining));
    }
    if (report != nullptr && context.has_deadline() && report->budget_hit)
        report->notes.push_back("scale: the time limit cut the search; remaining windows kept their initial cover");
    return std::move(assembler).finish(nodes.front().id);
}
}  // namespace

Result<Bvh> build_scale(std::span<const Primitive> primitives, const BuildContext& context, const ScaleOptions& options) {
    // Anytime: the deadline makes the remaining windows keep their initial cover, so levels always complete;
    // the guard's checkpoint is not used for it.
    BuildContext no_deadline = context;
    no_deadline.deadline = BuildContext::Clock::time_point::max();
    return detail::guarded_build(primitives, no_deadline, "scale", 1.0,
                                 [&](const detail::Checkpoint&) { return Result<Bvh>(scale_tree(primitives, context, options)); });
}

}  // namespace hbvh
