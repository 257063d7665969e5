// SPDX-License-Identifier: MIT
// `hbvh build`: primitives in, hierarchy out (the survey's XML).
#include <fmt/core.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "commands/command.hpp"
#include "hbvh/io/file.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/tree/binary_format.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh::cli {
namespace {
struct BuildArguments {
    std::string input;
    std::string output = "-";
    std::string format;
    BuilderFlags builder;
    bool report = false;
    bool stats = false;
};

/// What is proven about the tree's cost: "lower bound L over trees of fit_best volumes, gap G %" when the builder
/// knows such a bound
/// (BuildReport::lower_bound > 0; only `optimal` does, with L = the optimum), else "no global bound known".
std::string bound_summary(const BuildReport& report, double cost) {
    std::string text = "no global bound known";
    if (report.lower_bound > 0.0) {
        // The bound and the tree's recomputed cost may differ in the last bits: print that as 0.00 %.
        const double gap = cost / report.lower_bound - 1.0;
        // A bound over the trees whose every volume is fit_best's: a tree whose volumes came from elsewhere (auto's
        // refinement keeps an existing volume where it is smaller) can be cheaper still, by up to 1 % on small sets.
        text = fmt::format("lower bound {:.6g} over trees of fit_best volumes, gap {:.2f} %", report.lower_bound,
                           std::abs(gap) < 5e-5 ? 0.0 : 100.0 * gap);
    }
    if (report.budget_hit) text += "; budget hit (best tree found within the node/time budget)";
    return text;
}

void print_report(const BuildReport& report, double seconds, double cost) {
    // Insertion, splitting and merging build no levels; a header over no rows would look like a failure.
    if (report.levels.empty())
        fmt::print(stderr, "levels: none reported (the builder that made this tree does not work level by level)\n");
    else
        fmt::print(stderr, "{:>5} {:>7} {:>10} {:>13} {:>7} {:>11}  notes\n", "level", "nodes", "candidates",
                   "solver-nodes", "groups", "time-ms");
    for (std::size_t i = 0; i < report.levels.size(); ++i) {
        const LevelReport& level = report.levels[i];
        fmt::print(stderr, "{:>5} {:>7} {:>10} {:>13} {:>7} {:>11.3f}  {}{}\n", i, level.nodes, level.candidates,
                   level.solver_nodes, level.groups, 1e3 * level.seconds, level.fallback_used ? "fallback " : "",
                   level.budget_hit ? "budget-hit" : "");
    }
    for (const std::string& note : report.notes) fmt::print(stderr, "note: {}\n", note);
    fmt::print(stderr, "cost: {:.6g}; {}\n", cost, bound_summary(report, cost));
    fmt::print(stderr, "total: {:.3f} ms\n", 1e3 * seconds);
}

/// A progress callback drawing a bar on stderr, or an empty one when stderr is not a terminal. The bar
/// appears only once the build has run for a second, so quick builds print nothing.
std::function<void(double)> progress_bar(std::chrono::steady_clock::time_point start, bool& drawn) {
    if (isatty(STDERR_FILENO) == 0) return {};
    return [start, &drawn](double fraction) {
        if (std::chrono::steady_clock::now() - start < std::chrono::seconds(1)) return;
        constexpr int width = 40;
        const int filled = static_cast<int>(fraction * width + 0.5);
        fmt::print(stderr, "\r[{:<{}}] {:3.0f} %", std::string(static_cast<std::size_t>(filled), '#'), width, 100.0 * fraction);
        std::fflush(stderr);
        drawn = true;
    };
}

int run_build(const BuildArguments& args) {
    Result<Model> model = load_model(args.input, args.format);
    if (!model) return report_error(model.error());
    if (const std::string problem = output_replaces_input(args.input, args.output, model->imported); !problem.empty()) {
        fmt::print(stderr, "hbvh build: {}\n", problem);
        return exit_bad_usage;
    }
    report_warnings(model->warnings);
    if (Status stored = check_stored_hierarchy(model.value(), args.builder); !stored) return report_error(stored.error());
    Result<BuildRequest> request = args.builder.resolve();
    if (!request) {
        fmt::print(stderr, "hbvh build: {}\n", request.error().to_string());
        return exit_bad_usage;
    }
    BuildReport report;
    request->context.report = &report;
    const auto start = std::chrono::steady_clock::now();
    bool bar_drawn = false;
    request->context.progress = progress_bar(start, bar_drawn);
    const Algorithm algorithm = request->algorithm;
    const VolumePolicy& policy = request->context.policy;
    Result<Bvh> bvh = request->run(model->primitives);
    if (bar_drawn) fmt::print(stderr, "\n");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!bvh) return report_error(bvh.error());
    if (!report.substitution.empty()) report_warnings({report.substitution});
    if (args.report || args.stats) {
        const Stats stats = compute_stats(bvh.value(), policy);
        if (args.report) print_report(report, seconds, stats.cost);
        if (args.stats)
            fmt::print(stderr, "{}: {}, {}, height {}, cost {:.6g} ({} in {:.3f} ms); {}\n", args.input,
                       counted(stats.leaves, "primitive", "primitives"), counted(stats.nodes, "node", "nodes"),
                       stats.height, stats.cost,
                       report.built_by.empty() ? std::string(to_string(algorithm))
                                               : std::string(to_string(algorithm)) + ", built by " + report.built_by,
                       1e3 * seconds,
                       bound_summary(report, stats.cost));
    }
    // -o NAME.hbvh writes the binary format, anything else the survey XML.
    const bool binary = lower_case_extension(args.output) == ".hbvh";
    const std::string content = binary ? write_binary(bvh.value()) : write_xml(bvh.value());
    if (Status written = write_output(args.output, content); !written) return report_error(written.error());
    return exit_ok;
}
}  // namespace

void add_build_command(CLI::App& app, Command& command) {
    auto args = std::make_shared<BuildArguments>();
    CLI::App* sub = app.add_subcommand("build", "Build a hierarchy over a set of primitives");
    sub->add_option("input", args->input, "Primitive file (survey XML, MJCF, URDF, mesh), or - for stdin")->required();
    sub->add_option("-o,--output", args->output, "Output hierarchy (survey XML; .hbvh: binary), or - for stdout")
        ->capture_default_str()
        ->check(hierarchy_output_name());
    sub->add_option("--format", args->format, "Input format when the extension does not tell")
        ->check(input_format());
    args->builder.add_to(*sub);
    args->builder.add_refit_to(*sub);
    sub->add_flag("--report", args->report,
                  "Print the per-level build report to stderr, with the proven lower bound and gap when known");
    sub->add_flag("--stats", args->stats,
                  "Print a one-line summary (cost, height, time, lower bound and gap when known) to stderr");
    sub->footer("Example: hbvh build data/models/chair.xml -a two-level -o chair.hbvh.xml --stats");
    sub->callback([&command, args] { command = [args] { return run_build(*args); }; });
}

}  // namespace hbvh::cli
