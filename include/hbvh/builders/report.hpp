// SPDX-License-Identifier: MIT
// BuildReport: what a builder did, level by level, for `hbvh build --report` and `hbvh compare`.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace hbvh {

/// One merged level of a bottom-up builder (or one phase of another builder).
struct LevelReport {
    std::uint32_t nodes = 0;            ///< Nodes on the level before merging.
    std::uint32_t candidates = 0;       ///< Merging candidates (the survey's MC).
    std::uint64_t solver_nodes = 0;     ///< Search-tree nodes the set-partition solver explored.
    std::uint32_t groups = 0;           ///< Groups chosen (nodes on the next level).
    double seconds = 0.0;
    bool fallback_used = false;         ///< The candidates admitted no exact cover; see docs/algorithms.md.
    bool budget_hit = false;            ///< The solver stopped at its node/time budget; best found is used.
};

struct BuildReport {
    std::vector<LevelReport> levels;
    std::uint32_t total_candidates = 0;
    bool budget_hit = false;            ///< Any level hit its budget.
    /// Proven lower bound on the cost of every tree whose inner volumes are fit_best's over what they cover, where
    /// the builder knows one (else 0). Volumes fitted otherwise can make a cheaper tree (docs/solver.md §2).
    double lower_bound = 0.0;
    std::vector<std::string> notes;     ///< Free-form remarks (fallbacks, choices made by `auto`).
    /// The registry name of the builder whose tree was returned when it is not the one asked for (`optimal`
    /// above its primitive limit returns bnb-exact's); empty otherwise.
    std::string built_by;
    /// Why, when built_by is set: one sentence the CLI prints as a warning and Python raises as a UserWarning, so
    /// that a substituted tree is never silent (it is among the notes too).
    std::string substitution;
    /// The first note of a builder the time limit stopped (BuildContext::note_deadline), empty when none was: the
    /// tree returned is the best found by then. Python warns with it, as it does for `substitution`.
    std::string time_limit;
};

}  // namespace hbvh
