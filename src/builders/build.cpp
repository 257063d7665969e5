// SPDX-License-Identifier: MIT
#include "hbvh/builders/build.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "hbvh/assert.hpp"
#include "report_text.hpp"

namespace hbvh {
namespace {
/// A builder with its default options, as a BuildFunction.
template <auto builder>
Result<Bvh> with_defaults(std::span<const Primitive> primitives, const BuildContext& context) {
    return builder(primitives, context, {});
}

// The one table: a new builder is one row here. (The Algorithm constants in registry.hpp name the rows by
// their names; a builder needs none to be built, listed, tested and compared.)
constexpr std::array registry{
    AlgorithmInfo{"two-level", "the survey's baseline: one root BV (best allowed type) over all primitives", with_defaults<build_two_level>},
    AlgorithmInfo{"bnb-tightest", "the survey's B&B-Tightest: per level, Eq. 1 tightest-growth candidates + branch and bound", with_defaults<build_bnb_tightest>},
    AlgorithmInfo{"bnb-enlarge", "the survey's B&B-Enlarge: per level, 5 % enlargement candidates + branch and bound", with_defaults<build_bnb_enlarge>},
    AlgorithmInfo{"bnb-exact", "bottom-up levels, Tightest+Enlarge+kNN candidates, exact set partition; never worse than bnb-enlarge", with_defaults<build_bnb_exact>},
    AlgorithmInfo{"optimal", "globally optimal Eq. 2 hierarchy by subset DP; at most 18 primitives by default", with_defaults<build_optimal>},
    AlgorithmInfo{"merge", "OpenTissue bottom-up merge: collapse cheapest edges of an enlarged-overlap graph (survey 2.3)", with_defaults<build_merge>},
    AlgorithmInfo{"insertion", "Goldsmith-Salmon incremental insertion in input order (survey 2.1)", with_defaults<build_insertion>},
    AlgorithmInfo{"insertion-haber", "insertion with Haber et al.'s extra rule, re-insertion and ill-formed-group elimination (survey 2.1)", with_defaults<build_insertion_haber>},
    AlgorithmInfo{"split", "Mueller et al. top-down split at the cheapest sorted cut on x, y or z (survey 2.2)", with_defaults<build_split>},
    AlgorithmInfo{"obbtree", "Gottschalk OBB-tree: split at the mean centre along the covariance OBB's longest axis (survey 2.2)", with_defaults<build_obbtree>},
    AlgorithmInfo{"scale", "10^3-10^6 primitives: bottom-up levels, kNN candidates, exact partition per Morton window, multi-threaded (docs/scale.md)", with_defaults<build_scale>},
    AlgorithmInfo{"binned", "10^4-10^6+ primitives: top-down binned volume splits, then the Eq. 2-optimal collapse into wide nodes (docs/scale.md 9)", with_defaults<build_binned>},
    AlgorithmInfo{"fast", "the speed preset (--quality fast): binned's tree with cheap fits, treelets priced by cheap fits, fit_best on the heaviest nodes; about a millisecond for a few dozen primitives", with_defaults<build_fast>},
    AlgorithmInfo{"auto", "by size: optimal up to 10 primitives; above, the cheapest of a portfolio of builders, then treelet refinement (docs/treelets.md)", with_defaults<build_auto>},
};
}  // namespace

std::span<const AlgorithmInfo> algorithms() { return registry; }

const AlgorithmInfo& algorithm_info(Algorithm algorithm) {
    for (const AlgorithmInfo& row : registry)
        if (row.name == algorithm.name()) return row;
    HBVH_ASSERT(false && "every Algorithm names a registry row");
    return registry.front();
}

std::optional<Algorithm> parse_algorithm(std::string_view name) {
    for (const AlgorithmInfo& row : registry)
        if (row.name == name) return row.algorithm();
    return std::nullopt;
}

namespace {
/// "primitive 7 ('wheel')", or without the parentheses for an unnamed primitive.
std::string primitive_label(std::span<const Primitive> primitives, std::size_t index) {
    std::string label = "primitive " + std::to_string(index);
    if (!primitives[index].name.empty()) label += " ('" + primitives[index].name + "')";
    return label;
}

/// The span and the problem, and which two primitives set the widest extent (lowest and highest along that
/// axis), so that a user can find the stray one in a large file.
std::string range_message(const Vec3& extent, const char* problem, std::span<const Primitive> primitives,
                          const std::array<std::size_t, 3>& lowest, const std::array<std::size_t, 3>& highest) {
    char text[200];
    std::snprintf(text, sizeof text, "the primitives span %.3g x %.3g x %.3g: %s", extent.x(), extent.y(),
                  extent.z(), problem);
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (!(extent[a] <= extent[axis])) axis = a;  // the widest, an infinite or NaN one first
    const auto a = static_cast<std::size_t>(axis);
    return std::string(text) + " (along " + "xyz"[axis] + " from " + primitive_label(primitives, lowest[a]) + " to " +
           primitive_label(primitives, highest[a]) + ")";
}
}  // namespace

// Builders compare volumes of groups; once a volume overflows to infinity every choice ties and the exact
// searches lose their pruning (optimal ran for minutes on 1e150-sized input). A factor 8 above the box's
// own volume leaves room for the enlargements some builders try. Underflow is the mirror image: every
// volume rounds to zero and all trees cost the same. A box flat in some axis is fine (its volume is
// truly zero), so only a box of three positive extents whose volume is not a normal double is refused.
Status check_finite_extent(std::span<const Primitive> primitives) {
    Aabb box = Aabb::empty();
    std::array<std::size_t, 3> lowest{}, highest{};  // which primitive sets each side of the box
    for (std::size_t i = 0; i < primitives.size(); ++i) {
        // Eigen's cwiseMin/cwiseMax may skip a NaN operand, so a NaN box would vanish from the merge.
        const Aabb own = world_aabb(primitives[i].volume);
        if (!own.min.allFinite() || !own.max.allFinite())
            return Error{primitive_label(primitives, i) + " reaches beyond the range of double (its bounding box is "
                         "not finite); scale the model down", "", 0};
        for (int axis = 0; axis < 3; ++axis) {
            if (own.min[axis] < box.min[axis]) lowest[static_cast<std::size_t>(axis)] = i;
            if (own.max[axis] > box.max[axis]) highest[static_cast<std::size_t>(axis)] = i;
        }
        box = box.merged(own);
    }
    const Vec3 extent = box.max - box.min;
    const double volume = 8.0 * extent.x() * extent.y() * extent.z();
    if (!extent.allFinite() || !std::isfinite(volume))
        return Error{range_message(extent, "volumes overflow double precision; scale the model down", primitives,
                                   lowest, highest),
                     "", 0};
    if ((extent.array() > 0.0).all() && volume < std::numeric_limits<double>::min())
        return Error{range_message(extent, "volumes underflow double precision; scale the model up", primitives,
                                   lowest, highest),
                     "", 0};
    return Ok{};
}

Result<Bvh> build(std::span<const Primitive> primitives, Algorithm algorithm, const BuildContext& context) {
    return algorithm_info(algorithm).build(primitives, context);
}

TreeletOptions treelets_within(const BuildContext& context, TreeletOptions treelets) {
    if (context.has_deadline()) {
        // Whatever the builders left; a token amount when they used it all, so the call returns at once.
        const double left = std::max(context.seconds_left(), 1e-9);
        treelets.time_limit_seconds =
            treelets.time_limit_seconds > 0.0 ? std::min(treelets.time_limit_seconds, left) : left;
    }
    return treelets;
}

Result<Bvh> build_refined(std::span<const Primitive> primitives, Algorithm algorithm, const BuildContext& context,
                          const TreeletOptions& treelets) {
    if (algorithm == Algorithm::automatic) return build_auto(primitives, context, {true, treelets});
    Result<Bvh> built = build(primitives, algorithm, context);
    if (!built) return built;
    TreeletReport report;
    Bvh refined = refine_treelets(*built, context.policy, treelets_within(context, treelets), &report);
    if (context.report != nullptr) note_treelets(*context.report, report);
    return refined;
}

void note_treelets(BuildReport& report, const TreeletReport& treelets) {
    report.notes.push_back("treelets: " + std::to_string(treelets.passes) + " passes, " +
                           std::to_string(treelets.replaced) + " of " + std::to_string(treelets.treelets) +
                           " treelets replaced, " + std::to_string(treelets.fits) + " fits, cost " +
                           detail::format_cost(treelets.cost_before) + " -> " + detail::format_cost(treelets.cost_after) +
                           (treelets.time_limit_hit ? " (time limit hit)" : ""));
    if (treelets.time_limit_hit) report.budget_hit = true;
}

}  // namespace hbvh
