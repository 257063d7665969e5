// SPDX-License-Identifier: MIT
// Goldsmith and Salmon's incremental insertion (survey §2.1): primitives enter one at a time at the cheapest place.
#pragma once

#include <span>

#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_insertion.
struct InsertionOptions {
    /// 0: no cap. Otherwise the exact refits may fit this many primitives in all (summed over every refit); past
    /// that the build stops and returns the two-level tree, noted in the report with budget_hit. Input sorted
    /// along a line makes the insertion a chain and its refits cubic in n (a rope of 200 capsules: 1.6 s); auto
    /// caps its insertion members at auto_insertion_refit_budget(n), far above what any other input needed.
    std::uint64_t max_refit_primitives = 0;
};

/// Inserts the primitives in input order. Each one descends a single path from the root, at every group
/// g pricing, as an increase of Eq. 2, rule 1 (p becomes a child of g) and rule 2 (p and a child p' of g
/// form a new group under g), then follows rule 3 into the child group whose own Eq. 2 term grows least
/// (ties: nearest centre). The cheapest rule seen on the path wins (Haines' refinement). Candidate
/// volumes are estimated by fit_best around the node's BV and p; after the insertion every BV on the
/// path is refit exactly (fit_best over the covered primitives). The result depends on input order,
/// as the survey notes. Deadline: checked between insertions; the refit cap at every refit.
[[nodiscard]] Result<Bvh> build_insertion(std::span<const Primitive> primitives, const BuildContext& context,
                                          const InsertionOptions& options = {});

}  // namespace hbvh
