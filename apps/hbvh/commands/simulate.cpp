// SPDX-License-Identifier: MIT
// `hbvh simulate`: the survey's §5.3 benchmark — two copies of an object colliding, query time per collision.
#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include "commands/command.hpp"
#include "commands/json_text.hpp"
#include "hbvh/query/simulate.hpp"

namespace hbvh::cli {
namespace {
struct SimulateArguments {
    std::string input;
    std::string format;
    BuilderFlags builder;
    SimulateOptions options;
    bool two_level_query = false;
    bool json = false;
};

nlohmann::json to_json(const QueryStats& stats) {
    return {{"queries", stats.queries},
            {"intersecting", stats.intersecting},
            {"mean_query_ms", stats.mean_query_ms},
            {"mean_bv_tests", stats.mean_bv_tests},
            {"mean_primitive_tests", stats.mean_primitive_tests},
            {"mean_nodes_visited", stats.mean_nodes_visited}};
}

int run_simulate(SimulateArguments args) {
    const std::optional<BuildRequest> request = resolve_or_report(args.builder, "simulate");
    if (!request) return exit_bad_usage;
    Result<Model> model = load_model(args.input, args.format);
    if (!model) return report_error(model.error());
    report_warnings(model->warnings);
    Result<Bvh> bvh = hierarchy_of(model.value(), *request, args.builder);
    if (!bvh) return report_error(bvh.error());
    if (args.two_level_query) args.options.method = QueryMethod::two_level;
    const SimulationResult result = simulate(bvh.value(), args.options);
    // No moving query measured (copies whose roots never meet in flight, such as point spheres): its means would
    // read 0 ms, which a script takes for a result. Fewer than asked for is a result with a warning.
    if (result.moving.queries == 0)
        return report_error(Error{"no moving query was measured in " + std::to_string(result.steps) +
                                      " steps: the moving copy's root never met the other's (an object of zero size?)",
                                  args.input});
    if (!result.complete)
        fmt::print(stderr, "hbvh simulate: warning: stopped after {} steps with {} of the {} collisions asked for\n",
                   result.steps, result.moving.queries, args.options.collision_count);
    if (args.json) {
        // The builder that made the tree (--quality's preset included), or "stored" for a file's own hierarchy;
        // and which query ran.
        const std::string made_by =
            model->hierarchy ? std::string("stored") : std::string(to_string(request->algorithm));
        const nlohmann::json out{{"model", args.input},         {"algorithm", made_by},
                                 {"query", args.two_level_query ? "two-level" : "tandem"},
                                 {"moving", to_json(result.moving)}, {"total", to_json(result.total)},
                                 {"steps", result.steps},       {"restarts", result.restarts},
                                 {"complete", result.complete}};
        fmt::print("{}\n", json_text(out, 2));
    } else {
        const auto line = [](const char* name, const QueryStats& s) {
            fmt::print("{:<8} {:>6} queries ({} intersecting)  {:.4f} ms/query  {:.1f} BV tests  {:.1f} primitive tests\n",
                       name, s.queries, s.intersecting, s.mean_query_ms, s.mean_bv_tests, s.mean_primitive_tests);
        };
        line("moving", result.moving);
        line("total", result.total);
    }
    return exit_ok;
}
}  // namespace

void add_simulate_command(CLI::App& app, Command& command) {
    auto args = std::make_shared<SimulateArguments>();
    CLI::App* sub = app.add_subcommand("simulate", "The survey's collision benchmark (§5.3, Table 4) on two copies of an object");
    sub->add_option("file", args->input, "A hierarchy or a primitive set")->required();
    sub->add_option("--format", args->format, "Input format when the extension does not tell")
        ->check(input_format());
    args->builder.add_to(*sub);
    args->builder.add_refit_to(*sub);
    sub->add_option("--collisions", args->options.collision_count, "Root-overlapping queries to measure")
        ->capture_default_str()
        ->check(whole_number(1, 10000000));
    sub->add_option("--seed", args->options.seed, "Seed of the start states")
        ->capture_default_str()
        ->check(seed_validator());
    sub->add_flag("--two-level-query", args->two_level_query, "Query with the Two-Level method (root, then all pairs)");
    sub->add_flag("--json", args->json, "Print JSON");
    sub->footer("Example: hbvh simulate data/models/chair.xml --collisions 1000 --json");
    sub->callback([&command, args] { command = [args] { return run_simulate(*args); }; });
}

}  // namespace hbvh::cli
