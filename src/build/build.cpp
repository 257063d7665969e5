// SPDX-License-Identifier: MIT
#include "hbvh/build/build.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

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
    AlgorithmInfo{Algorithm::merge, "merge", "OpenTissue bottom-up merge: collapse cheapest edges of an enlarged-overlap graph (survey 2.3)"},
    AlgorithmInfo{Algorithm::insertion, "insertion", "Goldsmith-Salmon incremental insertion in input order (survey 2.1)"},
    AlgorithmInfo{Algorithm::insertion_haber, "insertion-haber", "insertion with Haber et al.'s extra rule, re-insertion and ill-formed-group elimination (survey 2.1)"},
    AlgorithmInfo{Algorithm::split, "split", "Mueller et al. top-down split at the cheapest sorted cut on x, y or z (survey 2.2)"},
    AlgorithmInfo{Algorithm::obb_tree, "obbtree", "Gottschalk OBB-tree: split at the mean centre along the covariance OBB's longest axis (survey 2.2)"},
    AlgorithmInfo{Algorithm::scale, "scale", "10^3-10^6 primitives: bottom-up levels, kNN candidates, exact partition per Morton window, multi-threaded (docs/scale.md)"},
    AlgorithmInfo{Algorithm::automatic, "auto", "by size: optimal up to 10 primitives, bnb-exact up to 24, scale above (measured: docs/scale.md)"},
};

/// bnb-exact's options with a whole-build time limit spread over its solver calls: the levels number
/// about log2(n), and each level may call the solver twice (fallback).
ExactBottomUpOptions exact_options_within(const BuildOptions& options, std::size_t primitive_count) {
    ExactBottomUpOptions exact = options.bnb_exact;
    if (options.time_limit_seconds > 0.0) {
        const double calls = 2.0 * std::max(1.0, std::log2(static_cast<double>(primitive_count)));
        // Half of the time for bnb-exact's own search, half for the bnb-enlarge tree it compares with.
        exact.budget.max_seconds = 0.5 * options.time_limit_seconds / calls;
        exact.enlarge_options.budget.max_seconds = 0.5 * options.time_limit_seconds / calls;
    }
    return exact;
}

ScaleOptions scale_options_within(const BuildOptions& options) {
    ScaleOptions scale = options.scale;
    if (options.time_limit_seconds > 0.0) scale.time_limit_seconds = options.time_limit_seconds;
    if (options.progress) scale.progress = options.progress;
    return scale;
}

std::string range_message(const Vec3& extent, const char* problem) {
    char text[200];
    std::snprintf(text, sizeof text, "the primitives span %.3g x %.3g x %.3g: %s", extent.x(), extent.y(),
                  extent.z(), problem);
    return text;
}
}  // namespace

// Builders compare volumes of groups; once a volume overflows to infinity every choice ties and the exact
// searches lose their pruning (optimal ran for minutes on 1e150-sized input). A factor 8 above the box's
// own volume leaves room for the enlargements some builders try. Underflow is the mirror image: every
// volume rounds to zero and all trees cost the same. A box flat in some axis is fine (its volume is
// truly zero), so only a box of three positive extents whose volume is not a normal double is refused.
Status check_finite_extent(std::span<const Primitive> primitives) {
    Aabb box = Aabb::empty();
    for (const Primitive& primitive : primitives) box = box.merged(world_aabb(primitive.volume));
    const Vec3 extent = box.max - box.min;
    const double volume = 8.0 * extent.x() * extent.y() * extent.z();
    if (!extent.allFinite() || !std::isfinite(volume))
        return Error{range_message(extent, "volumes overflow double precision; scale the model down"), "", 0};
    if ((extent.array() > 0.0).all() && volume < std::numeric_limits<double>::min())
        return Error{range_message(extent, "volumes underflow double precision; scale the model up"), "", 0};
    return Ok{};
}

Algorithm auto_choice(std::size_t primitive_count) {
    if (primitive_count <= auto_optimal_max_primitives) return Algorithm::optimal;
    if (primitive_count <= auto_exact_max_primitives) return Algorithm::bnb_exact;
    return Algorithm::scale;
}

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
    if (Status finite = check_finite_extent(primitives); !finite) return finite.error();
    switch (algorithm) {
        case Algorithm::two_level: return build_two_level(primitives, options.policy);
        case Algorithm::bnb_tightest:
            return build_bnb_tightest(primitives, options.policy, options.branch_and_bound, options.report);
        case Algorithm::bnb_enlarge:
            return build_bnb_enlarge(primitives, options.policy, options.branch_and_bound, options.report);
        case Algorithm::bnb_exact:
            return build_bnb_exact(primitives, options.policy, exact_options_within(options, primitives.size()),
                                   options.report);
        case Algorithm::optimal: return build_optimal(primitives, options.policy, options.optimal, options.report);
        case Algorithm::merge: return build_bottom_up_merge(primitives, options.policy, options.merge);
        case Algorithm::insertion: return build_incremental_insert(primitives, options.policy, options.insertion);
        case Algorithm::insertion_haber:
            return build_incremental_insert_haber(primitives, options.policy, options.insertion_haber);
        case Algorithm::split: return build_top_down_split(primitives, options.policy, options.split);
        case Algorithm::obb_tree: return build_obb_tree(primitives, options.policy, options.obb_tree);
        case Algorithm::scale:
            return build_scale(primitives, options.policy, scale_options_within(options), options.report);
        case Algorithm::automatic: {
            const Algorithm chosen = auto_choice(primitives.size());
            Result<Bvh> built = build(primitives, chosen, options);
            if (options.report != nullptr)
                options.report->notes.push_back("auto: " + std::to_string(primitives.size()) + " primitives, built with " +
                                                std::string(to_string(chosen)));
            return built;
        }
    }
    return Error{"unknown algorithm", "", 0};
}

}  // namespace hbvh
