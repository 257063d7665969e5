// SPDX-License-Identifier: MIT
#include "hbvh/build/build.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "hbvh/build/optimal.hpp"
#include "hbvh/build/two_level.hpp"
#include "hbvh/geometry/validation.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"

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
    AlgorithmInfo{Algorithm::automatic, "auto", "by size: optimal up to 10 primitives; above, the cheapest of a portfolio of builders, then treelet refinement (docs/treelets.md)"},
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
    for (std::size_t i = 0; i < primitives.size(); ++i) {
        // Eigen's cwiseMin/cwiseMax may skip a NaN operand, so a NaN box would vanish from the merge.
        const Aabb own = world_aabb(primitives[i].volume);
        if (!own.min.allFinite() || !own.max.allFinite())
            return Error{"primitive " + std::to_string(i) + " has non-finite coordinates", "", 0};
        box = box.merged(own);
    }
    const Vec3 extent = box.max - box.min;
    const double volume = 8.0 * extent.x() * extent.y() * extent.z();
    if (!extent.allFinite() || !std::isfinite(volume))
        return Error{range_message(extent, "volumes overflow double precision; scale the model down"), "", 0};
    if ((extent.array() > 0.0).all() && volume < std::numeric_limits<double>::min())
        return Error{range_message(extent, "volumes underflow double precision; scale the model up"), "", 0};
    return Ok{};
}

namespace {
TreeletOptions treelet_options_within(const BuildOptions& options, double elapsed_seconds) {
    TreeletOptions treelets = options.treelets;
    if (options.time_limit_seconds > 0.0) {
        // Whatever the builders left; a token amount when they used it all, so the call returns at once.
        const double left = options.time_limit_seconds - elapsed_seconds;
        treelets.time_limit_seconds = left > 0.0 ? left : 1e-9;
        if (options.treelets.time_limit_seconds > 0.0)
            treelets.time_limit_seconds = std::min(treelets.time_limit_seconds, options.treelets.time_limit_seconds);
    }
    return treelets;
}

std::string format_cost(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", value);
    return text;
}

Result<Bvh> build_one(std::span<const Primitive> primitives, Algorithm algorithm, const BuildOptions& options);

/// `auto`: every member of auto_portfolio(n) builds a tree and the cheapest under Eq. 2 (first in the list
/// on ties) wins. Up to auto_refine_each_max_primitives every member's tree is refined before the
/// comparison (refinement from different starts ends in different local optima, docs/treelets.md §3);
/// above, up to auto_refine_max_primitives, only the winner is.
Result<Bvh> build_auto(std::span<const Primitive> primitives, const BuildOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    const std::vector<Algorithm> members = auto_portfolio(primitives.size());
    const bool refine_any = members.front() != Algorithm::optimal &&
                            (options.refine || primitives.size() <= auto_refine_max_primitives);
    const bool refine_each = refine_any && primitives.size() <= auto_refine_each_max_primitives;
    std::optional<Bvh> best;
    BuildReport best_report;
    TreeletReport best_treelets;
    Algorithm winner = members.front();
    double best_cost = 0.0;
    std::string costs;
    const bool limited = options.time_limit_seconds > 0.0;
    std::string skipped;
    for (Algorithm member : members) {
        // Under a time limit the members share it: each gets what is left, and once nothing is left the rest
        // are skipped (the first always runs, so there is a tree). split and the insertions cannot stop early.
        if (best && limited && elapsed() >= options.time_limit_seconds) {
            skipped += (skipped.empty() ? "" : ", ") + std::string(to_string(member));
            continue;
        }
        BuildReport member_report;
        BuildOptions member_options = options;
        member_options.report = options.report != nullptr ? &member_report : nullptr;
        member_options.refine = false;
        if (limited) member_options.time_limit_seconds = std::max(options.time_limit_seconds - elapsed(), 1e-9);
        Result<Bvh> built = build_one(primitives, member, member_options);
        if (!built) return built;
        Bvh tree = std::move(built.value());
        double member_cost = cost(tree, options.policy);
        if (!costs.empty()) costs += ", ";
        costs += std::string(to_string(member)) + " " + format_cost(member_cost);
        TreeletReport treelets;
        if (refine_each) {
            tree = refine_treelets(tree, options.policy, treelet_options_within(options, elapsed()), &treelets);
            member_cost = treelets.cost_after;
            costs += " -> " + format_cost(member_cost);
        }
        if (!best || member_cost < best_cost) {
            best = std::move(tree);
            best_cost = member_cost;
            best_report = std::move(member_report);
            best_treelets = treelets;
            winner = member;
        }
    }
    if (refine_any && !refine_each)
        *best = refine_treelets(*best, options.policy, treelet_options_within(options, elapsed()), &best_treelets);
    if (options.report != nullptr) {
        *options.report = std::move(best_report);
        if (members.size() > 1)
            options.report->notes.push_back("auto: " + std::to_string(primitives.size()) + " primitives, portfolio " +
                                            costs + (refine_each ? " (each refined)" : "") + "; kept " +
                                            std::string(to_string(winner)));
        else
            options.report->notes.push_back("auto: " + std::to_string(primitives.size()) + " primitives, built with " +
                                            std::string(to_string(winner)));
        if (!skipped.empty()) {
            options.report->notes.push_back("auto: time limit reached; skipped " + skipped);
            options.report->budget_hit = true;
        }
        if (refine_any) note_treelets(*options.report, best_treelets);
    }
    return std::move(*best);
}
}  // namespace

void note_treelets(BuildReport& report, const TreeletReport& treelets) {
    report.notes.push_back("treelets: " + std::to_string(treelets.passes) + " passes, " +
                           std::to_string(treelets.replaced) + " of " + std::to_string(treelets.treelets) +
                           " treelets replaced, " + std::to_string(treelets.fits) + " fits, cost " +
                           format_cost(treelets.cost_before) + " -> " + format_cost(treelets.cost_after) +
                           (treelets.time_limit_hit ? " (time limit hit)" : ""));
    if (treelets.time_limit_hit) report.budget_hit = true;
}

Algorithm auto_choice(std::size_t primitive_count) { return auto_portfolio(primitive_count).front(); }

std::vector<Algorithm> auto_portfolio(std::size_t primitive_count) {
    if (primitive_count <= auto_optimal_max_primitives) return {Algorithm::optimal};
    if (primitive_count <= auto_exact_max_primitives)
        return {Algorithm::bnb_exact, Algorithm::insertion_haber, Algorithm::insertion, Algorithm::split,
                Algorithm::merge, Algorithm::scale};
    if (primitive_count <= auto_insertion_max_primitives)
        return {Algorithm::scale, Algorithm::insertion_haber, Algorithm::insertion, Algorithm::split};
    if (primitive_count <= auto_portfolio_max_primitives) return {Algorithm::scale, Algorithm::split};
    return {Algorithm::scale};
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

namespace {
/// The builder's tree, or an Error when it is not one queries can use (a fitter that overflowed to NaN on
/// extreme input once wrote "pos=-nan" into a file): a wrong tree is never handed on. Linear time.
Result<Bvh> checked_output(Result<Bvh> built, Algorithm algorithm) {
    if (!built) return built;
    if (Status structure = check_structure(*built); !structure)
        return Error{std::string(to_string(algorithm)) + " produced an unusable tree (" + structure.error().message +
                     "); the input's scale is probably beyond what double precision can fit"};
    return built;
}

Result<Bvh> build_unchecked(std::span<const Primitive> primitives, Algorithm algorithm, const BuildOptions& options) {
    if (algorithm == Algorithm::automatic) return build_auto(primitives, options);
    const auto start = std::chrono::steady_clock::now();
    Result<Bvh> built = build_one(primitives, algorithm, options);
    if (!built || !options.refine) return built;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    TreeletReport treelets;
    Bvh refined = refine_treelets(built.value(), options.policy, treelet_options_within(options, elapsed), &treelets);
    if (options.report != nullptr) note_treelets(*options.report, treelets);
    return refined;
}
}  // namespace

Result<Bvh> build(std::span<const Primitive> primitives, Algorithm algorithm, const BuildOptions& options) {
    if (primitives.empty()) return Error{"no primitives to build a hierarchy over", "", 0};
    if (Status valid = validate_primitives(primitives); !valid) return valid.error();
    if (Status finite = check_finite_extent(primitives); !finite) return finite.error();
    return checked_output(build_unchecked(primitives, algorithm, options), algorithm);
}

namespace {
Result<Bvh> build_one(std::span<const Primitive> primitives, Algorithm algorithm, const BuildOptions& options) {
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
        case Algorithm::automatic: return build_auto(primitives, options);
    }
    return Error{"unknown algorithm", "", 0};
}
}  // namespace

}  // namespace hbvh
