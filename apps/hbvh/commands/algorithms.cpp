// SPDX-License-Identifier: MIT
// `hbvh algorithms`: the registered builders, one line each.
#include <fmt/core.h>

#include "commands/command.hpp"

namespace hbvh::cli {

void add_algorithms_command(CLI::App& app, Command& command) {
    CLI::App* sub = app.add_subcommand("algorithms", "List the registered construction algorithms");
    sub->callback([&command] {
        command = [] {
            for (const AlgorithmInfo& info : algorithms()) fmt::print("{:<18} {}\n", info.name, info.summary);
            return exit_ok;
        };
    });
}

}  // namespace hbvh::cli
