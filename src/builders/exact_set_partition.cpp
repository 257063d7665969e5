// SPDX-License-Identifier: MIT
// solve_exact: a provably optimal solver for the set-partition problem of the survey's §3 (Eqs. 4-6).
//
// Exact-cover search in the style of Knuth's Algorithm X ("Dancing Links", 2000): every uncovered node
// must be covered by exactly one chosen candidate, so branching on the candidates of ONE uncovered node
// is complete, and picking the node with the fewest compatible candidates keeps the tree narrow.
// Bounding (docs/solver.md §1): a candidate c can be charged to its members as cost(c)/|c| each, so any
// completion pays at least, for each uncovered node, the cheapest share among the candidates still
// compatible with the partial solution. The survey's §6.1 asks for an initial cost guess; we start from
// a greedy cover improved by a large-neighbourhood local search (re-solving the union of one or two
// chosen groups exactly), so pruning works from the first search node.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "hbvh/assert.hpp"
#include "set_partition.hpp"

namespace hbvh {
namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();

/// One instance, in the solver's own layout: flat member lists, per-node candidate lists by share.
struct Instance {
    std::uint32_t node_count = 0;
    std::vector<double> cost;                    // per candidate
    std::vector<double> share;                   // cost / |members|
    std::vector<std::uint32_t> member_begin;     // members of c: members[member_begin[c], member_begin[c+1])
    std::vector<std::uint32_t> members;
    std::vector<std::uint32_t> node_begin;       // candidates of j: by_node[node_begin[j], node_begin[j+1])
    std::vector<std::uint32_t> by_node;          // sorted by (share, index): cheapest share first

    [[nodiscard]] std::uint32_t candidate_count() const { return static_cast<std::uint32_t>(cost.size()); }
    [[nodiscard]] std::span<const std::uint32_t> members_of(std::uint32_t c) const {
        return {members.data() + member_begin[c], member_begin[c + 1] - member_begin[c]};
    }
    [[nodiscard]] std::span<const std::uint32_t> candidates_of(std::uint32_t j) const {
        return {by_node.data() + node_begin[j], node_begin[j + 1] - node_begin[j]};
    }
};

/// Builds the layout from the caller's candidates. `ids` are the caller's indices of the kept
/// candidates (empty member lists are dropped: they cover nothing and only add cost).
Instance make_instance(std::uint32_t node_count, std::span<const Candidate> candidates,
                       std::vector<std::uint32_t>& ids) {
    Instance in;
    in.node_count = node_count;
    in.member_begin.push_back(0);
    std::vector<std::uint32_t> degree(node_count, 0);
    for (std::uint32_t i = 0; i < candidates.size(); ++i) {
        const Candidate& c = candidates[i];
        if (c.members.empty()) continue;
        for (std::size_t k = 0; k < c.members.size(); ++k) {
            HBVH_ASSERT(c.members[k] < node_count);
            HBVH_ASSERT(k == 0 || c.members[k - 1] < c.members[k]);
            ++degree[c.members[k]];
        }
        ids.push_back(i);
        in.cost.push_back(c.cost);
        in.share.push_back(c.cost / static_cast<double>(c.members.size()));
        in.members.insert(in.members.end(), c.members.begin(), c.members.end());
        in.member_begin.push_back(static_cast<std::uint32_t>(in.members.size()));
    }
    in.node_begin.assign(node_count + 1, 0);
    for (std::uint32_t j = 0; j < node_count; ++j) in.node_begin[j + 1] = in.node_begin[j] + degree[j];
    in.by_node.resize(in.node_begin[node_count]);
    std::vector<std::uint32_t> fill(in.node_begin.begin(), in.node_begin.end() - 1);
    for (std::uint32_t c = 0; c < in.candidate_count(); ++c)
        for (std::uint32_t j : in.members_of(c)) in.by_node[fill[j]++] = c;
    for (std::uint32_t j = 0; j < node_count; ++j)
        std::stable_sort(in.by_node.begin() + in.node_begin[j], in.by_node.begin() + in.node_begin[j + 1],
                         [&](std::uint32_t a, std::uint32_t b) { return in.share[a] < in.share[b]; });
    return in;
}

/// The branch-and-bound search over one Instance. Candidate indices are the Instance's own.
class Search {
public:
    Search(const Instance& instance, const SolverBudget& budget)
        : in_(instance), budget_(budget), covered_(instance.node_count, 0), blocked_(instance.candidate_count(), 0),
          alive_count_(instance.node_count, 0), words_((instance.node_count + 63) / 64, 0),
          zobrist_(instance.node_count), start_(std::chrono::steady_clock::now()) {
        for (std::uint32_t j = 0; j < in_.node_count; ++j)
            alive_count_[j] = static_cast<std::uint32_t>(in_.candidates_of(j).size());
        uncovered_ = in_.node_count;
        // Fixed keys (not seeded by time), so the search is reproducible.
        std::uint64_t state = 0x2545f4914f6cdd1dULL;
        for (std::uint64_t& key : zobrist_) {
            state += 0x9e3779b97f4a7c15ULL;
            std::uint64_t z = state;
            z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
            z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
            key = z ^ (z >> 31);
        }
    }

    /// Seeds the incumbent (an upper bound) with a known cover.
    void set_incumbent(std::vector<std::uint32_t> chosen, double cost) {
        if (cost < best_cost_) {
            best_cost_ = cost;
            best_ = std::move(chosen);
        }
    }

    /// Runs the search. Afterwards: best(), best_cost(), nodes(), budget_hit(), lower_bound().
    void run() {
        root_bound_ = bound();
        open_bound_ = infinity;
        descend(0.0);
        if (!budget_hit_) open_bound_ = infinity;
    }

    [[nodiscard]] const std::vector<std::uint32_t>& best() const { return best_; }
    [[nodiscard]] double best_cost() const { return best_cost_; }
    [[nodiscard]] std::uint64_t nodes() const { return nodes_; }
    [[nodiscard]] bool budget_hit() const { return budget_hit_; }
    /// Proven lower bound on the optimum: the incumbent when the search finished, otherwise the
    /// smallest bound of a subtree left unexplored.
    [[nodiscard]] double lower_bound() const {
        if (!budget_hit_) return best_cost_;
        return std::min(best_cost_, std::max(root_bound_, open_bound_));
    }

private:
    /// Cheapest share among j's candidates that are still compatible (infinity if none).
    [[nodiscard]] double min_share(std::uint32_t j) const {
        for (std::uint32_t c : in_.candidates_of(j))
            if (blocked_[c] == 0) return in_.share[c];
        return infinity;
    }

    /// The per-node lower bound on the cost of covering every uncovered node (docs/solver.md §1).
    [[nodiscard]] double bound() const {
        double sum = 0.0;
        for (std::uint32_t j = 0; j < in_.node_count; ++j)
            if (!covered_[j]) sum += min_share(j);
        return sum;
    }

    [[nodiscard]] bool out_of_budget() {
        if (budget_.max_nodes != 0 && nodes_ >= budget_.max_nodes) return true;
        if (budget_.max_seconds > 0.0 && (nodes_ & 255u) == 0) {
            const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start_;
            if (elapsed.count() >= budget_.max_seconds) return true;
        }
        return false;
    }

    /// Choose candidate c: cover its members and block every candidate that shares a member.
    void select(std::uint32_t c) {
        for (std::uint32_t j : in_.members_of(c)) {
            covered_[j] = 1;
            words_[j / 64] |= std::uint64_t{1} << (j % 64);
            hash_ ^= zobrist_[j];
            --uncovered_;
            for (std::uint32_t d : in_.candidates_of(j))
                if (blocked_[d]++ == 0)
                    for (std::uint32_t k : in_.members_of(d)) --alive_count_[k];
        }
        chosen_.push_back(c);
    }

    /// Exact inverse of select(c).
    void unselect(std::uint32_t c) {
        chosen_.pop_back();
        const auto ms = in_.members_of(c);
        for (auto it = ms.rbegin(); it != ms.rend(); ++it) {
            const std::uint32_t j = *it;
            for (std::uint32_t d : in_.candidates_of(j))
                if (--blocked_[d] == 0)
                    for (std::uint32_t k : in_.members_of(d)) ++alive_count_[k];
            covered_[j] = 0;
            words_[j / 64] &= ~(std::uint64_t{1} << (j % 64));
            hash_ ^= zobrist_[j];
            ++uncovered_;
        }
    }

    void descend(double cost_so_far) {
        if (budget_hit_) return;
        if (out_of_budget()) {
            budget_hit_ = true;
            open_bound_ = std::min(open_bound_, cost_so_far + bound());
            return;
        }
        ++nodes_;
        if (uncovered_ == 0) {
            if (cost_so_far < best_cost_) {
                best_cost_ = cost_so_far;
                best_ = chosen_;
            }
            return;
        }
        // Branching node: the uncovered node with the fewest compatible candidates (Knuth's "S heuristic");
        // ties go to the lowest index, so the search is deterministic.
        std::uint32_t branch = 0;
        std::uint32_t fewest = std::numeric_limits<std::uint32_t>::max();
        double rest = 0.0;
        for (std::uint32_t j = 0; j < in_.node_count; ++j) {
            if (covered_[j]) continue;
            if (alive_count_[j] == 0) return;  // j can no longer be covered: dead end.
            if (alive_count_[j] < fewest) {
                fewest = alive_count_[j];
                branch = j;
            }
            rest += min_share(j);
        }
        if (cost_so_far + rest >= best_cost_) return;
        // Transposition table: different partial solutions often leave the same nodes uncovered (e.g.
        // {a,b},{c,d} and {a,c},{b,d}); a completion bound proven for that set before prunes here too.
        const std::uint32_t memo = find_memo();
        if (memo != no_memo && cost_so_far + memo_bound_[memo] >= best_cost_) return;
        const double best_at_entry = best_cost_;

        // Children cheapest share first. Before descending, a weaker bound that needs no update already
        // prunes many: after choosing c, the other uncovered nodes' shares can only grow, so
        // rest - (the shares c's members had) + cost(c) is still a lower bound.
        const auto options = in_.candidates_of(branch);
        for (std::size_t i = 0; i < options.size(); ++i) {
            const std::uint32_t c = options[i];
            if (blocked_[c] != 0) continue;
            double released = 0.0;
            for (std::uint32_t j : in_.members_of(c)) released += min_share(j);
            const double child_bound = cost_so_far + in_.cost[c] + (rest - released);
            if (child_bound >= best_cost_) continue;
            if (budget_hit_) {
                // Unwinding after the budget ran out: remember how good the unexplored children could be.
                open_bound_ = std::min(open_bound_, child_bound);
                continue;
            }
            select(c);
            descend(cost_so_far + in_.cost[c]);
            unselect(c);
        }
        // Searched to the end: every completion of this set costs at least min(incumbent) - cost so far,
        // because the search only discards what cannot beat the incumbent, and an improvement found here
        // is the best completion (infinity: no completion exists). Not after a budget stop.
        if (!budget_hit_) store_memo(memo, std::min(best_at_entry, best_cost_) - cost_so_far);
    }

    static constexpr std::uint32_t no_memo = std::numeric_limits<std::uint32_t>::max();

    /// The table entry for the current covered set, or no_memo. Keys are verified word by word, so a
    /// hash collision can never lend a bound to the wrong set.
    [[nodiscard]] std::uint32_t find_memo() const {
        const auto it = memo_index_.find(hash_);
        if (it == memo_index_.end()) return no_memo;
        const std::size_t stride = words_.size();
        if (!std::equal(words_.begin(), words_.end(), memo_keys_.begin() + static_cast<std::ptrdiff_t>(it->second * stride)))
            return no_memo;
        return it->second;
    }

    void store_memo(std::uint32_t memo, double bound) {
        if (memo != no_memo) {
            memo_bound_[memo] = std::max(memo_bound_[memo], bound);
            return;
        }
        if (memo_bound_.size() >= memo_capacity || memo_index_.count(hash_) != 0) return;
        const auto index = static_cast<std::uint32_t>(memo_bound_.size());
        memo_index_.emplace(hash_, index);
        memo_keys_.insert(memo_keys_.end(), words_.begin(), words_.end());
        memo_bound_.push_back(bound);
    }

    const Instance& in_;
    SolverBudget budget_;
    std::vector<char> covered_;
    std::vector<std::uint32_t> blocked_;      // chosen candidates sharing a member with this one
    std::vector<std::uint32_t> alive_count_;  // compatible candidates containing this node
    std::uint32_t uncovered_ = 0;
    std::vector<std::uint64_t> words_;         // covered set as a growable bitset (the memo key)
    std::vector<std::uint64_t> zobrist_;       // per-node random keys; hash_ = XOR over covered nodes
    std::uint64_t hash_ = 0;
    static constexpr std::size_t memo_capacity = 1u << 20;  // entries; bounds memory to ~tens of MB
    std::unordered_map<std::uint64_t, std::uint32_t> memo_index_;
    std::vector<std::uint64_t> memo_keys_;
    std::vector<double> memo_bound_;
    std::vector<std::uint32_t> chosen_;
    std::vector<std::uint32_t> best_;
    double best_cost_ = infinity;
    double root_bound_ = 0.0;
    double open_bound_ = infinity;
    std::uint64_t nodes_ = 0;
    bool budget_hit_ = false;
    std::chrono::steady_clock::time_point start_;
};

/// Greedy cover: candidates by ascending share (then index), each taken when it is compatible.
/// Returns an empty vector when the greedy choice gets stuck before covering every node.
std::vector<std::uint32_t> greedy_cover(const Instance& in) {
    std::vector<std::uint32_t> order(in.candidate_count());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return in.share[a] < in.share[b]; });
    std::vector<char> covered(in.node_count, 0);
    std::uint32_t remaining = in.node_count;
    std::vector<std::uint32_t> chosen;
    for (std::uint32_t c : order) {
        const auto ms = in.members_of(c);
        if (std::any_of(ms.begin(), ms.end(), [&](std::uint32_t j) { return covered[j] != 0; })) continue;
        for (std::uint32_t j : ms) covered[j] = 1;
        remaining -= static_cast<std::uint32_t>(ms.size());
        chosen.push_back(c);
        if (remaining == 0) return chosen;
    }
    return {};
}

/// Large-neighbourhood local search: for each chosen group, and each pair of chosen groups that some
/// other candidate straddles, re-cover the union of their members optimally with the candidates lying
/// inside it (a small exact sub-search). Repeats while it improves, at most `rounds` times.
void improve_locally(const Instance& in, std::vector<std::uint32_t>& chosen, int rounds) {
    std::vector<std::uint32_t> owner(in.node_count);  // node -> position in `chosen`
    std::vector<char> in_region(in.node_count, 0);
    for (int round = 0; round < rounds; ++round) {
        for (std::uint32_t p = 0; p < chosen.size(); ++p)
            for (std::uint32_t j : in.members_of(chosen[p])) owner[j] = p;
        // Neighbourhoods: {p} for each group, {p, q} for groups straddled by a single candidate.
        std::vector<std::pair<std::uint32_t, std::uint32_t>> regions;
        for (std::uint32_t p = 0; p < chosen.size(); ++p) regions.emplace_back(p, p);
        for (std::uint32_t c = 0; c < in.candidate_count(); ++c) {
            std::uint32_t first = owner[in.members_of(c).front()];
            std::uint32_t second = first;
            bool too_many = false;
            for (std::uint32_t j : in.members_of(c)) {
                const std::uint32_t o = owner[j];
                if (o == first || o == second) continue;
                if (second == first) second = o;
                else too_many = true;
            }
            if (!too_many && second != first) regions.emplace_back(std::min(first, second), std::max(first, second));
        }
        std::sort(regions.begin(), regions.end());
        regions.erase(std::unique(regions.begin(), regions.end()), regions.end());

        bool improved = false;
        std::vector<char> retired(chosen.size(), 0);  // groups already replaced this round
        std::vector<std::uint32_t> next;
        for (const auto& [p, q] : regions) {
            if (retired[p] || retired[q]) continue;
            // The sub-instance: nodes of the region renumbered 0.., candidates lying entirely inside.
            std::vector<std::uint32_t> nodes;
            for (std::uint32_t j : in.members_of(chosen[p])) nodes.push_back(j);
            if (q != p)
                for (std::uint32_t j : in.members_of(chosen[q])) nodes.push_back(j);
            std::sort(nodes.begin(), nodes.end());
            for (std::uint32_t j : nodes) in_region[j] = 1;
            std::vector<Candidate> local;
            std::vector<std::uint32_t> local_ids;
            for (std::uint32_t j : nodes)
                for (std::uint32_t c : in.candidates_of(j)) {
                    const auto ms = in.members_of(c);
                    if (ms.front() != j) continue;  // visit each candidate once, from its first member
                    if (!std::all_of(ms.begin(), ms.end(), [&](std::uint32_t k) { return in_region[k] != 0; }))
                        continue;
                    Candidate local_candidate;
                    local_candidate.cost = in.cost[c];
                    for (std::uint32_t k : ms)
                        local_candidate.members.push_back(static_cast<std::uint32_t>(
                            std::lower_bound(nodes.begin(), nodes.end(), k) - nodes.begin()));
                    local.push_back(std::move(local_candidate));
                    local_ids.push_back(c);
                }
            for (std::uint32_t j : nodes) in_region[j] = 0;
            const double current = in.cost[chosen[p]] + (q != p ? in.cost[chosen[q]] : 0.0);
            std::vector<std::uint32_t> ignored;
            const Instance sub = make_instance(static_cast<std::uint32_t>(nodes.size()), local, ignored);
            Search search(sub, SolverBudget{10000, 0.0});
            search.run();
            if (search.best().empty() || !(search.best_cost() < current)) continue;
            retired[p] = retired[q] = 1;
            for (std::uint32_t c : search.best()) next.push_back(local_ids[c]);
            improved = true;
        }
        if (!improved) return;
        for (std::uint32_t p = 0; p < chosen.size(); ++p)
            if (!retired[p]) next.push_back(chosen[p]);
        chosen = std::move(next);
    }
}

double total_cost(const Instance& in, std::span<const std::uint32_t> chosen) {
    double sum = 0.0;
    for (std::uint32_t c : chosen) sum += in.cost[c];
    return sum;
}

}  // namespace

std::optional<Partition> solve_exact(std::uint32_t node_count, std::span<const Candidate> candidates,
                                     const SolverBudget& budget) {
    // Stage 1: the solver's layout.
    std::vector<std::uint32_t> ids;
    const Instance in = make_instance(node_count, candidates, ids);

    // Stage 2: an initial upper bound (survey §6.1), greedy then local search.
    Search search(in, budget);
    std::vector<std::uint32_t> start = greedy_cover(in);
    if (!start.empty() || node_count == 0) {
        improve_locally(in, start, 4);
        const double start_cost = total_cost(in, start);
        search.set_incumbent(std::move(start), start_cost);
    }

    // Stage 3: branch and bound; the incumbent is optimal when it finishes within budget.
    search.run();
    if (search.best().empty() && node_count != 0) return std::nullopt;

    Partition result;
    for (std::uint32_t c : search.best()) result.chosen.push_back(ids[c]);
    std::sort(result.chosen.begin(), result.chosen.end());
    // Sum in the caller's order so equal partitions give bit-identical costs however they were found.
    for (std::uint32_t c : result.chosen) result.cost += candidates[c].cost;
    result.nodes_explored = search.nodes();
    result.budget_hit = search.budget_hit();
    result.lower_bound = result.budget_hit ? std::min(result.cost, search.lower_bound()) : result.cost;
    return result;
}

}  // namespace hbvh
