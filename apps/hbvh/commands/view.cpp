// SPDX-License-Identifier: MIT
// `hbvh view`: one self-contained HTML page that shows a hierarchy level by level.
#include <fmt/core.h>

#include <filesystem>
#include <memory>

#include "commands/command.hpp"
#include "hbvh/io/file.hpp"
#include "hbvh/io/view_html.hpp"

namespace hbvh::cli {
namespace {
struct ViewArguments {
    std::string input;
    std::string format;
    std::string output = "view.html";
    std::string title;
    BuilderFlags builder;
};

int run_view(const ViewArguments& args) {
    // The page is HTML whatever the name says; an extension of another format is a mistake best caught before
    // the build (a .gltf holding HTML would fail later, in another program).
    if (const std::string extension = lower_case_extension(args.output);
        args.output != "-" && !extension.empty() && extension != ".html" && extension != ".htm") {
        fmt::print(stderr, "hbvh view: the output '{}' is not named .html: view writes an HTML page (for glTF, DOT or "
                           "SVG use `hbvh export`)\n", args.output);
        return exit_bad_usage;
    }
    const std::optional<BuildRequest> request = resolve_or_report(args.builder, "view");
    if (!request) return exit_bad_usage;
    Result<Model> model = load_model(args.input, args.format);
    if (!model) return report_error(model.error());
    report_warnings(model->warnings);
    Result<Bvh> bvh = hierarchy_of(model.value(), *request, args.builder);
    if (!bvh) return report_error(bvh.error());
    // Default title: the input's file name, which is what a user has open in several tabs.
    const std::string title = !args.title.empty()    ? args.title
                              : args.input == "-" ? std::string("hbvh")
                                                  : std::filesystem::path(args.input).filename().string();
    if (Status written = write_output(args.output, export_html(bvh.value(), title)); !written)
        return report_error(written.error());
    return exit_ok;
}
}  // namespace

void add_view_command(CLI::App& app, Command& command) {
    auto args = std::make_shared<ViewArguments>();
    CLI::App* sub = app.add_subcommand("view", "An offline HTML page showing a hierarchy level by level");
    sub->add_option("file", args->input, "Hierarchy file, or a primitive set (built first with -a)")->required();
    sub->add_option("-o,--output", args->output, "Output HTML page, or - for stdout")
        ->capture_default_str()
        ->check(output_name());
    sub->add_option("--format", args->format, "Input format when the extension does not tell")
        ->check(input_format());
    sub->add_option("--title", args->title, "Page title (default: the input's file name)");
    args->builder.add_to(*sub);
    args->builder.add_refit_to(*sub);
    sub->footer("Example: hbvh view data/models/chair.xml -o chair.html, then open chair.html#level=2\n"
                "See docs/export.md.");
    sub->callback([&command, args] { command = [args] { return run_view(*args); }; });
}

}  // namespace hbvh::cli
