// SPDX-License-Identifier: MIT
// `hbvh convert`: MJCF, URDF or a mesh in, the survey's primitive XML out.
#include <fmt/core.h>

#include <optional>

#include "commands/command.hpp"
#include "hbvh/io/file.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/tree/binary_format.hpp"

namespace hbvh::cli {

void add_convert_command(CLI::App& app, Command& command) {
    struct ConvertArguments {
        std::string input;
        std::string output = "-";
        std::string format;
        BuilderFlags checks;  ///< Only its --refit is used: convert builds nothing.
    };
    auto args = std::make_shared<ConvertArguments>();
    CLI::App* sub = app.add_subcommand("convert", "Convert MJCF, URDF or a mesh (UBX_/USP_/UCP_/UCX_) to survey XML");
    sub->add_option("input", args->input, "Input file (.xml MJCF or survey, .urdf, .gltf/.glb/.obj/.fbx/.dae)")->required();
    sub->add_option("-o,--output", args->output, "Output survey XML (.hbvh: binary), or - for stdout")
        ->capture_default_str()
        ->check(hierarchy_output_name());
    sub->add_option("--format", args->format, "hbvh, xml, mjcf, urdf or mesh, when the extension does not tell; mesh-nodes: a plain mesh, one fitted primitive per mesh node")
        ->check(input_format());
    args->checks.add_refit_to(*sub);
    sub->footer("Example: hbvh convert robot.urdf -o robot.xml");
    sub->callback([&command, args] {
        command = [args] {
            Result<Model> model = load_model(args->input, args->format);
            if (!model) return report_error(model.error());
            if (const std::string problem = output_replaces_input(args->input, args->output, model->imported);
                !problem.empty()) {
                fmt::print(stderr, "hbvh convert: {}\n", problem);
                return exit_bad_usage;
            }
            report_warnings(model->warnings);
            // A stored hierarchy is checked like everywhere else: converting must not turn a file whose
            // volumes miss their primitives into a binary one that looks trustworthy.
            std::optional<Bvh> hierarchy;
            if (model->hierarchy) {
                Result<Bvh> checked = hierarchy_of(model.value(), BuildRequest{}, args->checks);
                if (!checked) return report_error(checked.error());
                hierarchy = std::move(checked.value());
            }
            // -o NAME.hbvh writes the binary format (a primitive set as a Bvh without nodes), anything else XML.
            std::string content;
            if (lower_case_extension(args->output) == ".hbvh")
                content = write_binary(hierarchy ? *hierarchy : Bvh{{}, model->primitives});
            else
                content = hierarchy ? write_xml(*hierarchy) : write_primitives_xml(model->primitives);
            if (Status written = write_output(args->output, content); !written) return report_error(written.error());
            return exit_ok;
        };
    });
}

}  // namespace hbvh::cli
