// SPDX-License-Identifier: MIT
// `hbvh compare`: every builder on every model, as the survey's Tables 2 and 3.
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "commands/command.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh::cli {
namespace {
struct CompareArguments {
    std::vector<std::string> inputs;
    std::string algorithm_list;  // empty = all registered
    BuilderFlags builder;
    int repeats = 5;
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
    double relative = 0.0;  ///< cost / two-level cost
    bool budget_hit = false;
    std::string error;
};

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
Row measure(const std::vector<Primitive>& primitives, Algorithm algorithm, BuildOptions options, int repeats) {
    Row row;
    row.algorithm = std::string(to_string(algorithm));
    row.primitives = primitives.size();
    std::vector<double> times;
    for (int r = 0; r < repeats; ++r) {
        BuildReport report;
        options.report = &report;
        const auto start = std::chrono::steady_clock::now();
        Result<Bvh> bvh = build(primitives, algorithm, options);
        times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        if (!bvh) {
            row.error = bvh.error().to_string();
            return row;
        }
        const Stats stats = compute_stats(bvh.value(), options.policy);
        row.cost = stats.cost;
        row.height = stats.height;
        row.candidates = report.total_candidates;
        row.budget_hit = report.budget_hit;
        // A build that takes seconds is measured once: its median would not change the table.
        if (times.back() > 1000.0) break;
    }
    std::sort(times.begin(), times.end());
    row.median_ms = times[times.size() / 2];
    return row;
}

void print_markdown(const std::vector<Row>& rows) {
    fmt::print("| model | algorithm | primitives | time (ms) | MC | cost | height | cost / two-level |\n");
    fmt::print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    for (const Row& row : rows) {
        if (!row.error.empty()) {
            fmt::print("| {} | {} | {} | error: {} | | | | |\n", row.model, row.algorithm, row.primitives, row.error);
            continue;
        }
        fmt::print("| {} | {} | {} | {:.3f} | {} | {:.6g} | {} | {:.3f}{} |\n", row.model, row.algorithm, row.primitives,
                   row.median_ms, row.candidates, row.cost, row.height, row.relative,
                   row.budget_hit ? " (budget hit)" : "");
    }
}

void print_text(const std::vector<Row>& rows) {
    fmt::print("{:<20} {:<16} {:>6} {:>11} {:>6} {:>14} {:>6} {:>9}\n", "model", "algorithm", "prims", "time-ms", "MC",
               "cost", "height", "vs-2lvl");
    for (const Row& row : rows) {
        if (!row.error.empty()) {
            fmt::print("{:<20} {:<16} error: {}\n", row.model, row.algorithm, row.error);
            continue;
        }
        fmt::print("{:<20} {:<16} {:>6} {:>11.3f} {:>6} {:>14.6g} {:>6} {:>9.3f}{}\n", row.model, row.algorithm,
                   row.primitives, row.median_ms, row.candidates, row.cost, row.height, row.relative,
                   row.budget_hit ? "  budget-hit" : "");
    }
}

void print_json(const std::vector<Row>& rows) {
    nlohmann::json out = nlohmann::json::array();
    for (const Row& row : rows) {
        nlohmann::json entry{{"model", row.model},         {"algorithm", row.algorithm}, {"primitives", row.primitives},
                             {"time_ms", row.median_ms},   {"candidates", row.candidates}, {"cost", row.cost},
                             {"height", row.height},       {"relative_to_two_level", row.relative},
                             {"budget_hit", row.budget_hit}};
        if (!row.error.empty()) entry["error"] = row.error;
        out.push_back(entry);
    }
    fmt::print("{}\n", out.dump(2));
}

int run_compare(const CompareArguments& args) {
    std::vector<Algorithm> chosen;
    if (args.algorithm_list.empty()) {
        for (const AlgorithmInfo& info : algorithms()) chosen.push_back(info.algorithm);
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
    Result<std::pair<Algorithm, BuildOptions>> resolved = args.builder.resolve();
    if (!resolved) {
        fmt::print(stderr, "hbvh compare: {}\n", resolved.error().to_string());
        return exit_bad_usage;
    }
    const BuildOptions& options = resolved->second;
    std::vector<Row> rows;
    for (const std::string& input : args.inputs) {
        Result<Model> model = load_model(input);
        if (!model) return report_error(model.error());
        report_warnings(model->warnings);
        const double baseline = measure(model->primitives, Algorithm::two_level, options, 1).cost;
        for (Algorithm algorithm : chosen) {
            Row row = measure(model->primitives, algorithm, options, args.repeats);
            row.model = std::filesystem::path(input).stem().string();
            row.relative = baseline > 0.0 ? row.cost / baseline : 1.0;
            rows.push_back(std::move(row));
        }
    }
    if (args.json)
        print_json(rows);
    else if (args.markdown)
        print_markdown(rows);
    else
        print_text(rows);
    return exit_ok;
}
}  // namespace

void add_compare_command(CLI::App& app, Command& command) {
    auto args = std::make_shared<CompareArguments>();
    CLI::App* sub = app.add_subcommand("compare", "Run builders on models and tabulate time and cost (survey Tables 2-3)");
    sub->add_option("files", args->inputs, "Primitive files")->required();
    sub->add_option("--algorithms", args->algorithm_list, "Comma-separated builders (default: all registered)");
    sub->add_option("--repeat", args->repeats, "Builds per row; the median time is reported")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000));
    args->builder.add_to(*sub);
    sub->add_flag("--json", args->json, "Print JSON");
    sub->add_flag("--markdown", args->markdown, "Print a Markdown table");
    sub->footer("Example: hbvh compare data/models/*.xml --markdown");
    sub->callback([&command, args] { command = [args] { return run_compare(*args); }; });
}

}  // namespace hbvh::cli
