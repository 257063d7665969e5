// SPDX-License-Identifier: MIT
// `hbvh calibrate`: what an inner node's overlap test costs in the tandem traversal, per BV kind, on this
// machine, written as per-kind weights that `--type-weight @FILE` reads (docs/metrics.md, "Calibrated cost").
//
// One generated scene is built four times, each time with a single kind allowed for the inner nodes, and
// every tree answers the same recorded simulator queries. A query's time is taken as
//   T = t_kind x (inner-node tests) + t_leaf x (primitive tests),
// with t_leaf from the Two-Level query (primitive tests only) on the same queries; each kind's t_kind follows.
#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <span>
#include <utility>

#include "commands/command.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/query/simulate.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh::cli {
namespace {

struct CalibrateArguments {
    std::uint32_t primitives = 300;
    std::uint32_t queries = 300;
    int passes = 9;
    std::string output;  // empty: print only
};

/// Tests made over `poses` (copy A at the identity, B at each pose), all pairs reported.
std::pair<double, double> test_counts(const QueryTree& tree, std::span<const RigidTransform> poses, QueryMethod method) {
    double inner = 0.0, leaf = 0.0;
    CollideResult result;
    for (const RigidTransform& pose : poses) {
        if (method == QueryMethod::tandem)
            collide(tree, RigidTransform::identity(), tree, pose, CollideMode::all, result);
        else
            collide_two_level(tree, RigidTransform::identity(), tree, pose, CollideMode::all, result);
        inner += static_cast<double>(result.bv_tests);
        leaf += static_cast<double>(result.primitive_tests);
    }
    return {inner, leaf};
}

double seconds_for(const QueryTree& tree, std::span<const RigidTransform> poses, QueryMethod method, int passes) {
    return time_queries(tree, poses, SimulatedPhase::moving, method, CollideMode::all, passes) *
           static_cast<double>(poses.size());
}

int run_calibrate(const CalibrateArguments& args) {
    const std::vector<Primitive> scene = generate_scene({.count = args.primitives, .seed = 11});
    const Result<Bvh> flat = build(scene, Algorithm::two_level);
    if (!flat) return report_error(flat.error());
    const SimulationResult recorded = simulate(
        *flat, {.collision_count = args.queries, .seed = 5, .method = QueryMethod::two_level, .record_poses = true});
    const std::span<const RigidTransform> poses = recorded.moving_poses;
    if (poses.empty()) return report_error(Error{"the simulator found no root-overlapping queries to time"});

    const QueryTree flat_tree(*flat);
    const double leaf_seconds = seconds_for(flat_tree, poses, QueryMethod::two_level, args.passes) /
                                test_counts(flat_tree, poses, QueryMethod::two_level).second;

    std::array<double, bv_type_count> inner_seconds{};
    for (BvType type : all_bv_types) {
        BuildContext context;
        context.policy = VolumePolicy::only(type);
        const Result<Bvh> tree = build(scene, Algorithm::split, context);
        if (!tree) return report_error(tree.error());
        const QueryTree query_tree(*tree);
        const auto [inner, leaf] = test_counts(query_tree, poses, QueryMethod::tandem);
        const double total = seconds_for(query_tree, poses, QueryMethod::tandem, args.passes);
        inner_seconds[static_cast<std::size_t>(type)] = std::max(total - leaf_seconds * leaf, 0.0) / std::max(inner, 1.0);
    }

    const double aabb = inner_seconds[static_cast<std::size_t>(BvType::aabb)];
    std::string weights;
    fmt::print("{:<8} {:>12} {:>8}\n", "kind", "ns per test", "weight");
    for (BvType type : all_bv_types) {
        const double ns = 1e9 * inner_seconds[static_cast<std::size_t>(type)];
        // A kind whose share could not be told from the noise (0 after the leaf tests) keeps weight 1; the floor
        // keeps every weight one that --type-weight accepts (positive at the printed precision).
        const double weight =
            aabb > 0.0 && ns > 0.0 ? std::max(inner_seconds[static_cast<std::size_t>(type)] / aabb, 0.001) : 1.0;
        fmt::print("{:<8} {:>12.2f} {:>8.3f}\n", to_string(type), ns, weight);
        weights += fmt::format("{}{}={:.3f}", weights.empty() ? "" : ",", to_string(type), weight);
    }
    fmt::print("{:<8} {:>12.2f}   (primitive test, for reference)\n", "leaf", 1e9 * leaf_seconds);
    if (!args.output.empty()) {
        if (Status written = write_output(args.output, weights + "\n"); !written) return report_error(written.error());
        if (args.output != "-") fmt::print("weights written to {} (use: --type-weight @{})\n", args.output, args.output);
    }
    return exit_ok;
}

}  // namespace

void add_calibrate_command(CLI::App& app, Command& command) {
    auto args = std::make_shared<CalibrateArguments>();
    CLI::App* sub = app.add_subcommand(
        "calibrate", "Measure the tandem traversal's inner-node test cost per BV kind; write per-kind weights");
    sub->add_option("--primitives", args->primitives, "Primitives in the generated scene")
        ->capture_default_str()
        ->check(CLI::Range(20u, 100000u));
    sub->add_option("--queries", args->queries, "Recorded simulator queries each tree answers")
        ->capture_default_str()
        ->check(CLI::Range(10u, 100000u));
    sub->add_option("--passes", args->passes, "Timed passes over the queries; the fastest counts")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000));
    sub->add_option("-o,--output", args->output, "Write the weights (type=weight,...) to this file");
    sub->footer("Example: hbvh calibrate -o weights.txt && hbvh build model.xml --type-weight @weights.txt");
    sub->callback([&command, args] { command = [args] { return run_calibrate(*args); }; });
}

}  // namespace hbvh::cli
