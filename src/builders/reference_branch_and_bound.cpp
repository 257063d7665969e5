// SPDX-License-Identifier: MIT
// The survey's branch and bound for the per-level set-partition problem (§3, Appendix A, Algorithms 2-3).
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "hbvh/assert.hpp"
#include "set_partition.hpp"

namespace hbvh {
namespace {

/// One nonzero 64-bit word of a candidate's member bitset.
struct MaskWord {
    std::uint32_t word = 0;
    std::uint64_t bits = 0;
};

/// A candidate as sparse bitset words (the survey's 32-bit word, made growable, §4.2) and its total
/// member volume (what choosing it removes from the Eq. 7 estimate).
struct PreparedCandidate {
    std::vector<MaskWord> mask;
    double member_volume = 0.0;
    std::uint32_t member_count = 0;
};

/// One activation of RecB&B (Algorithm 3). `stage` says which of its two recursive calls comes next;
/// the saved cost and uncovered volume undo a push exactly, without floating-point drift.
struct Frame {
    std::uint32_t current = 0;
    bool select = false;  ///< The survey's binSelect.
    bool pushed = false;
    std::uint8_t stage = 0;
    double saved_cost = 0.0;
    double saved_uncovered = 0.0;
};

/// A per-node lower bound that is admissible for every instance: in an exact cover each node is covered by
/// exactly one chosen candidate, so charging each node the cheapest cost-per-member share of a candidate
/// containing it can only underestimate. Used for Partition::lower_bound when Eq. 7 is not known to hold.
double per_node_lower_bound(std::uint32_t node_count, std::span<const Candidate> candidates) {
    std::vector<double> share(node_count, std::numeric_limits<double>::infinity());
    for (const Candidate& candidate : candidates) {
        const double per_member = candidate.cost / static_cast<double>(candidate.members.size());
        for (std::uint32_t member : candidate.members) share[member] = std::min(share[member], per_member);
    }
    double total = 0.0;
    for (double s : share) total += s;
    return total;
}

/// True when every candidate costs at least 2 x the volume of its members: then no completion of a partial
/// cover can cost less than 2 x the uncovered volume, so Eq. 7 is a true lower bound and the search is exact.
bool eq7_is_admissible(std::span<const Candidate> candidates, std::span<const double> node_volumes) {
    for (const Candidate& candidate : candidates) {
        double members = 0.0;
        for (std::uint32_t member : candidate.members) members += node_volumes[member];
        if (candidate.cost < 2.0 * members) return false;
    }
    return true;
}

}  // namespace

std::optional<Partition> solve_reference_branch_and_bound(std::uint32_t node_count, std::span<const Candidate> candidates,
                                                          std::span<const double> node_volumes,
                                                          const SolverBudget& budget) {
    HBVH_ASSERT(node_volumes.size() == node_count);
    const auto candidate_count = static_cast<std::uint32_t>(candidates.size());

    // Stage 1: bitsets. The survey stores the selector in a 32-bit integer and so stops at 32 primitives
    // (§4.2); words of a std::vector lift that limit.
    const std::size_t word_count = (node_count + 63) / 64;
    std::vector<PreparedCandidate> prepared(candidate_count);
    for (std::uint32_t i = 0; i < candidate_count; ++i) {
        const Candidate& candidate = candidates[i];
        HBVH_ASSERT(!candidate.members.empty());
        HBVH_ASSERT(std::is_sorted(candidate.members.begin(), candidate.members.end()));
        HBVH_ASSERT(std::adjacent_find(candidate.members.begin(), candidate.members.end()) == candidate.members.end());
        for (std::uint32_t member : candidate.members) {
            HBVH_ASSERT(member < node_count);
            const std::uint32_t word = member / 64;
            if (prepared[i].mask.empty() || prepared[i].mask.back().word != word) prepared[i].mask.push_back({word, 0});
            prepared[i].mask.back().bits |= std::uint64_t{1} << (member % 64);
            prepared[i].member_volume += node_volumes[member];
        }
        prepared[i].member_count = static_cast<std::uint32_t>(candidate.members.size());
    }

    // Search state: the survey's stack of chosen candidates, plus the covered bitset it implies.
    std::vector<std::uint64_t> covered(word_count, 0);
    std::uint32_t covered_count = 0;
    std::vector<std::uint32_t> stack;
    double cost_so_far = 0.0;
    double uncovered_volume = 0.0;
    for (double v : node_volumes) uncovered_volume += v;

    double best_cost = std::numeric_limits<double>::infinity();  // the survey's smallestSolution
    std::optional<std::vector<std::uint32_t>> best;
    std::uint64_t explored = 0;
    bool budget_hit = false;

    const auto start = std::chrono::steady_clock::now();
    auto out_of_budget = [&] {
        if (budget.max_nodes > 0 && explored >= budget.max_nodes) return true;
        // Reading the clock costs more than a search node, so look only every 4096 nodes.
        if (budget.max_seconds > 0.0 && explored % 4096 == 0) {
            const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
            return elapsed.count() >= budget.max_seconds;
        }
        return false;
    };
    auto conflicts = [&](std::uint32_t candidate) {
        for (const MaskWord& m : prepared[candidate].mask)
            if (covered[m.word] & m.bits) return true;
        return false;
    };

    // Algorithm 2 starts two branches, RecB&B(0, 0) and RecB&B(0, 1). Algorithm 3 is run with an explicit
    // stack of frames so that thousands of candidates cannot overflow the call stack; the order in which
    // search nodes are visited, and so the count, is the recursive one.
    std::vector<Frame> frames;
    frames.reserve(static_cast<std::size_t>(candidate_count) + 2);
    auto enter = [&](std::uint32_t current, bool select) { frames.push_back({current, select, false, 0, 0.0, 0.0}); };
    if (candidate_count > 0 || node_count == 0) {
        enter(0, true);
        enter(0, false);  // on top: the survey explores the 0-branch first
    } else {
        enter(0, false);  // no candidates: one visit checks whether the empty stack already covers
    }

    while (!frames.empty()) {
        Frame& frame = frames.back();
        if (frame.stage == 0) {
            // Lines 3.1-3.6: register a better exact cover. Conflicts are rejected before a push, so the
            // stack is always disjoint and "covers" means every node is covered.
            ++explored;
            if (covered_count == node_count && cost_so_far < best_cost) {
                best_cost = cost_so_far;
                best = stack;
            }
            if (out_of_budget()) {
                budget_hit = true;
                break;
            }
            // Lines 3.7-3.9: no candidates left to decide.
            if (frame.current >= candidate_count) {
                frames.pop_back();
                continue;
            }
            // Lines 3.10-3.13: Eq. 7 bound; prune only when strictly worse than the best (as the survey).
            const double bound = cost_so_far + 2.0 * uncovered_volume;
            if (best_cost < bound) {
                frames.pop_back();
                continue;
            }
            // Lines 3.18-3.23: select candidate `current` unless it overlaps the stack.
            if (frame.select) {
                if (conflicts(frame.current)) {
                    frames.pop_back();
                    continue;
                }
                const PreparedCandidate& chosen = prepared[frame.current];
                frame.pushed = true;
                frame.saved_cost = cost_so_far;
                frame.saved_uncovered = uncovered_volume;
                for (const MaskWord& m : chosen.mask) covered[m.word] |= m.bits;
                covered_count += chosen.member_count;
                cost_so_far += candidates[frame.current].cost;
                uncovered_volume -= chosen.member_volume;
                stack.push_back(frame.current);
            }
            // Lines 3.15-3.16 / 3.24-3.25: first the 0-branch, then the 1-branch of the next candidate.
            frame.stage = 1;
            const std::uint32_t next = frame.current + 1;
            enter(next, false);
            continue;
        }
        if (frame.stage == 1) {
            frame.stage = 2;
            const std::uint32_t next = frame.current + 1;
            enter(next, true);
            continue;
        }
        // Line 3.26: pop the candidate this frame pushed.
        if (frame.pushed) {
            const PreparedCandidate& chosen = prepared[frame.current];
            for (const MaskWord& m : chosen.mask) covered[m.word] &= ~m.bits;
            covered_count -= chosen.member_count;
            cost_so_far = frame.saved_cost;
            uncovered_volume = frame.saved_uncovered;
            stack.pop_back();
        }
        frames.pop_back();
    }

    if (!best) return std::nullopt;
    Partition partition;
    partition.chosen = std::move(*best);
    std::sort(partition.chosen.begin(), partition.chosen.end());
    partition.cost = best_cost;
    partition.nodes_explored = explored;
    partition.budget_hit = budget_hit;
    // Only a complete search under an admissible bound proves optimality; otherwise report a bound that
    // always holds (see docs/algorithms.md for an instance where Eq. 7 prunes the optimum).
    const bool proven = !budget_hit && eq7_is_admissible(candidates, node_volumes);
    partition.lower_bound = proven ? best_cost : std::min(best_cost, per_node_lower_bound(node_count, candidates));
    return partition;
}

}  // namespace hbvh
