// SPDX-License-Identifier: MIT
// The survey's two builders, B&B-Tightest and B&B-Enlarge (§3): bottom_up.hpp's driver with the
// heuristics of candidates.hpp and, by default, the survey's reference branch and bound.
#pragma once

#include <span>
#include <string_view>

#include "bottom_up.hpp"
#include "candidates.hpp"
#include "hbvh/builders/context.hpp"
#include "hbvh/builders/report.hpp"
#include "hbvh/result.hpp"

namespace hbvh::detail {

/// The survey's Algorithm 1 with `generate`'s candidates and `solver` (empty: the survey's reference branch
/// and bound), `budget` per solver call: what bnb-tightest and bnb-enlarge share (and tests, with other
/// solvers). Deadline: between levels (the two-level tree once it passes).
[[nodiscard]] Result<Bvh> build_survey_bottom_up(std::span<const Primitive> primitives, const BuildContext& context,
                                                 std::string_view name, const CandidateGenerator& generate,
                                                 const LevelSolver& solver, const SolverBudget& budget);

}  // namespace hbvh::detail
