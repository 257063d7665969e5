// SPDX-License-Identifier: MIT
// B&B-Tightest and B&B-Enlarge: the survey's heuristics plugged into the bottom-up driver (§3).
#include "hbvh/build/branch_and_bound.hpp"

namespace hbvh {
namespace {
Bvh build_with(std::span<const Primitive> primitives, const VolumePolicy& policy, const CandidateGenerator& generate,
               const BranchAndBoundOptions& options, BuildReport* report) {
    const LevelSolver solver = options.solver ? options.solver : reference_level_solver();
    return build_bottom_up(primitives, policy, generate, solver, {options.budget, report});
}
}  // namespace

Bvh build_bnb_tightest(std::span<const Primitive> primitives, const VolumePolicy& policy,
                       const BranchAndBoundOptions& options, BuildReport* report) {
    return build_with(primitives, policy, tightest_candidates, options, report);
}

Bvh build_bnb_enlarge(std::span<const Primitive> primitives, const VolumePolicy& policy,
                      const BranchAndBoundOptions& options, BuildReport* report) {
    const EnlargeOptions enlarge = options.enlarge;
    return build_with(primitives, policy, [enlarge](const Level& level) { return enlarge_candidates(level, enlarge); },
                      options, report);
}

}  // namespace hbvh
