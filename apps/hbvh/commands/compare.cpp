// SPDX-License-Identifier: MIT
// `hbvh compare`: every builder on every model, as the survey's Tables 2 and 3, with each row's gap to
// the proven optimum (the `optimal` builder's subset DP) on models small enough for it.
#include <fmt/core.h>

#include <algorithm>
#include <limits>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands/command.hpp"
#include "commands/json_text.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh::cli {
namespace {
struct CompareArguments {
    std::vector<std::string> inputs;
    std::string algorithm_list;  // empty = all registered
    BuilderFlags builder;
    int repeats = 5;
    /// Models with at most this many primitives get the optimum (and a gap column); clamped to the
    /// optimal builder's own limit, since compare never lets it fall back to a heuristic tree.
    std::uint32_t optimum_max_primitives = OptimalOptions{}.max_primitives;
    /// Search-node budget per call of the survey's reference branch and bound (bnb-tightest, bnb-enlarge,
    /// and the bnb-enlarge tree inside bnb-exact); 0 keeps the library default.
    std::uint64_t bnb_nodes = 0;
    bool json = false;
    bool markdown = false;
};

struct Row {
    std::string model;
    std::string algorithm;
    std::size_t primitives = 0;
    double median_ms = 0.0;
    std::uint32_t candidates = 0;
    double cost = 0.0;
    std::uint32_t height = 0;
    std::optional<double> relative;  ///< cost / two-level cost; none where both are 0 (one primitive, flat boxes)
    std::optional<double> gap;  ///< cost / optimum - 1, when the model's optimum is known
    std::optional<double> optimum;  ///< Set on `optimal` rows that finished: the proven optimum's Eq. 2 cost
    bool budget_hit = false;
    std::string error;    ///< The build failed: no numbers, and compare exits 1
    std::string skipped;  ///< Not built, on purpose (--optimum-max-primitives): no numbers
};

/// "12.34 %" (or "-" when unknown) for the text and Markdown tables. A tree as cheap as the optimum may
/// differ from it in the last bits; that prints as 0.00 %, not -0.00 %.
std::string format_gap(const std::optional<double>& gap) {
    if (!gap) return "-";
    return fmt::format("{:.2f} %", std::abs(*gap) < 5e-5 ? 0.0 : 100.0 * *gap);
}

std::vector<std::string> split_names(const std::string& list) {
    std::vector<std::string> names;
    std::size_t start = 0;
    while (start <= list.size()) {
        const std::size_t comma = std::min(list.find(',', start), list.size());
        if (comma > start) names.push_back(list.substr(start, comma - start));
        start = comma + 1;
    }
    return names;
}

/// Builds `repeats` times; the median time is robust to the odd slow run on a shared machine.
/// What compare tunes beyond the flags: optimal never falls back (an `optimal` row is the optimum or an
/// error, never bnb-exact's tree under optimal's name), and --bnb-nodes caps the survey's search.
struct CompareSettings {
    BuildRequest request;
    std::uint64_t bnb_nodes = 0;
};

/// One build of `algorithm` with compare's settings; the deadline counts from now.
Result<Bvh> build_for_compare(const std::vector<Primitive>& primitives, Algorithm algorithm,
                              const CompareSettings& settings, BuildReport& report) {
    BuildContext context = settings.request.context.with_time_limit(settings.request.time_limit_seconds);
    context.report = &report;
    if (algorithm == Algorithm::optimal) {
        OptimalOptions options;
        options.fall_back = false;
        return build_optimal(primitives, context, options);
    }
    if (algorithm == Algorithm::bnb_tightest) {
        BnbTightestOptions options;
        if (settings.bnb_nodes > 0) options.budget.max_nodes = settings.bnb_nodes;
        return build_bnb_tightest(primitives, context, options);
    }
    if (algorithm == Algorithm::bnb_enlarge) {
        BnbEnlargeOptions options;
        if (settings.bnb_nodes > 0) options.budget.max_nodes = settings.bnb_nodes;
        return build_bnb_enlarge(primitives, context, options);
    }
    if (algorithm == Algorithm::bnb_exact) {
        BnbExactOptions options;
        if (settings.bnb_nodes > 0) options.enlarge_options.budget.max_nodes = settings.bnb_nodes;
        return build_bnb_exact(primitives, context, options);
    }
    return build_requested(primitives, algorithm, context, settings.request.refine, settings.request.treelets);
}

Row measure(const std::vector<Primitive>& primitives, Algorithm algorithm, const CompareSettings& settings, int repeats) {
    Row row;
    row.algorithm = std::string(to_string(algorithm));
    row.primitives = primitives.size();
    std::vector<double> times;
    for (int r = 0; r < repeats; ++r) {
        BuildReport report;
        const auto start = std::chrono::steady_clock::now();
        Result<Bvh> bvh = build_for_compare(primitives, algorithm, settings, report);
        times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        if (!bvh) {
            row.error = bvh.error().to_string();
            return row;
        }
        const Stats stats = compute_stats(bvh.value(), settings.request.context.policy);
        row.cost = stats.cost;
        row.height = stats.height;
        row.candidates = report.total_candidates;
        row.budget_hit = report.budget_hit;
        // An optimal build stopped by --time-limit returns a tree it could not prove optimal: no optimum, no gaps.
        if (algorithm == Algorithm::optimal && !report.budget_hit) row.optimum = stats.cost;
        // A build that takes seconds is measured once: its median would not change the table.
        if (times.back() > 1000.0) break;
    }
    std::sort(times.begin(), times.end());
    row.median_ms = times[times.size() / 2];
    return row;
}

/// What a row without a tree prints in place of its numbers: "error: ..." or "skipped: ...".
std::string why_no_numbers(const Row& row) { return row.error.empty() ? "skipped: " + row.skipped : "error: " + row.error; }

/// `text` for a Markdown table cell: a '|' would end the cell, a line break the row (a file name may hold either).
std::string markdown_cell(const std::string& text) {
    std::string out;
    for (const char c : text) {
        if (c == '|') out += '\\';
        out += c == '\n' || c == '\r' ? ' ' : c;
    }
    return out;
}

/// The cost relative to the two-level tree's, or "-" where that is 0/0.
std::string format_relative(const std::optional<double>& relative) {
    return relative ? fmt::format("{:.3f}", *relative) : std::string("-");
}

void print_markdown(const std::vector<Row>& rows) {
    fmt::print("| model | algorithm | primitives | time (ms) | MC | cost | height | cost / two-level | gap to optimum |\n");
    fmt::print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    for (const Row& row : rows) {
        if (!row.error.empty() || !row.skipped.empty()) {
            fmt::print("| {} | {} | {} | {} | | | | | |\n", markdown_cell(row.model), row.algorithm, row.primitives,
                       why_no_numbers(row));
            continue;
        }
        fmt::print("| {} | {} | {} | {:.3f}{} | {} | {:.6g} | {} | {} | {} |\n", markdown_cell(row.model), row.algorithm,
                   row.primitives, row.median_ms, row.budget_hit ? " (budget hit)" : "", row.candidates, row.cost,
                   row.height, format_relative(row.relative), format_gap(row.gap));
    }
}

void print_text(const std::vector<Row>& rows) {
    fmt::print("{:<20} {:<16} {:>6} {:>11} {:>6} {:>14} {:>6} {:>9} {:>10}\n", "model", "algorithm", "prims", "time-ms",
               "MC", "cost", "height", "vs-2lvl", "gap-opt");
    for (const Row& row : rows) {
        if (!row.error.empty() || !row.skipped.empty()) {
            fmt::print("{:<20} {:<16} {:>6} {}\n", row.model, row.algorithm, row.primitives, why_no_numbers(row));
            continue;
        }
        fmt::print("{:<20} {:<16} {:>6} {:>11.3f} {:>6} {:>14.6g} {:>6} {:>9} {:>10}{}\n", row.model, row.algorithm,
                   row.primitives, row.median_ms, row.candidates, row.cost, row.height, format_relative(row.relative),
                   format_gap(row.gap), row.budget_hit ? "  budget-hit" : "");
    }
}

void print_json(const std::vector<Row>& rows) {
    nlohmann::json out = nlohmann::json::array();
    for (const Row& row : rows) {
        nlohmann::json entry{{"model", row.model},         {"algorithm", row.algorithm}, {"primitives", row.primitives},
                             {"time_ms", row.median_ms},   {"candidates", row.candidates}, {"cost", row.cost},
                             {"height", row.height},
                             {"relative_to_two_level", row.relative ? nlohmann::json(*row.relative) : nlohmann::json(nullptr)},
                             {"budget_hit", row.budget_hit}};
        // A fraction (0.05 = 5 % above the optimum); null where the optimum is unknown.
        entry["gap_to_optimum"] = row.gap ? nlohmann::json(*row.gap) : nlohmann::json(nullptr);
        if (!row.error.empty() || !row.skipped.empty()) {
            // No tree, so no numbers: a cost of 0 would read as the cheapest tree of all.
            for (const char* key : {"time_ms", "candidates", "cost", "height", "relative_to_two_level"}) entry[key] = nullptr;
            if (!row.error.empty()) entry["error"] = row.error;
            if (!row.skipped.empty()) entry["skipped"] = row.skipped;
        }
        out.push_back(entry);
    }
    fmt::print("{}\n", json_text(out, 2));
}

int run_compare(const CompareArguments& args) {
    std::vector<Algorithm> chosen;
    if (args.algorithm_list.empty()) {
        for (const AlgorithmInfo& info : algorithms()) chosen.push_back(info.algorithm());
    } else {
        for (const std::string& name : split_names(args.algorithm_list)) {
            const std::optional<Algorithm> algorithm = parse_algorithm(name);
            if (!algorithm) {
                fmt::print(stderr, "hbvh compare: unknown algorithm '{}' (see `hbvh algorithms`)\n", name);
                return exit_bad_usage;
            }
            chosen.push_back(*algorithm);
        }
    }
    Result<BuildRequest> resolved = args.builder.resolve();
    if (!resolved) {
        fmt::print(stderr, "hbvh compare: {}\n", resolved.error().to_string());
        return exit_bad_usage;
    }
    const CompareSettings settings{resolved.value(), args.bnb_nodes};
    const std::uint32_t optimum_limit =
        std::min({args.optimum_max_primitives, OptimalOptions{}.max_primitives, optimal_hard_limit});
    std::vector<Row> rows;
    for (const std::string& input : args.inputs) {
        // The file's stem, unless another input has the same one (d1/m.xml, d2/m.xml): then the path as given.
        const std::string stem = std::filesystem::path(input).stem().string();
        const bool shared_stem = std::count_if(args.inputs.begin(), args.inputs.end(), [&](const std::string& other) {
                                     return std::filesystem::path(other).stem().string() == stem;
                                 }) > 1;
        const std::string name = shared_stem ? input : stem;
        Result<Model> model = load_model(input);
        if (!model) {
            // One unreadable model is a failed row, not the end of the table: the others are still measured, and
            // compare exits 1 (it printed nothing for the models before it).
            report_error(model.error());
            Row row;
            row.model = name;
            row.algorithm = "-";
            row.error = model.error().to_string();
            rows.push_back(std::move(row));
            continue;
        }
        report_warnings(model->warnings);
        const std::size_t count = model->primitives.size();
        fmt::print(stderr, "hbvh compare: {} ({})\n", name, counted(count, "primitive", "primitives"));
        const double baseline = measure(model->primitives, Algorithm::two_level, settings, 1).cost;
        const std::size_t first = rows.size();
        for (Algorithm algorithm : chosen) {
            Row row;
            if (algorithm == Algorithm::optimal && count > optimum_limit) {
                // Not built: its subset DP doubles per primitive (docs/solver.md §2).
                row.algorithm = std::string(to_string(algorithm));
                row.primitives = count;
                row.skipped = fmt::format("{} primitives > {} (--optimum-max-primitives)", count, optimum_limit);
            } else {
                row = measure(model->primitives, algorithm, settings, args.repeats);
            }
            row.model = name;
            if (baseline > 0.0) row.relative = row.cost / baseline;
            rows.push_back(std::move(row));
        }
        // The optimum: the `optimal` row's when the list has one, else one extra build.
        std::optional<double> optimum;
        if (count <= optimum_limit) {
            for (std::size_t i = first; i < rows.size() && !optimum; ++i) optimum = rows[i].optimum;
            if (!optimum) optimum = measure(model->primitives, Algorithm::optimal, settings, 1).optimum;
        }
        if (optimum && *optimum > 0.0)
            for (std::size_t i = first; i < rows.size(); ++i)
                if (rows[i].error.empty()) rows[i].gap = rows[i].cost / *optimum - 1.0;
    }
    if (args.json)
        print_json(rows);
    else if (args.markdown)
        print_markdown(rows);
    else
        print_text(rows);
    // Every row is printed, and a failed build still fails the command.
    const bool failed = std::any_of(rows.begin(), rows.end(), [](const Row& row) { return !row.error.empty(); });
    return failed ? exit_bad_input : exit_ok;
}
}  // namespace

void add_compare_command(CLI::App& app, Command& command) {
    auto args = std::make_shared<CompareArguments>();
    CLI::App* sub = app.add_subcommand("compare", "Run builders on models and tabulate time and cost (survey Tables 2-3)");
    sub->add_option("files", args->inputs, "Primitive files")->required();
    // -a names the builders here too (one or a list), as it names the one builder of the other commands; a
    // --quality preset is a builder's name (`-a fast`), so compare has no --quality.
    sub->add_option("-a,--algorithm,--algorithms", args->algorithm_list,
                    "Comma-separated builders (default: all registered)");
    sub->add_option("--repeat", args->repeats, "Builds per row; the median time is reported")
        ->capture_default_str()
        ->check(whole_number(1, 1000));
    sub->add_option("--optimum-max-primitives", args->optimum_max_primitives,
                    "Compute the optimum (gap column) for models up to this size, at most the optimal builder's "
                    "limit; above it an `optimal` row is skipped (reported as skipped, with no numbers)")
        ->capture_default_str();
    // whole_number: CLI11 alone wraps "-1" to 2^64 - 1, an unlimited budget.
    sub->add_option("--bnb-nodes", args->bnb_nodes,
                    "Search-node budget per solver call of the survey's branch and bound (0 = library default)")
        ->check(whole_number(0, std::numeric_limits<std::uint64_t>::max()));
    args->builder.add_to(*sub, /*choose_builder=*/false);
    CLI::Option* json = sub->add_flag("--json", args->json, "Print JSON");
    sub->add_flag("--markdown", args->markdown, "Print a Markdown table")->excludes(json);
    sub->footer(
        "Gap to optimum: cost / optimum - 1 (JSON: gap_to_optimum, a fraction, null when unknown), where the\n"
        "optimum is the optimal builder's proven Eq. 2 minimum; computed for models of at most\n"
        "--optimum-max-primitives primitives. Rows whose solver stopped at its budget are marked.\n"
        "--time-limit bounds every build, optimal's too (bnb-tightest and bnb-enlarge spread it over their solver\n"
        "calls); an optimal build it stops proves no optimum, so that model's gaps are then unknown.\n"
        "A row whose build fails, or a model that cannot be read (algorithm '-'), prints its error; the other\n"
        "rows are still measured, and compare then exits 1. cost / two-level is '-' (JSON null) where both are 0.\n"
        "Example: hbvh compare data/models/*.xml --markdown");
    sub->callback([&command, args] { command = [args] { return run_compare(*args); }; });
}

}  // namespace hbvh::cli
