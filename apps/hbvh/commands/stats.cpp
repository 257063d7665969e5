// SPDX-License-Identifier: MIT
// `hbvh stats`: the survey's quality measures of a hierarchy (or of one built from a primitive set).
#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include <cmath>

#include "commands/command.hpp"
#include "commands/json_text.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh::cli {
namespace {
struct StatsArguments {
    std::string input;
    std::string format;
    BuilderFlags builder;
    bool json = false;
};

nlohmann::ordered_json to_json(const Summary& summary) {
    return {{"min", summary.min}, {"mean", summary.mean}, {"max", summary.max}};
}

nlohmann::ordered_json to_json(const Stats& stats) {
    nlohmann::ordered_json types;
    for (BvType type : all_bv_types) types[std::string(to_string(type))] = stats.types[static_cast<std::size_t>(type)];
    return {{"cost", stats.cost},
            {"calibrated_cost", stats.calibrated_cost},
            {"height", stats.height},
            {"nodes", stats.nodes},
            {"inner_nodes", stats.inner_nodes},
            {"leaves", stats.leaves},
            {"branching", to_json(stats.branching)},
            {"tightness", to_json(stats.tightness)},
            {"leaf_depth", to_json(stats.leaf_depth)},
            {"overlap", stats.overlap},
            {"types", types}};
}

void print_text(const Stats& stats) {
    const auto line = [](const char* name, const Summary& s) {
        fmt::print("{:<12} min {:.4g}  mean {:.4g}  max {:.4g}\n", name, s.min, s.mean, s.max);
    };
    fmt::print("{:<12} {:.6g}\n", "cost", stats.cost);
    fmt::print("{:<12} {:.6g}\n", "calibrated", stats.calibrated_cost);
    fmt::print("{:<12} {}\n", "height", stats.height);
    fmt::print("{:<12} {} ({} inner, {})\n", "nodes", stats.nodes, stats.inner_nodes, counted(stats.leaves, "leaf", "leaves"));
    line("branching", stats.branching);
    line("tightness", stats.tightness);
    line("leaf depth", stats.leaf_depth);
    fmt::print("{:<12} {:.4g}\n", "overlap", stats.overlap);
    fmt::print("{:<12} aabb {}  obb {}  sphere {}  capsule {}\n", "types", stats.types[0], stats.types[1], stats.types[2],
               stats.types[3]);
}

/// The stored hierarchy's containment violations, each with its line and message (`"violations"` in --json).
nlohmann::ordered_json violations_json(const Model& model, const Bvh& bvh,
                                       const std::vector<ContainmentViolation>& violations) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const ContainmentViolation& v : violations)
        out.push_back({{"node", v.node},
                       {"line", line_of_node(model.node_lines, v.node)},
                       {"type", to_string(type_of(bvh.nodes[v.node].volume))},
                       {"primitive", v.primitive},
                       {"name", bvh.primitives[v.primitive].name},
                       {"by", v.protrusion},
                       {"message", describe_violation(bvh, v)}});
    return out;
}

int run_stats(const StatsArguments& args) {
    const std::optional<BuildRequest> request = resolve_or_report(args.builder, "stats");
    if (!request) return exit_bad_usage;
    Result<Model> model = load_model(args.input, args.format);
    if (!model) return report_error(model.error());
    report_warnings(model->warnings);
    // A stored hierarchy is measured as it is, violations and all: stats is how a user checks a file. Only
    // --type-weight (which weighs the cost) applies to it.
    warn_if_build_flags_unused(model.value(), args.builder, /*measured=*/true);
    Result<Bvh> bvh = model->hierarchy ? Result<Bvh>(*model->hierarchy) : request->run(model->primitives);
    if (!bvh) return report_error(bvh.error());
    if (Status finite = check_finite_volumes(bvh.value(), model->node_lines, model->source); !finite)
        return report_error(finite.error());
    const std::vector<ContainmentViolation> violations = containment_violations(bvh.value());
    // --type-weight weighs each volume of `cost` (and of `calibrated_cost`), as `build --stats` does; `cost` stays
    // Eq. 2's volume measure whatever --objective the tree was built for.
    VolumePolicy weighted = request->context.policy;
    weighted.measure = NodeMeasure::volume;
    const Stats stats = compute_stats(bvh.value(), weighted);
    // Every volume is finite (above), so an infinite cost is the weights' doing.
    if (!std::isfinite(stats.cost))
        return report_error(Error{"the cost overflows double precision: --type-weight's weights times the volumes "
                                  "exceed it; lower the weights",
                                  model->source});
    if (args.json) {
        nlohmann::ordered_json out = to_json(stats);
        out["violations"] = violations_json(model.value(), bvh.value(), violations);
        fmt::print("{}\n", json_text(out, 2));
    } else {
        print_text(stats);
        if (violations.empty()) {
            fmt::print("{:<12} none (every volume encloses its primitives)\n", "violations");
        } else {
            fmt::print("{:<12} {} volumes do not enclose their primitives (--refit on other commands repairs them)\n",
                       "violations", violations.size());
            for (const ContainmentViolation& v : violations)
                fmt::print("  {}:{}: {}\n", model->source, line_of_node(model->node_lines, v.node),
                           describe_violation(bvh.value(), v));
        }
    }
    return exit_ok;
}
}  // namespace

void add_stats_command(CLI::App& app, Command& command) {
    auto args = std::make_shared<StatsArguments>();
    CLI::App* sub = app.add_subcommand("stats", "Quality measures of a hierarchy (cost Eq. 2, tightness Eq. 1, shape)");
    sub->add_option("file", args->input, "Hierarchy file, or a primitive set (built first with -a)")->required();
    sub->add_option("--format", args->format, "Input format when the extension does not tell")
        ->check(input_format());
    args->builder.add_to(*sub);
    sub->add_flag("--json", args->json, "Print JSON with the keys listed in docs/metrics.md");
    sub->footer("Example: hbvh stats chair.hbvh.xml --json");
    sub->callback([&command, args] { command = [args] { return run_stats(*args); }; });
}

}  // namespace hbvh::cli
