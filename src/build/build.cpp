// SPDX-License-Identifier: MIT
#include "hbvh/build/build.hpp"

#include <array>

#include "hbvh/build/optimal.hpp"
#include "hbvh/build/two_level.hpp"

namespace hbvh {
namespace {
constexpr std::array registry{
    AlgorithmInfo{Algorithm::two_level, "two-level", "the survey's baseline: one root BV (best allowed type) over all primitives"},
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
        case Algorithm::optimal: return build_optimal(primitives, options.policy, options.optimal, options.report);
    }
    return Error{"unknown algorithm", "", 0};
}

}  // namespace hbvh
