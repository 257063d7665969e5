// SPDX-License-Identifier: MIT
#include "hbvh/build/build.hpp"

#include <array>

#include "hbvh/build/optimal.hpp"
#include "hbvh/build/two_level.hpp"

namespace hbvh {
namespace {
constexpr std::array registry{
    AlgorithmInfo{Algorithm::two_level, "two-level", "the survey's baseline: one root BV (best allowed type) over all primitives"},
    AlgorithmInfo{Algorithm::bnb_tightest, "bnb-tightest", "the survey's B&B-Tightest: per level, Eq. 1 tightest-growth candidates + branch and bound"},
    AlgorithmInfo{Algorithm::bnb_enlarge, "bnb-enlarge", "the survey's B&B-Enlarge: per level, 5 % enlargement candidates + branch and bound"},
    AlgorithmInfo{Algorithm::bnb_exact, "bnb-exact", "bottom-up levels, Tightest+Enlarge+kNN candidates, exact set partition; never worse than bnb-enlarge"},
    AlgorithmInfo{Algorithm::optimal, "optimal", "globally optimal Eq. 2 hierarchy by subset DP; at most 18 primitives by default"},
};
}  // namespace

std::span<const AlgorithmInfo> algorithms() { return registry; }

std::optional<Algorithm> parse_algorithm(std::string_view name) {
    for (const AlgorithmInfo& info : registry)
        if (info.name == name) return info.algorithm;
    return std::nullopt;
}

std::string_view to_string(Algorithm algorithm) {
    for (const AlgorithmInfo& info : registry)
        if (info.algorithm == algorithm) return info.name;
    return "unknown";
}

Result<Bvh> build(std::span<const Primitive> primitives, Algorithm algorithm, const BuildOptions& options) {
    if (primitives.empty()) return Error{"no primitives to build a hierarchy over", "", 0};
    switch (algorithm) {
        case Algorithm::two_level: return build_two_level(primitives, options.policy);
        case Algorithm::bnb_tightest:
            return build_bnb_tightest(primitives, options.policy, options.branch_and_bound, options.report);
        case Algorithm::bnb_enlarge:
            return build_bnb_enlarge(primitives, options.policy, options.branch_and_bound, options.report);
        case Algorithm::bnb_exact: return build_bnb_exact(primitives, options.policy, options.bnb_exact, options.report);
        case Algorithm::optimal: return build_optimal(primitives, options.policy, options.optimal, options.report);
    }
    return Error{"unknown algorithm", "", 0};
}

}  // namespace hbvh
