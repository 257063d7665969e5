// SPDX-License-Identifier: MIT
// `hbvh generate`: a seeded random primitive set, for tests and benchmarks of any size.
#include "commands/command.hpp"
#include "hbvh/io/file.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/binary_format.hpp"

namespace hbvh::cli {

void add_generate_command(CLI::App& app, Command& command) {
    auto options = std::make_shared<SceneOptions>();
    auto output = std::make_shared<std::string>("-");
    auto uniform = std::make_shared<bool>(false);
    CLI::App* sub = app.add_subcommand("generate", "Write a seeded random set of primitives (survey XML, or .hbvh)");
    sub->add_option("--count", options->count, "Number of primitives")->capture_default_str()->check(whole_number(1, 100000000));
    sub->add_option("--seed", options->seed, "Random seed")->capture_default_str()->check(seed_validator());
    sub->add_flag("--uniform", *uniform, "Scatter uniformly instead of in clusters");
    sub->add_option("-o,--output", *output, "Output file (survey XML; .hbvh: binary), or - for stdout")
        ->capture_default_str()
        ->check(hierarchy_output_name());
    sub->footer("Example: hbvh generate --count 1000 --seed 7 -o scene.xml");
    sub->callback([&command, options, output, uniform] {
        command = [options, output, uniform] {
            options->clustered = !*uniform;
            std::vector<Primitive> primitives = generate_scene(*options);
            // -o NAME.hbvh writes the binary format, as build and convert do (a primitive set: no nodes); it
            // wrote XML under that name, which every reader then refused as a broken binary file.
            const std::string content = lower_case_extension(*output) == ".hbvh"
                                            ? write_binary(Bvh{{}, std::move(primitives)})
                                            : write_primitives_xml(primitives);
            if (Status written = write_output(*output, content); !written)
                return report_error(written.error());
            return exit_ok;
        };
    });
}

}  // namespace hbvh::cli
