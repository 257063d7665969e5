// SPDX-License-Identifier: MIT
// The survey's B&B-Tightest (§3): bottom-up levels whose merging candidates are the groups of tightest Eq. 1
// growth, and a set partition per level by the survey's branch and bound.
#pragma once

#include <span>

#include "hbvh/builders/budget.hpp"
#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_bnb_tightest.
struct BnbTightestOptions {
    /// Per solver call (one per level, one more per fallback); deterministic, like BnbEnlargeOptions'.
    SolverBudget budget{1'000'000, 0.0};
};

/// B&B-Tightest. Deadline: checked between levels.
[[nodiscard]] Result<Bvh> build_bnb_tightest(std::span<const Primitive> primitives, const BuildContext& context,
                                             const BnbTightestOptions& options = {});

}  // namespace hbvh
