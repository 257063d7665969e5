// SPDX-License-Identifier: MIT
// `hbvh calibrate`: what an inner node's overlap test costs in the tandem traversal, per pair of BV kinds, on
// this machine, written as per-kind weights that `--type-weight @FILE` reads (docs/metrics.md, "Calibrated cost").
//
// One generated scene is built four times, each time with a single kind allowed for the inner nodes, and every
// pair of those trees (one as copy A, the other as copy B) answers the same recorded simulator queries. A query's
// time is taken as
//   T = t_pair x (inner-node tests) + t_leaf x (primitive tests),
// with t_leaf from the Two-Level query (primitive tests only) on the same queries; each pair's t_pair follows.
// A kind's weight is its test against its own kind, relative to the AABB's: a builder's tree meets copies of
// itself (the survey's simulator, the benchmarks) or trees built under the same policy. Weighting every partner
// kind alike instead (the row's mean) ranked the trees of generated objects worse and made their calibrated
// trees slower (docs/metrics.md, "Per-kind weights"), so the table of pairs is written for the record only.
#include <fmt/core.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <span>
#include <string_view>
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

/// Tests made over `poses` (a at the identity, b at each pose), all pairs reported.
std::pair<double, double> test_counts(const QueryTree& a, const QueryTree& b, std::span<const RigidTransform> poses,
                                      QueryMethod method) {
    double inner = 0.0, leaf = 0.0;
    CollideResult result;
    for (const RigidTransform& pose : poses) {
        if (method == QueryMethod::tandem)
            collide(a, RigidTransform::identity(), b, pose, CollideMode::all, result);
        else
            collide_two_level(a, RigidTransform::identity(), b, pose, CollideMode::all, result);
        inner += static_cast<double>(result.bv_tests);
        leaf += static_cast<double>(result.primitive_tests);
    }
    return {inner, leaf};
}

double seconds_for(const QueryTree& a, const QueryTree& b, std::span<const RigidTransform> poses, QueryMethod method,
                   int passes) {
    return time_queries(a, b, poses, SimulatedPhase::moving, method, CollideMode::all, passes) *
           static_cast<double>(poses.size());
}

using PairTable = std::array<std::array<double, bv_type_count>, bv_type_count>;  ///< ns, [this kind][the other's]

/// The table of pairs, a header row and a row per kind, each line starting with `prefix`.
std::string pair_table_text(const PairTable& pair_ns, std::string_view prefix) {
    std::string text = fmt::format("{}{:<8}", prefix, "");
    for (BvType other : all_bv_types) text += fmt::format(" {:>8}", to_string(other));
    text += "\n";
    for (BvType type : all_bv_types) {
        text += fmt::format("{}{:<8}", prefix, to_string(type));
        for (double ns : pair_ns[static_cast<std::size_t>(type)]) text += fmt::format(" {:>8.2f}", ns);
        text += "\n";
    }
    return text;
}

/// The weights file: the pair table as comment lines (for the reader), then the weights in --type-weight syntax.
std::string weights_file(const PairTable& pair_ns, const std::string& weights) {
    return "# hbvh calibrate: ns per inner-node test in the tandem traversal; row: this tree's kind,\n"
           "# column: the other tree's. A kind's weight is its diagonal entry over the AABB's.\n" +
           pair_table_text(pair_ns, "# ") + weights + "\n";
}

int run_calibrate(const CalibrateArguments& args) {
    // An output that cannot be written is said before the minute of measuring, not after it.
    if (!args.output.empty() && args.output != "-") {
        const std::filesystem::path output(args.output);
        const std::filesystem::path folder = output.parent_path().empty() ? "." : output.parent_path();
        std::error_code ignored;
        if (!std::filesystem::is_directory(folder, ignored))
            return report_error(Error{"cannot write: the folder " + folder.string() + " does not exist", args.output});
        if (std::filesystem::is_directory(output, ignored))
            return report_error(Error{"is a directory, not a file: give the output a file name", args.output});
        // The output is written next to itself and renamed, so the folder must take a new file: tried with one, since
        // access() says yes to root in folders that take none (/sys, /proc, a read-only mount). A device or fifo is
        // written into instead (write_file_atomic), which needs no new file.
        struct stat existing {};
        const bool stream = ::stat(output.c_str(), &existing) == 0 && !S_ISREG(existing.st_mode);
        if (!stream) {
            const std::filesystem::path probe = folder / (".hbvh-calibrate-probe-" + std::to_string(::getpid()));
            const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
            if (fd < 0)
                return report_error(Error{"cannot write: the folder " + folder.string() + " does not take new files (" +
                                              std::strerror(errno) + ")",
                                          args.output});
            ::close(fd);
            ::unlink(probe.c_str());
        }
    }
    const std::vector<Primitive> scene = generate_scene({.count = args.primitives, .seed = 11});
    const Result<Bvh> flat = build(scene, Algorithm::two_level);
    if (!flat) return report_error(flat.error());
    const SimulationResult recorded = simulate(
        *flat, {.collision_count = args.queries, .seed = 5, .method = QueryMethod::two_level, .record_poses = true});
    const std::span<const RigidTransform> poses = recorded.moving_poses;
    if (poses.empty()) return report_error(Error{"the simulator found no root-overlapping queries to time"});

    const QueryTree flat_tree(*flat);
    const double leaf_seconds = seconds_for(flat_tree, flat_tree, poses, QueryMethod::two_level, args.passes) /
                                test_counts(flat_tree, flat_tree, poses, QueryMethod::two_level).second;

    std::vector<QueryTree> trees;  // one per kind, in all_bv_types order
    for (BvType type : all_bv_types) {
        BuildContext context;
        context.policy = VolumePolicy::only(type);
        const Result<Bvh> tree = build(scene, Algorithm::split, context);
        if (!tree) return report_error(tree.error());
        trees.emplace_back(*tree);
    }
    PairTable pair_ns{};
    for (std::size_t i = 0; i < bv_type_count; ++i)
        for (std::size_t j = 0; j < bv_type_count; ++j) {
            const auto [inner, leaf] = test_counts(trees[i], trees[j], poses, QueryMethod::tandem);
            const double total = seconds_for(trees[i], trees[j], poses, QueryMethod::tandem, args.passes);
            pair_ns[i][j] = 1e9 * std::max(total - leaf_seconds * leaf, 0.0) / std::max(inner, 1.0);
        }

    const auto self_ns = [&](BvType type) {
        const auto index = static_cast<std::size_t>(type);
        return pair_ns[index][index];
    };
    const double aabb = self_ns(BvType::aabb);
    // With -o - the weights file is standard output, so that it pipes into --type-weight @/dev/stdin: the table
    // then goes to standard error.
    std::FILE* const table = args.output == "-" ? stderr : stdout;
    fmt::print(table, "ns per inner-node test (row: this tree's kind, column: the other tree's)\n{}",
               pair_table_text(pair_ns, ""));
    std::string weights;
    fmt::print(table, "\n{:<8} {:>12} {:>8}\n", "kind", "ns per test", "weight");
    for (BvType type : all_bv_types) {
        const double ns = self_ns(type);  // against its own kind
        // A kind whose share could not be told from the noise (0 after the leaf tests) keeps weight 1; the floor
        // keeps every weight one that --type-weight accepts (positive at the printed precision).
        const double weight = aabb > 0.0 && ns > 0.0 ? std::max(ns / aabb, 0.001) : 1.0;
        fmt::print(table, "{:<8} {:>12.2f} {:>8.3f}\n", to_string(type), ns, weight);
        weights += fmt::format("{}{}={:.3f}", weights.empty() ? "" : ",", to_string(type), weight);
    }
    fmt::print(table, "{:<8} {:>12.2f}   (primitive test, for reference)\n", "leaf", 1e9 * leaf_seconds);
    if (!args.output.empty()) {
        if (Status written = write_output(args.output, weights_file(pair_ns, weights)); !written)
            return report_error(written.error());
        if (args.output != "-") fmt::print(table, "weights written to {} (use: --type-weight @{})\n", args.output, args.output);
    }
    return exit_ok;
}

}  // namespace

void add_calibrate_command(CLI::App& app, Command& command) {
    auto args = std::make_shared<CalibrateArguments>();
    CLI::App* sub = app.add_subcommand(
        "calibrate",
        "Measure the tandem traversal's inner-node test cost per pair of BV kinds; write per-kind weights");
    sub->add_option("--primitives", args->primitives, "Primitives in the generated scene")
        ->capture_default_str()
        ->check(whole_number(20, 100000));
    sub->add_option("--queries", args->queries, "Recorded simulator queries each tree answers")
        ->capture_default_str()
        ->check(whole_number(10, 100000));
    sub->add_option("--passes", args->passes, "Timed passes over the queries; the fastest counts")
        ->capture_default_str()
        ->check(whole_number(1, 1000));
    sub->add_option("-o,--output", args->output, "Write the weights (type=weight,...) to this file")
        ->check(output_name());
    sub->footer("Example: hbvh calibrate -o weights.txt && hbvh build model.xml --type-weight @weights.txt");
    sub->callback([&command, args] { command = [args] { return run_calibrate(*args); }; });
}

}  // namespace hbvh::cli
