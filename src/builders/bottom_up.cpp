// SPDX-License-Identifier: MIT
// The generic bottom-up driver (survey §3, Appendix A Algorithm 1): heuristic -> set partition -> next level.
#include "bottom_up.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>

#include "hbvh/assert.hpp"
#include "guarded_build.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh {
namespace {

/// The geometric key that orders nodes canonically: world-AABB centre, then weighted volume, then kind
/// and the AABB corners. Only nodes with identical keys (in practice: identical primitives) can swap, and
/// swapping identical geometry changes nothing, so the hierarchy's cost does not depend on the input order.
auto canonical_key(const LevelNode& node) {
    const Aabb box = world_aabb(node.volume);
    const Vec3 c = box.center();
    return std::make_tuple(c.x(), c.y(), c.z(), node.weighted_volume, node.volume.index(), box.min.x(), box.min.y(),
                           box.min.z(), box.max.x(), box.max.y(), box.max.z());
}

void sort_canonically(std::vector<LevelNode>& nodes, std::vector<std::uint32_t>& ids) {
    std::vector<std::uint32_t> order(nodes.size());
    std::iota(order.begin(), order.end(), 0u);
    // Stable: exact key ties keep their current order (only identical geometry ties).
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return canonical_key(nodes[a]) < canonical_key(nodes[b]); });
    std::vector<LevelNode> sorted_nodes;
    std::vector<std::uint32_t> sorted_ids;
    sorted_nodes.reserve(nodes.size());
    sorted_ids.reserve(nodes.size());
    for (std::uint32_t i : order) {
        sorted_nodes.push_back(std::move(nodes[i]));
        sorted_ids.push_back(ids[i]);
    }
    nodes = std::move(sorted_nodes);
    ids = std::move(sorted_ids);
}

/// The last resort when even the fallback candidates admit no exact cover (or the budget ran out before
/// the solver found one): pick candidates greedily by cost per member, then give each node left over to
/// the group whose Eq. 2 cost grows least. Every group keeps >= 2 members, so the level still shrinks.
std::vector<std::vector<std::uint32_t>> greedy_cover(const Level& level, std::span<const Candidate> candidates) {
    std::vector<std::uint32_t> order(candidates.size());
    std::iota(order.begin(), order.end(), 0u);
    auto per_member = [&](std::uint32_t i) { return candidates[i].cost / static_cast<double>(candidates[i].members.size()); };
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return per_member(a) < per_member(b); });

    std::vector<bool> covered(level.size(), false);
    std::vector<std::vector<std::uint32_t>> groups;
    for (std::uint32_t i : order) {
        const auto& members = candidates[i].members;
        if (std::any_of(members.begin(), members.end(), [&](std::uint32_t m) { return covered[m]; })) continue;
        for (std::uint32_t m : members) covered[m] = true;
        groups.push_back(members);
    }
    std::vector<std::uint32_t> left;
    for (std::uint32_t j = 0; j < level.size(); ++j)
        if (!covered[j]) left.push_back(j);
    if (groups.empty()) return {left};  // nothing to join: the leftovers (the whole level) form one group
    for (std::uint32_t j : left) {
        std::size_t best = 0;
        double best_growth = std::numeric_limits<double>::infinity();
        for (std::size_t g = 0; g < groups.size(); ++g) {
            std::vector<std::uint32_t> grown = groups[g];
            grown.insert(std::upper_bound(grown.begin(), grown.end(), j), j);
            const double growth = level.candidate_cost(grown) - level.candidate_cost(groups[g]);
            if (growth < best_growth) {
                best_growth = growth;
                best = g;
            }
        }
        groups[best].insert(std::upper_bound(groups[best].begin(), groups[best].end(), j), j);
    }
    return groups;
}

}  // namespace

Level::Level(std::span<const Primitive> primitives, std::vector<LevelNode> nodes, const VolumePolicy& policy)
    : primitives_(primitives), nodes_(std::move(nodes)), policy_(policy), bounds_(Aabb::empty()) {
    for (const LevelNode& node : nodes_) bounds_ = bounds_.merged(world_aabb(node.volume));
}

const FittedGroup& Level::fit_group(std::span<const std::uint32_t> members) const {
    HBVH_ASSERT(!members.empty());
    std::vector<std::uint32_t> key(members.begin(), members.end());
    if (auto found = fitted_.find(key); found != fitted_.end()) return found->second;
    check_deadline();
    // Fit around the primitives themselves (Definition 1.2: a BV need only cover coverage(n)), in member
    // order and each node's canonical primitive order, so the fitters always see the same sphere sequence.
    FitInput input;
    for (std::uint32_t member : members) {
        HBVH_ASSERT(member < nodes_.size());
        for (std::uint32_t p : nodes_[member].primitives) input.add(primitives_[p].volume);
    }
    BoundingVolume volume = fit_best(input.spheres, policy_, input.hint_axes);
    const double weighted = policy_.weighted_volume(volume);
    return fitted_.emplace(std::move(key), FittedGroup{std::move(volume), weighted}).first->second;
}

void Level::check_deadline() const {
    if (deadline_ != std::chrono::steady_clock::time_point::max() && std::chrono::steady_clock::now() >= deadline_)
        throw LevelDeadlinePassed{};
}

double Level::candidate_cost(std::span<const std::uint32_t> members) const {
    return static_cast<double>(members.size()) * fit_group(members).weighted_volume;
}

double Level::tightness(std::span<const std::uint32_t> members) const {
    double children = 0.0;
    for (std::uint32_t m : members) children += nodes_[m].weighted_volume;
    const double parent = fit_group(members).weighted_volume;
    if (children > 0.0) return parent / children;
    return parent > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
}

LevelSolver reference_level_solver() {
    return [](std::uint32_t node_count, std::span<const Candidate> candidates, std::span<const double> node_volumes,
              const SolverBudget& budget) {
        return solve_reference_branch_and_bound(node_count, candidates, node_volumes, budget);
    };
}

std::vector<Candidate> make_candidates(const Level& level, std::vector<std::vector<std::uint32_t>> member_sets) {
    for (auto& members : member_sets) {
        std::sort(members.begin(), members.end());
        members.erase(std::unique(members.begin(), members.end()), members.end());
        for (std::uint32_t m : members) HBVH_ASSERT(m < level.size());
    }
    // Singletons are not merges: the survey requires every node to merge with at least one other (§3).
    std::erase_if(member_sets, [](const auto& members) { return members.size() < 2; });
    // Small sets first, then lexicographic. Besides being canonical, this ends the list with the largest
    // sets (Tightest's whole level), which the survey's skip-first search selects first: it meets a cover
    // at once and can prune from there (docs/algorithms.md).
    std::sort(member_sets.begin(), member_sets.end(), [](const auto& a, const auto& b) {
        return a.size() != b.size() ? a.size() < b.size() : a < b;
    });
    member_sets.erase(std::unique(member_sets.begin(), member_sets.end()), member_sets.end());
    std::vector<Candidate> candidates;
    candidates.reserve(member_sets.size());
    for (auto& members : member_sets) {
        const double cost = level.candidate_cost(members);
        candidates.push_back({std::move(members), cost});
    }
    return candidates;
}

std::vector<std::vector<std::uint32_t>> fallback_member_sets(const Level& level) {
    std::vector<std::vector<std::uint32_t>> sets;
    const std::uint32_t n = level.size();
    // Grow {i} twice by the Tightest rule (§3, Eq. 1). Pairs alone cannot cover a level with an odd
    // number of nodes; the triples can.
    for (std::uint32_t i = 0; i < n; ++i) {
        std::vector<std::uint32_t> group{i};
        for (int step = 0; step < 2 && group.size() < n; ++step) {
            std::vector<std::uint32_t> best;
            double best_tightness = std::numeric_limits<double>::infinity();
            for (std::uint32_t j = 0; j < n; ++j) {
                if (std::binary_search(group.begin(), group.end(), j)) continue;
                std::vector<std::uint32_t> grown = group;
                grown.insert(std::upper_bound(grown.begin(), grown.end(), j), j);
                const double t = level.tightness(grown);
                if (best.empty() || t < best_tightness) {
                    best_tightness = t;
                    best = std::move(grown);
                }
            }
            group = std::move(best);
            sets.push_back(group);
        }
    }
    return sets;
}

namespace {

/// Lines 1.4-1.5 of the survey's level step: the heuristic's candidates (left in `candidates`) and the solver,
/// with the fall-backs where they find no exact cover. Returns the chosen groups (member indices of `level`).
std::vector<std::vector<std::uint32_t>> choose_groups(const Level& level, const CandidateGenerator& generate,
                                                      const LevelSolver& solve, const BottomUpOptions& options,
                                                      std::uint32_t level_index, std::vector<Candidate>& candidates,
                                                      LevelReport& row) {
    const std::uint32_t n = level.size();
    // Stage 1: the heuristic's candidates and the solver.
    candidates = make_candidates(level, generate(level));
    std::vector<double> volumes(n);
    for (std::uint32_t j = 0; j < n; ++j) volumes[j] = level.nodes()[j].weighted_volume;
    std::optional<Partition> partition = solve(n, candidates, volumes, options.budget);
    auto account = [&](const std::optional<Partition>& result) {
        if (!result) return;
        row.solver_nodes += result->nodes_explored;
        row.budget_hit = row.budget_hit || result->budget_hit;
    };
    account(partition);
    std::string note;

    // Stage 2: no exact cover (the survey's failure case, end of §3) -> add each node's best pair
    // and triple and solve again.
    if (!partition) {
        row.fallback_used = true;
        std::vector<std::vector<std::uint32_t>> sets = fallback_member_sets(level);
        for (Candidate& c : candidates) sets.push_back(std::move(c.members));
        candidates = make_candidates(level, std::move(sets));
        partition = solve(n, candidates, volumes, options.budget);
        account(partition);
        note = "level " + std::to_string(level_index) + ": no exact cover among the candidates; added pair/triple candidates";
    }
    std::vector<std::vector<std::uint32_t>> groups;
    if (partition) {
        for (std::uint32_t c : partition->chosen) groups.push_back(candidates[c].members);
    } else {
        // Stage 3: still none (or the budget ran out first): a greedy cover that cannot fail.
        groups = greedy_cover(level, candidates);
        note += "; still none, used the greedy cover";
    }
    if (!note.empty() && options.report) options.report->notes.push_back(std::move(note));
    return groups;
}

}  // namespace

Bvh build_bottom_up(std::span<const Primitive> primitives, const VolumePolicy& policy, const CandidateGenerator& generate,
                    const LevelSolver& solve, const BottomUpOptions& options) {
    HBVH_ASSERT(!primitives.empty());
    TreeAssembler assembler(primitives);

    // Level 0: one node per primitive, ordered canonically; its primitive list is its canonical order.
    std::vector<LevelNode> nodes;
    std::vector<std::uint32_t> ids;
    for (std::uint32_t p = 0; p < primitives.size(); ++p) {
        nodes.push_back({primitives[p].volume, policy.weighted_volume(primitives[p].volume), {p}});
        ids.push_back(assembler.add_leaf(p));
    }
    sort_canonically(nodes, ids);

    std::uint32_t level_index = 0;
    const double primitive_count = static_cast<double>(primitives.size());
    // Anytime: once the deadline has passed, the levels built so far stay and one root takes the rest.
    const auto root_over_the_rest = [&](std::span<const LevelNode> left) {
        // The nodes left cover every primitive; past the deadline their root is fitted quickly.
        const std::uint32_t root = assembler.add_group(ids, detail::root_volume(primitives, policy, detail::RootFit::quick));
        options.checkpoint->context().note_deadline("time limit reached after " + std::to_string(level_index) +
                                                    " levels; one root over the " + std::to_string(left.size()) +
                                                    " nodes left");
        return std::move(assembler).finish(root);
    };
    while (nodes.size() > 1) {
        if (options.checkpoint != nullptr && options.checkpoint->context().expired()) return root_over_the_rest(nodes);
        if (options.checkpoint != nullptr) options.checkpoint->report(primitive_count - static_cast<double>(nodes.size()));
        const auto start = std::chrono::steady_clock::now();
        Level level(primitives, std::move(nodes), policy);
        const std::uint32_t n = level.size();
        LevelReport row;
        row.nodes = n;
        // The candidates, the solver and the fall-backs fit new groups until the partition is chosen; past the
        // deadline the next such fit ends the level (the heuristics alone took minutes at 900 nodes).
        if (options.checkpoint != nullptr) level.stop_fitting_after(options.checkpoint->context().deadline);
        std::vector<Candidate> candidates;
        std::vector<std::vector<std::uint32_t>> groups;
        try {
            groups = choose_groups(level, generate, solve, options, level_index, candidates, row);
        } catch (const LevelDeadlinePassed&) {
            return root_over_the_rest(level.nodes());
        }
        level.stop_fitting_after(std::chrono::steady_clock::time_point::max());

        // Each chosen group becomes a node of the next level, with the BV already fitted for its cost.
        std::vector<LevelNode> next;
        std::vector<std::uint32_t> next_ids;
        for (const auto& members : groups) {
            HBVH_ASSERT(members.size() >= 2);
            const FittedGroup& fitted = level.fit_group(members);
            LevelNode node{fitted.volume, fitted.weighted_volume, {}};
            std::vector<std::uint32_t> children;
            for (std::uint32_t m : members) {
                const auto& covered = level.nodes()[m].primitives;
                node.primitives.insert(node.primitives.end(), covered.begin(), covered.end());
                children.push_back(ids[m]);
            }
            next_ids.push_back(assembler.add_group(children, fitted.volume));
            next.push_back(std::move(node));
        }
        HBVH_ASSERT(next.size() < n);
        sort_canonically(next, next_ids);

        row.candidates = static_cast<std::uint32_t>(candidates.size());
        row.groups = static_cast<std::uint32_t>(next.size());
        row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (options.report) {
            options.report->levels.push_back(row);
            options.report->total_candidates += row.candidates;
            options.report->budget_hit = options.report->budget_hit || row.budget_hit;
        }
        nodes = std::move(next);
        ids = std::move(next_ids);
        ++level_index;
    }
    return std::move(assembler).finish(ids.front());
}

}  // namespace hbvh
