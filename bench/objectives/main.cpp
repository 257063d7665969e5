// SPDX-License-Identifier: MIT
// hbvh_objectives: does a tree's cost predict how fast it answers queries? For every object, every
// registered builder's tree is timed on the same simulator queries (the survey's §5.3 benchmark, both
// phases), and each cost objective is scored by its Spearman rank correlation with the measured times.
#include <Eigen/QR>
#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <numeric>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "../common/bench_objects.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/query/simulate.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh::bench {
namespace {

struct Options {
    bool markdown = false;
    std::uint32_t collisions = 300;  ///< Root-overlapping queries per phase.
    int passes = 7;                  ///< Timed passes over the queries; the fastest counts.
    double build_seconds = 10.0;     ///< A builder that needs longer on an object gets no row for it.
    std::string only;                ///< When set, only objects whose name contains it.
    bool verbose = false;            ///< Each build's time on stderr.
    CollideMode mode = CollideMode::first;  ///< The simulator's: does B touch A at all.
    bool summary_only = false;              ///< Only the table of correlations, not every tree's row.
    std::string type_weights;               ///< Per-kind weights of the calibrated objective (hbvh calibrate's).
    double leaf_weight = 0.5;               ///< A leaf child's test in child_priced_cost, in AABB tests.
};

/// One builder's tree on one object.
struct Row {
    std::string builder;
    double eq2 = 0.0;
    double calibrated = 0.0;
    double moving_us = 0.0;
    double total_us = 0.0;
    double child_priced = 0.0;  ///< child_priced_cost: a candidate cost, not (yet) one the builders minimise.
    /// The two yardsticks of a cost's ρ (moving phase): the same queries timed again after both phases (what
    /// any ρ is held back by when the trees' times differ by less than the timing's noise), and the BV tests
    /// they make (what Eq. 2 models: a cost that counted those exactly would reach the ρ of this column).
    double moving_retest_us = 0.0;
    double moving_bv_tests = 0.0;
    double moving_primitive_tests = 0.0;  ///< With the BV tests, what the fitted-counts yardstick is fitted on.
};

/// Ranks 1..n with ties given their mean rank, as Spearman's coefficient needs.
std::vector<double> ranks(const std::vector<double>& values) {
    std::vector<std::size_t> order(values.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
    std::vector<double> rank(values.size());
    for (std::size_t i = 0; i < order.size();) {
        std::size_t j = i;
        while (j + 1 < order.size() && values[order[j + 1]] == values[order[i]]) ++j;
        const double mean_rank = 0.5 * static_cast<double>(i + j) + 1.0;
        for (std::size_t k = i; k <= j; ++k) rank[order[k]] = mean_rank;
        i = j + 1;
    }
    return rank;
}

/// Spearman's rank correlation: Pearson's on the ranks. nullopt when either side has no spread.
std::optional<double> spearman(const std::vector<double>& x, const std::vector<double>& y) {
    const std::vector<double> rx = ranks(x), ry = ranks(y);
    const double n = static_cast<double>(rx.size());
    const double mx = std::accumulate(rx.begin(), rx.end(), 0.0) / n;
    const double my = std::accumulate(ry.begin(), ry.end(), 0.0) / n;
    double sxy = 0.0, sxx = 0.0, syy = 0.0;
    for (std::size_t i = 0; i < rx.size(); ++i) {
        sxy += (rx[i] - mx) * (ry[i] - my);
        sxx += (rx[i] - mx) * (rx[i] - mx);
        syy += (ry[i] - my) * (ry[i] - my);
    }
    if (sxx == 0.0 || syy == 0.0) return std::nullopt;
    return sxy / std::sqrt(sxx * syy);
}

std::string format_rho(const std::optional<double>& rho) { return rho ? fmt::format("{:+.2f}", *rho) : "-"; }

/// The simulator's queries for `object`, recorded from a run with the Two-Level query: its first reported
/// pair, and so the mover's path, depends on the primitives alone, not on any tree.
SimulationResult record_queries(const std::vector<Primitive>& primitives, const Options& options) {
    Result<Bvh> two_level = build(primitives, Algorithm::two_level);
    SimulateOptions simulate_options{.collision_count = options.collisions, .seed = 3,
                                     .method = QueryMethod::two_level, .record_poses = true};
    return simulate(two_level.value(), simulate_options);
}

/// The smallest object size on which each builder ran out of build time: it is not tried on larger ones,
/// whose deadline it would miss too (and some builders overrun theirs by far on large inputs).
using SizeLimits = std::map<std::string_view, std::size_t>;

/// The two objectives a builder can minimise (BuildContext::policy.measure).
constexpr std::array<NodeMeasure, 2> objectives{NodeMeasure::volume, NodeMeasure::minkowski};

/// A candidate cost that prices each test by what is tested: every inner node x is reached in proportion to its
/// measure (the policy's: the Minkowski one for the calibrated weights), and reaching it tests each of its
/// children, an inner child at its own kind's weight and a leaf child at `leaf_weight`. The calibrated objective
/// charges all k children at x's own kind's weight instead (k x weight(x) x measure(x)), as Eq. 2 does with
/// weight 1. Not per-node in the builders' sense (a node's term depends on its children's kinds), so no builder
/// minimises it; it is here to measure whether it predicts query time (docs/metrics.md).
double child_priced_cost(const Bvh& bvh, const VolumePolicy& policy, double leaf_weight) {
    double total = 0.0;
    for (const Node& node : bvh.nodes) {
        if (node.child_count == 0) continue;
        double tests = 0.0;
        for (std::uint32_t c = node.first_child; c < node.first_child + node.child_count; ++c) {
            const Node& child = bvh.nodes[c];
            tests += child.child_count == 0 ? leaf_weight : policy.weight_of(type_of(child.volume));
        }
        total += tests * policy.unweighted_measure(node.volume);
    }
    return total;
}

/// The row of one tree: its costs under both objectives (`calibrated`: the policy measuring nodes by
/// self_minkowski_volume, docs/metrics.md) and its time on the recorded queries.
Row measure_tree(std::string builder, const Bvh& bvh, const SimulationResult& queries, const Options& options,
                 const VolumePolicy& calibrated) {
    const QueryTree tree(bvh);
    Row row{.builder = std::move(builder), .eq2 = cost(bvh), .calibrated = cost(bvh, calibrated)};
    row.child_priced = child_priced_cost(bvh, calibrated, options.leaf_weight);
    row.moving_us = 1e6 * time_queries(tree, queries.moving_poses, SimulatedPhase::moving, QueryMethod::tandem,
                                       options.mode, options.passes);
    row.total_us = 1e6 * time_queries(tree, queries.total_poses, SimulatedPhase::total, QueryMethod::tandem,
                                      options.mode, options.passes);
    row.moving_retest_us = 1e6 * time_queries(tree, queries.moving_poses, SimulatedPhase::moving,
                                              QueryMethod::tandem, options.mode, options.passes);
    CollideResult result;
    for (const RigidTransform& pose : queries.moving_poses) {
        collide(tree, RigidTransform::identity(), tree, pose, options.mode, result);
        row.moving_bv_tests += static_cast<double>(result.bv_tests);
        row.moving_primitive_tests += static_cast<double>(result.primitive_tests);
    }
    return row;
}

/// Every builder's tree under each objective ("NAME" for Eq. 2, "NAME/cal" for the calibrated one).
std::vector<Row> measure_object(const BenchObject& object, const Options& options, const VolumePolicy& calibrated,
                                SizeLimits& too_slow_from) {
    const SimulationResult queries = record_queries(object.primitives, options);
    std::vector<Row> rows;
    if (queries.moving_poses.empty()) return rows;
    for (const AlgorithmInfo& info : algorithms()) {
        // The survey's searches fit candidates before their deadline applies: beyond 100 primitives they can
        // run for many minutes whatever the budget (docs/algorithms.md).
        const bool is_search = info.name.starts_with("bnb-") || info.name == "optimal";
        if (is_search && object.primitives.size() > 100) continue;
        if (auto limit = too_slow_from.find(info.name);
            limit != too_slow_from.end() && object.primitives.size() >= limit->second) {
            fmt::print(stderr, "hbvh_objectives: {}: no {} row (out of build time on {} primitives)\n", object.name,
                       info.name, limit->second);
            continue;
        }
        for (NodeMeasure objective : objectives) {
            const std::string name = std::string(info.name) + (objective == NodeMeasure::volume ? "" : "/cal");
            BuildReport report;
            BuildContext context = BuildContext{}.with_time_limit(options.build_seconds);
            if (objective == NodeMeasure::minkowski) context.policy = calibrated;
            context.report = &report;
            const auto started = std::chrono::steady_clock::now();
            Result<Bvh> bvh = info.build(object.primitives, context);
            if (options.verbose)
                fmt::print(stderr, "hbvh_objectives: {}: {} built in {:.2f} s\n", object.name, name,
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
            if (bvh && report.budget_hit) too_slow_from.emplace(info.name, object.primitives.size());
            if (!bvh || report.budget_hit) {
                fmt::print(stderr, "hbvh_objectives: {}: no {} row ({})\n", object.name, name,
                           bvh ? "build budget reached" : bvh.error().to_string());
                break;
            }
            rows.push_back(measure_tree(name, *bvh, queries, options, calibrated));
        }
    }
    return rows;
}

/// One object's summary: how each cost ranks its trees, and what building auto for the calibrated
/// objective changed in query time.
struct Correlations {
    std::size_t trees = 0;
    std::optional<double> eq2_moving, eq2_total, calibrated_moving, calibrated_total;
    std::optional<double> child_priced_moving, child_priced_total;
    std::optional<double> retest_moving, bv_tests_moving;  ///< The yardsticks (Row): their ρ with the moving time.
    std::optional<double> fitted_counts_moving;            ///< fitted_counts' ρ with the moving time.
    std::optional<double> auto_moving_ratio, auto_total_ratio;  ///< auto/cal time / auto time.
};

/// A third yardstick: the moving time predicted from the tests each tree's queries made, by the least-squares
/// fit of time = a x (BV tests) + b x (primitive tests) + c over the object's own trees. It is fitted to the very
/// times it is scored against, so it is an upper estimate of what any cost built from those two counts can reach
/// (docs/metrics.md, "What any cost is up against"). Empty with fewer than four trees.
std::vector<double> fitted_counts(const std::vector<Row>& rows) {
    if (rows.size() < 4) return {};
    Eigen::MatrixXd counts(static_cast<Eigen::Index>(rows.size()), 3);
    Eigen::VectorXd times(static_cast<Eigen::Index>(rows.size()));
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto at = static_cast<Eigen::Index>(i);
        counts(at, 0) = rows[i].moving_bv_tests;
        counts(at, 1) = rows[i].moving_primitive_tests;
        counts(at, 2) = 1.0;
        times(at) = rows[i].moving_us;
    }
    const Eigen::VectorXd predicted = counts * counts.colPivHouseholderQr().solve(times);
    return {predicted.data(), predicted.data() + predicted.size()};
}

Correlations correlate(const std::vector<Row>& rows) {
    std::vector<double> eq2, calibrated, child_priced, moving, total, retest, bv_tests;
    const Row* by_eq2 = nullptr;
    const Row* by_calibrated = nullptr;
    for (const Row& row : rows) {
        eq2.push_back(row.eq2);
        calibrated.push_back(row.calibrated);
        moving.push_back(row.moving_us);
        total.push_back(row.total_us);
        child_priced.push_back(row.child_priced);
        retest.push_back(row.moving_retest_us);
        bv_tests.push_back(row.moving_bv_tests);
        if (row.builder == "auto") by_eq2 = &row;
        if (row.builder == "auto/cal") by_calibrated = &row;
    }
    Correlations c;
    c.trees = rows.size();
    c.eq2_moving = spearman(eq2, moving);
    c.eq2_total = spearman(eq2, total);
    c.calibrated_moving = spearman(calibrated, moving);
    c.calibrated_total = spearman(calibrated, total);
    c.child_priced_moving = spearman(child_priced, moving);
    c.child_priced_total = spearman(child_priced, total);
    c.retest_moving = spearman(retest, moving);
    c.bv_tests_moving = spearman(bv_tests, moving);
    if (const std::vector<double> predicted = fitted_counts(rows); !predicted.empty())
        c.fitted_counts_moving = spearman(predicted, moving);
    if (by_eq2 && by_calibrated) {
        c.auto_moving_ratio = by_calibrated->moving_us / by_eq2->moving_us;
        c.auto_total_ratio = by_calibrated->total_us / by_eq2->total_us;
    }
    return c;
}

void print_object(const BenchObject& object, const std::vector<Row>& rows, const Options& options) {
    if (options.markdown) {
        fmt::print("\n#### {} ({} primitives)\n\n", object.name, object.primitives.size());
        fmt::print("| builder | Eq. 2 cost | calibrated cost | moving µs | total µs |\n|---|---:|---:|---:|---:|\n");
        for (const Row& r : rows)
            fmt::print("| {} | {:.6g} | {:.6g} | {:.3f} | {:.3f} |\n", r.builder, r.eq2, r.calibrated, r.moving_us, r.total_us);
        return;
    }
    fmt::print("\n{} ({} primitives)\n{:<16} {:>14} {:>16} {:>10} {:>10}\n", object.name, object.primitives.size(),
               "builder", "Eq. 2 cost", "calibrated cost", "moving us", "total us");
    for (const Row& r : rows)
        fmt::print("{:<16} {:>14.6g} {:>16.6g} {:>10.3f} {:>10.3f}\n", r.builder, r.eq2, r.calibrated, r.moving_us, r.total_us);
}

std::string format_ratio(const std::optional<double>& ratio) { return ratio ? fmt::format("{:.2f}", *ratio) : "-"; }

void print_summary(const std::vector<std::pair<std::string, Correlations>>& summary, const Options& options) {
    if (options.markdown) {
        fmt::print("\n| object | trees | ρ Eq. 2 / moving | ρ Eq. 2 / total | ρ calibrated / moving | "
                   "ρ calibrated / total | ρ child-priced / moving | ρ child-priced / total | ρ retest / moving | "
                   "ρ BV tests / moving | ρ fitted counts / moving | auto/cal ÷ auto, moving | "
                   "auto/cal ÷ auto, total |\n"
                   "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (const auto& [name, c] : summary)
            fmt::print("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", name, c.trees,
                       format_rho(c.eq2_moving), format_rho(c.eq2_total), format_rho(c.calibrated_moving),
                       format_rho(c.calibrated_total), format_rho(c.child_priced_moving),
                       format_rho(c.child_priced_total), format_rho(c.retest_moving), format_rho(c.bv_tests_moving),
                       format_rho(c.fitted_counts_moving), format_ratio(c.auto_moving_ratio),
                       format_ratio(c.auto_total_ratio));
        return;
    }
    fmt::print("\n{:<36} {:>5} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9}\n",
               "Spearman rho", "trees", "eq2/mov", "eq2/total", "cal/mov", "cal/total", "child/mov", "child/total",
               "retest/mov", "tests/mov", "fitted/mov", "autocal/m", "autocal/t");
    for (const auto& [name, c] : summary)
        fmt::print("{:<36} {:>5} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9}\n", name,
                   c.trees, format_rho(c.eq2_moving), format_rho(c.eq2_total), format_rho(c.calibrated_moving),
                   format_rho(c.calibrated_total), format_rho(c.child_priced_moving), format_rho(c.child_priced_total),
                   format_rho(c.retest_moving), format_rho(c.bv_tests_moving), format_rho(c.fitted_counts_moving),
                   format_ratio(c.auto_moving_ratio), format_ratio(c.auto_total_ratio));
}

}  // namespace
}  // namespace hbvh::bench

int main(int argc, char** argv) {
    using namespace hbvh::bench;
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        if (arg == "--markdown") {
            options.markdown = true;
        } else if (arg == "--collisions" && i + 1 < argc) {
            options.collisions = static_cast<std::uint32_t>(std::strtoul(argv[++i], nullptr, 10));
        } else if (arg == "--passes" && i + 1 < argc) {
            options.passes = std::max(1, std::atoi(argv[++i]));
        } else if (arg == "--build-seconds" && i + 1 < argc) {
            options.build_seconds = std::strtod(argv[++i], nullptr);
        } else if (arg == "--type-weight" && i + 1 < argc) {
            options.type_weights = argv[++i];
        } else if (arg == "--leaf-weight" && i + 1 < argc) {
            options.leaf_weight = std::strtod(argv[++i], nullptr);
        } else if (arg == "--summary") {
            options.summary_only = true;
        } else if (arg == "--all-pairs") {
            options.mode = hbvh::CollideMode::all;
        } else if (arg == "--verbose") {
            options.verbose = true;
        } else if (arg == "--only" && i + 1 < argc) {
            options.only = argv[++i];
        } else {
            fmt::print(stderr, "usage: hbvh_objectives [--markdown] [--collisions N] [--passes N] [--build-seconds S] "
                               "[--only NAME] [--verbose] [--all-pairs] [--summary] [--type-weight LIST|@FILE] "
                               "[--leaf-weight W]\n");
            return 2;
        }
    }
    hbvh::Result<hbvh::VolumePolicy> calibrated =
        options.type_weights.empty() ? hbvh::VolumePolicy::all() : hbvh::type_weights_from(options.type_weights);
    if (!calibrated) {
        fmt::print(stderr, "hbvh_objectives: --type-weight: {}\n", calibrated.error().to_string());
        return 2;
    }
    calibrated->measure = hbvh::NodeMeasure::minkowski;
    std::vector<std::pair<std::string, Correlations>> summary;
    SizeLimits too_slow_from;
    for (const BenchObject& object : load_bench_objects("hbvh_objectives")) {
        if (object.name.find(options.only) == std::string::npos) continue;
        const std::vector<Row> rows = measure_object(object, options, *calibrated, too_slow_from);
        if (!options.summary_only) print_object(object, rows, options);
        summary.emplace_back(object.name, correlate(rows));
    }
    print_summary(summary, options);
    return 0;
}
