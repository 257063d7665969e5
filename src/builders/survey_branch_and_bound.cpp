// SPDX-License-Identifier: MIT
// B&B-Tightest and B&B-Enlarge: the survey's heuristics plugged into the bottom-up driver (§3).
#include "survey_branch_and_bound.hpp"

#include <algorithm>
#include <cmath>

#include "hbvh/builders/bnb_enlarge.hpp"
#include "hbvh/builders/bnb_tightest.hpp"

namespace hbvh {

Result<Bvh> detail::build_survey_bottom_up(std::span<const Primitive> primitives, const BuildContext& context,
                                           std::string_view name, const CandidateGenerator& generate,
                                           const LevelSolver& solver, const SolverBudget& budget) {
    return guarded_build(primitives, context, name, static_cast<double>(primitives.size()),
                         [&](const Checkpoint& checkpoint) {
                             const LevelSolver chosen = solver ? solver : reference_level_solver();
                             // The survey's exponential search gets a share of the time left per solver call
                             // (about 2 log2 n of them), so that levels finish with the best partition found.
                             SolverBudget within = budget;
                             if (context.has_deadline()) {
                                 const double calls = 2.0 * std::max(1.0, std::log2(static_cast<double>(primitives.size())));
                                 const double share = std::max(context.seconds_left(), 1e-9) / calls;
                                 within.max_seconds = within.max_seconds > 0.0 ? std::min(within.max_seconds, share) : share;
                             }
                             return build_bottom_up(primitives, context.policy, generate, chosen,
                                                    {within, context.report, &checkpoint});
                         });
}

Result<Bvh> build_bnb_tightest(std::span<const Primitive> primitives, const BuildContext& context,
                               const BnbTightestOptions& options) {
    return detail::build_survey_bottom_up(primitives, context, "bnb-tightest", tightest_candidates, {}, options.budget);
}

Result<Bvh> build_bnb_enlarge(std::span<const Primitive> primitives, const BuildContext& context,
                              const BnbEnlargeOptions& options) {
    const EnlargeOptions enlarge = options.enlarge;
    return detail::build_survey_bottom_up(
        primitives, context, "bnb-enlarge", [enlarge](const Level& level) { return enlarge_candidates(level, enlarge); },
        {}, options.budget);
}

}  // namespace hbvh
