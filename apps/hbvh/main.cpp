// SPDX-License-Identifier: MIT
// hbvh: builds and queries heterogeneous bounding-volume hierarchies from the command line.
#include <CLI/CLI.hpp>
#include <cstdio>

#include "commands/command.hpp"
#include "hbvh/io/xml_memory.hpp"
#include "hbvh/version.hpp"

int main(int argc, char** argv) {
    using namespace hbvh::cli;
    // The program owns its process, so it may set pugixml's process-wide allocator: a large XML file's DOM
    // then lands on huge pages (reading 10^6 primitives took a third of the time on a host with costly page faults).
    hbvh::use_huge_pages_for_xml();
    CLI::App app{"hbvh: builds heterogeneous bounding-volume hierarchies (AABB, OBB, sphere, capsule) over\n"
                 "primitive volumes, measures them, and answers collision queries with them."};
    app.set_version_flag("--version", std::string("hbvh ") + HBVH_VERSION_STRING);
    app.require_subcommand(1);
    Command command;
    add_algorithms_command(app, command);
    add_build_command(app, command);
    add_stats_command(app, command);
    add_generate_command(app, command);
    add_compare_command(app, command);
    add_convert_command(app, command);
    add_collide_command(app, command);
    add_simulate_command(app, command);
    add_export_command(app, command);
    add_view_command(app, command);
    add_calibrate_command(app, command);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        // --help and --version arrive here too, with exit code 0.
        return app.exit(error) == 0 ? exit_ok : exit_bad_usage;
    }
    return command ? command() : exit_bad_usage;
}
