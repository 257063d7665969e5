// SPDX-License-Identifier: MIT
// Input, output and error reporting shared by all subcommands.
#include <fmt/core.h>

#include <iostream>
#include <iterator>

#include "commands/command.hpp"
#include "hbvh/io/file.hpp"
#include "hbvh/io/xml.hpp"

namespace hbvh::cli {

Result<Model> load_model(const std::string& path, const std::string& format) {
    std::string text;
    if (path == "-") {
        text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
    } else {
        Result<std::string> file = read_text_file(path);
        if (!file) return file.error();
        text = std::move(file.value());
    }
    if (!format.empty() && format != "xml") return Error{"unknown input format '" + format + "'", path};
    Result<XmlModel> xml = read_xml_string(text, path == "-" ? "<stdin>" : path);
    if (!xml) return xml.error();
    return Model{std::move(xml->primitives), std::move(xml->hierarchy), {}};
}

Status write_output(const std::string& path, const std::string& content) {
    if (path == "-") {
        std::fwrite(content.data(), 1, content.size(), stdout);
        if (std::fflush(stdout) != 0) return Error{"cannot write to standard output", "-"};
        return Ok{};
    }
    return write_file_atomic(path, content);
}

int report_error(const Error& error) {
    fmt::print(stderr, "hbvh: {}\n", error.to_string());
    return exit_bad_input;
}

void report_warnings(const std::vector<std::string>& warnings) {
    for (const std::string& warning : warnings) fmt::print(stderr, "hbvh: warning: {}\n", warning);
}

void BuilderFlags::add_to(CLI::App& command) {
    command.add_option("-a,--algorithm", algorithm, "Construction algorithm (see `hbvh algorithms`)")
        ->capture_default_str();
    command.add_option("--types", types, "Allowed BV types for inner nodes, comma-separated")->capture_default_str();
    command.add_option("--type-weight", type_weights,
                       "Per-type cost weights, e.g. obb=1.5,capsule=1.2 (default 1 each)");
    command.add_option("--time-limit", time_limit_seconds,
                       "Seconds the build may take (0 = no limit); scale and bnb-exact return their best by then")
        ->check(CLI::NonNegativeNumber);
}

Result<std::pair<Algorithm, BuildOptions>> BuilderFlags::resolve() const {
    const std::optional<Algorithm> chosen = parse_algorithm(algorithm);
    if (!chosen) return Error{"unknown algorithm '" + algorithm + "' (see `hbvh algorithms`)"};
    Result<VolumePolicy> policy = parse_allowed_types(types);
    if (!policy) return policy.error();
    if (!type_weights.empty()) {
        policy = parse_type_weights(type_weights, policy.value());
        if (!policy) return policy.error();
    }
    BuildOptions options;
    options.policy = policy.value();
    options.time_limit_seconds = time_limit_seconds;
    return std::pair{*chosen, options};
}

Result<Bvh> hierarchy_of(const Model& model, const BuilderFlags& flags) {
    if (model.hierarchy) return *model.hierarchy;
    Result<std::pair<Algorithm, BuildOptions>> resolved = flags.resolve();
    if (!resolved) return resolved.error();
    return build(model.primitives, resolved->first, resolved->second);
}

}  // namespace hbvh::cli
