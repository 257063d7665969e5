// SPDX-License-Identifier: MIT
// The survey's level-by-level bottom-up driver (§3, Appendix A Algorithm 1), with the candidate heuristic
// and the set-partition solver plugged in, so that better heuristics and solvers reuse the same loop.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <vector>

#include "guarded_build.hpp"
#include "hbvh/builders/report.hpp"
#include "set_partition.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// One node of the level being merged: a primitive on the first level, a chosen group above it.
struct LevelNode {
    BoundingVolume volume;                  ///< The node's BV (the primitive's own, or the group's fitted BV).
    double weighted_volume = 0.0;           ///< policy.weighted_volume(volume): Eq. 1's and Eq. 7's volume(n).
    std::vector<std::uint32_t> primitives;  ///< Covered input primitive indices, in canonical (not index) order.
};

/// The BV fitted around every primitive a set of nodes covers, and its weighted volume.
struct FittedGroup {
    BoundingVolume volume;
    double weighted_volume = 0.0;
};

/// A level of the bottom-up build: its nodes in canonical order (docs/algorithms.md: sorted by the centre
/// of their world AABB, then volume, so that node indices do not depend on the input order) and a memo of
/// fitted groups shared by the candidate heuristic and the candidate costs. The memo makes const calls
/// mutate: one Level must not be used from several threads at once.
class Level {
public:
    /// `nodes` must already be in canonical order (build_bottom_up sorts them); `primitives` is the input.
    Level(std::span<const Primitive> primitives, std::vector<LevelNode> nodes, const VolumePolicy& policy);

    [[nodiscard]] std::span<const LevelNode> nodes() const { return nodes_; }
    [[nodiscard]] std::uint32_t size() const { return static_cast<std::uint32_t>(nodes_.size()); }
    [[nodiscard]] const VolumePolicy& policy() const { return policy_; }
    [[nodiscard]] std::span<const Primitive> primitives() const { return primitives_; }
    /// World AABB around every node of the level.
    [[nodiscard]] const Aabb& bounds() const { return bounds_; }

    /// fit_best over the generating spheres of ALL primitives the `members` cover (not over the members'
    /// BVs, which would only be looser), memoised per member set. `members`: ascending node indices,
    /// non-empty. The reference stays valid for the lifetime of the Level.
    [[nodiscard]] const FittedGroup& fit_group(std::span<const std::uint32_t> members) const;
    /// Eq. 2's share of a merging candidate: |members| x the fitted group's weighted volume (§3).
    [[nodiscard]] double candidate_cost(std::span<const std::uint32_t> members) const;
    /// Eq. 1 for merging `members`: fitted weighted volume / sum of the members' weighted volumes. Members
    /// with zero total volume (points, flat boxes) give +inf unless the group is also of zero volume (1).
    [[nodiscard]] double tightness(std::span<const std::uint32_t> members) const;
    /// Number of distinct groups fitted so far.
    [[nodiscard]] std::size_t fitted_count() const { return fitted_.size(); }
    /// From now on, a fit_group that would fit a new group after `deadline` throws LevelDeadlinePassed instead:
    /// the survey's candidate heuristics fit O(n^2) groups a level, minutes at 900 nodes, and the deadline is
    /// otherwise seen only between levels. time_point::max(): never (the default).
    void stop_fitting_after(std::chrono::steady_clock::time_point deadline) { deadline_ = deadline; }
    /// Throws LevelDeadlinePassed once stop_fitting_after's deadline has passed: for the heuristics' loops that
    /// fit nothing (B&B-Enlarge's growth tests every pair of nodes, seconds at 2000 nodes and minutes at 20 000).
    void check_deadline() const;

private:
    std::span<const Primitive> primitives_;
    std::vector<LevelNode> nodes_;
    VolumePolicy policy_;
    Aabb bounds_;
    mutable std::map<std::vector<std::uint32_t>, FittedGroup> fitted_;
    std::chrono::steady_clock::time_point deadline_ = std::chrono::steady_clock::time_point::max();
};

/// Thrown by Level::fit_group past the deadline set by stop_fitting_after.
struct LevelDeadlinePassed {};

/// A candidate heuristic: member sets (node indices of `level`) to offer the solver. Sets may come in any
/// order, unsorted or repeated; the driver normalises them, drops singletons and duplicates, and prices them.
using CandidateGenerator = std::function<std::vector<std::vector<std::uint32_t>>(const Level& level)>;

/// A set-partition solver with the shape of solve_reference_branch_and_bound / solve_exact.
using LevelSolver = std::function<std::optional<Partition>(std::uint32_t node_count,
                                                           std::span<const Candidate> candidates,
                                                           std::span<const double> node_volumes,
                                                           const SolverBudget& budget)>;

/// The survey's reference solver as a LevelSolver.
[[nodiscard]] LevelSolver reference_level_solver();

/// Turns member sets into the solver's candidate list: each set sorted and deduplicated, singletons and
/// repeated sets dropped, then ordered by (size, members lexicographically) and priced with
/// Level::candidate_cost. The order is a function of the level alone, never of the input order.
[[nodiscard]] std::vector<Candidate> make_candidates(const Level& level,
                                                     std::vector<std::vector<std::uint32_t>> member_sets);

/// Candidates added when a level's candidates admit no exact cover: for every node, its first two growth
/// steps by the Tightest rule (the partner with the smallest Eq. 1 tightness, then the best third).
[[nodiscard]] std::vector<std::vector<std::uint32_t>> fallback_member_sets(const Level& level);

/// Options of the generic driver.
struct BottomUpOptions {
    SolverBudget budget;             ///< Per solver call (each level, each fallback stage).
    BuildReport* report = nullptr;   ///< Filled (levels appended) when non-null.
    /// Between levels: progress, and the deadline — once it has passed, one root over the nodes left (the
    /// levels built so far are kept). Null: neither.
    const detail::Checkpoint* checkpoint = nullptr;
};

/// Algorithm 1: merge the primitives level by level until one node remains. On each level `generate`
/// proposes candidates, `solve` picks an exact cover, and every chosen group becomes a node of the next
/// level with the BV fitted around its primitives. Never fails: without an exact cover (or when the budget
/// runs out before one is found) it falls back as docs/algorithms.md describes and sets
/// LevelReport::fallback_used. Every group has >= 2 children. Precondition: primitives non-empty.
[[nodiscard]] Bvh build_bottom_up(std::span<const Primitive> primitives, const VolumePolicy& policy,
                                  const CandidateGenerator& generate, const LevelSolver& solve,
                                  const BottomUpOptions& options = {});

}  // namespace hbvh
