// SPDX-License-Identifier: MIT
// hbvh: builds and queries heterogeneous bounding-volume hierarchies from the command line.
#include <CLI/CLI.hpp>
#include <signal.h>

#include <csignal>
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "commands/command.hpp"
#include "hbvh/files.hpp"
#include "hbvh/io/xml_memory.hpp"
#include "hbvh/version.hpp"

namespace {

/// Ctrl-C, kill or a closed terminal in the middle of writing an output: the temporary file goes (the output is
/// still the old one or absent, as for any failed write), then the signal takes its usual course, so the exit
/// status still says which signal ended the process.
extern "C" void end_on_signal(int signal_number) {
    hbvh::remove_pending_temporary_files();
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
}

void remove_temporaries_on_termination_signals() {
    for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
        struct sigaction action {};
        action.sa_handler = end_on_signal;
        sigemptyset(&action.sa_mask);
        // A signal that was ignored when the process started (nohup, a shell's background job) stays ignored.
        struct sigaction previous {};
        if (::sigaction(signal_number, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
        ::sigaction(signal_number, &action, nullptr);
    }
}

}  // namespace

int main(int argc, char** argv) {
    using namespace hbvh::cli;
    remove_temporaries_on_termination_signals();
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
    // CLI11 answers both a misspelt command and an option before any command with "A subcommand is required".
    if (argc >= 2) {
        const std::string first = argv[1];
        const bool known = first == "-h" || first == "--help" || first == "--version" ||
                           !app.get_subcommands([&](const CLI::App* sub) { return sub->get_name() == first; }).empty();
        if (!known) {
            std::string commands;
            for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
                commands += (commands.empty() ? "" : ", ") + sub->get_name();
            if (first.starts_with('-'))
                std::fprintf(stderr, "hbvh: unknown option '%s': options follow a command (hbvh COMMAND --help)\n",
                             first.c_str());
            else
                std::fprintf(stderr, "hbvh: unknown command '%s' (one of: %s)\n", first.c_str(), commands.c_str());
            return exit_bad_usage;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        // --help and --version arrive here too, with exit code 0.
        return app.exit(error) == 0 ? exit_ok : exit_bad_usage;
    }
    if (!command) return exit_bad_usage;
    int code = exit_bad_usage;
    try {
        code = command();
    } catch (const std::bad_alloc&) {
        // The library returns an Error for every bad input it can see; what it cannot see is how much memory
        // the machine has (a huge file, or a deep hierarchy exported with every level's primitives).
        std::fflush(stdout);
        std::fputs("hbvh: out of memory\n", stderr);
        return exit_bad_input;
    } catch (const std::exception& error) {
        // The last resort: every failure the commands foresee is an Error with its file and line. An exception
        // here is a defect of hbvh, but it must still end in a message and exit 1, not std::terminate's abort.
        std::fflush(stdout);
        std::fprintf(stderr, "hbvh: internal error (please report it): %s\n", error.what());
        return exit_bad_input;
    }
    // Whatever a command printed is checked once here: a full disk or a closed pipe behind standard output must
    // not end in exit 0 (fmt::print and printf buffer, so their errors appear at the flush).
    // A command that failed has said why already (write_output names a failed write itself).
    if ((std::fflush(stdout) != 0 || std::ferror(stdout)) && code == exit_ok) {
        std::fprintf(stderr, "hbvh: cannot write to standard output\n");
        return exit_bad_input;
    }
    return code;
}
