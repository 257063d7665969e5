// SPDX-License-Identifier: MIT
// Input, output and error reporting shared by all subcommands.
#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <iterator>
#include <limits>
#include <system_error>

#include "commands/command.hpp"
#include "hbvh/io/file.hpp"
#include "hbvh/io/model_file.hpp"
#include "hbvh/tree/binary_format.hpp"

namespace hbvh::cli {

namespace {
/// Standard input, as survey XML or .hbvh bytes (other formats need a file name: the importers read files).
Result<ModelFile> read_standard_input(const std::string& format) {
    if (!format.empty() && format != "xml" && format != "hbvh")
        return Error{"standard input is read as survey XML or .hbvh; --format " + format + " needs a file", "<stdin>"};
    // Read once and kept: `-` means the same bytes each time it is given (`hbvh collide - -`: a model against
    // itself), where a second read would find standard input used up.
    static const std::string text{std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>()};
    if (format == "hbvh" && !has_binary_magic(std::as_bytes(std::span(text.data(), text.size()))))
        return Error{"not an .hbvh file (wrong magic bytes)", "<stdin>"};
    return read_model_bytes(text, "<stdin>");
}

/// The file as a Model, without checks across primitives (load_model adds those): read as the Python module
/// reads it (read_model_file).
Result<Model> read_model(const std::string& path, const std::string& format) {
    Result<ModelFile> read = path == "-" ? read_standard_input(format) : read_model_file(path, format);
    if (!read) return read.error();
    return Model{std::move(read).value(), {}};
}
}  // namespace

Result<Model> load_model(const std::string& path, const std::string& format) {
    Result<Model> model = read_model(path, format);
    if (!model) return model;
    model->source = path == "-" ? "<stdin>" : path;
    // Refused here rather than in build() so that the message names the file.
    if (Status checked = check_model_file(*model, model->source); !checked) return checked.error();
    return model;
}

std::string output_replaces_input(const std::string& input, const std::string& output, bool input_imported,
                                  bool any_input) {
    if (input == "-" || output == "-" || !(input_imported || any_input)) return {};
    std::error_code error;
    // equivalent() follows links and compares devices and inodes, so "./robot.xml", a hard link or a symbolic link
    // to the input are caught as well; an output that does not exist yet (the usual case) is an error, not a match.
    if (!std::filesystem::equivalent(input, output, error) || error) return {};
    return "the output '" + output + "' is the input file" +
           (input_imported ? " (an imported model, of which the output would keep only the primitives)" : "") +
           ": writing it would replace the input; give another output name";
}

Status write_output(const std::string& path, const std::string& content) {
    if (path == "-") {
        errno = 0;
        const bool written = std::fwrite(content.data(), 1, content.size(), stdout) == content.size();
        if (!written || std::fflush(stdout) != 0) {
            const std::string reason = errno != 0 ? ": " + std::generic_category().message(errno) : std::string();
            return Error{"cannot write to standard output" + reason, "-"};
        }
        return Ok{};
    }
    return write_file_atomic(path, content);
}

CLI::Validator whole_number(std::uint64_t least, std::uint64_t most) {
    return CLI::Validator(
        [least, most](const std::string& text) {
            std::uint64_t value = 0;
            const auto [end, code] = std::from_chars(text.data(), text.data() + text.size(), value);
            return code == std::errc{} && end == text.data() + text.size() && value >= least && value <= most
                       ? std::string()
                       : "'" + text + "' is not a whole number from " + std::to_string(least) + " to " +
                             std::to_string(most);
        },
        "[" + std::to_string(least) + " - " + std::to_string(most) + "]");
}

CLI::Validator output_name() {
    // An empty name is a slip of the command line (an unset shell variable), not a file that cannot be written.
    return CLI::Validator(
        [](const std::string& name) { return name.empty() ? std::string("the output name is empty") : std::string(); },
        "OUTPUT");
}

CLI::Validator input_format() {
    return CLI::Validator([](const std::string& name) { return input_format_problem(name); }, "FORMAT");
}

CLI::Validator hierarchy_output_name() {
    return CLI::Validator(
        [](const std::string& name) {
            if (name.empty()) return std::string("the output name is empty");
            static constexpr std::string_view others[] = {".gltf", ".glb", ".obj", ".stl", ".ply", ".fbx", ".dae",
                                                          ".dot", ".svg", ".html", ".htm", ".urdf", ".json"};
            const std::string extension = lower_case_extension(name);
            if (std::find(std::begin(others), std::end(others), extension) == std::end(others)) return std::string();
            return "'" + name + "' names another format (" + extension +
                   "): this command writes survey XML, or the binary format for a .hbvh name (glTF, DOT, SVG: "
                   "hbvh export; HTML: hbvh view)";
        },
        "OUTPUT");
}

CLI::Validator seed_validator() { return whole_number(0, std::numeric_limits<std::uint64_t>::max()); }

int report_error(const Error& error) {
    fmt::print(stderr, "hbvh: {}\n", error.to_string());
    return exit_bad_input;
}

void report_warnings(const std::vector<std::string>& warnings) {
    for (const std::string& warning : warnings) fmt::print(stderr, "hbvh: warning: {}\n", warning);
}

void BuilderFlags::add_to(CLI::App& command, bool choose_builder) {
    if (choose_builder) {
        CLI::Option* algorithm_option =
            command.add_option("-a,--algorithm", algorithm, "Construction algorithm (see `hbvh algorithms`)")
                ->capture_default_str();
        command.add_option("--quality", quality,
                           "Preset instead of -a: fast (builds in about a millisecond for dozens of primitives, trees "
                           "that cost more) or auto (the default: the cheapest trees, in 0.02-0.5 s for up to a few hundred primitives)")
            ->check(CLI::IsMember({"fast", "auto"}))
            ->excludes(algorithm_option);
    }
    command.add_option("--types", types, "Allowed BV types for inner nodes, comma-separated")->capture_default_str();
    command.add_option("--type-weight", type_weights,
                       "Per-type cost weights from 1e-6 to 1e6, each type at most once, e.g. obb=1.5,capsule=1.2 (default 1 each), or @FILE as `hbvh calibrate` writes");
    command.add_option("--objective", objective,
                       "Cost the builder minimises: eq2 (Eq. 2, node volume) or calibrated (node "
                       "measured by its Minkowski sum with a turned copy; docs/metrics.md)")
        ->capture_default_str()
        ->check(CLI::IsMember({"eq2", "calibrated"}));
    command.add_option("--time-limit", time_limit_seconds,
                       "Seconds the build may take (0 = no limit); scale and bnb-exact return their best by then")
        ->check(CLI::Validator(
            [](const std::string& text) {
                double seconds = 0.0;
                return CLI::detail::lexical_cast(text, seconds) && seconds >= 0.0  // NaN fails this too
                           ? std::string()
                           : "'" + text + "' is not a number of seconds >= 0 (0: no limit)";
            },
            "SECONDS"));
    command.add_flag("--refine", refine,
                     "Refine the builder's tree by optimal treelet re-arrangement (never costlier; docs/treelets.md)");
    command.add_option("--treelet-units", treelet_units,
                       "Subtrees per treelet for --refine and auto (2^m fits each)")
        ->capture_default_str()
        ->check(whole_number(3, 12));
}

Result<BuildRequest> BuilderFlags::resolve() const {
    // --quality names a registered builder too: "fast" and "auto".
    const std::string& name = quality.empty() ? algorithm : quality;
    const std::optional<Algorithm> chosen = parse_algorithm(name);
    if (!chosen) return Error{"unknown algorithm '" + name + "' (see `hbvh algorithms`)"};
    Result<VolumePolicy> policy = parse_allowed_types(types);
    if (!policy) return policy.error();
    if (!type_weights.empty()) {  // a list, or "@FILE": the weights `hbvh calibrate -o FILE` wrote
        policy = type_weights_from(type_weights, policy.value());
        if (!policy) return policy.error();
    }
    if (objective == "calibrated") policy->measure = NodeMeasure::minkowski;
    BuildRequest request;
    request.algorithm = *chosen;
    request.context.policy = policy.value();
    request.time_limit_seconds = time_limit_seconds;
    request.refine = refine;
    request.treelets.max_units = treelet_units;
    return request;
}

Result<Bvh> build_requested(std::span<const Primitive> primitives, Algorithm algorithm, const BuildContext& context,
                            bool refine, const TreeletOptions& treelets) {
    if (refine) return build_refined(primitives, algorithm, context, treelets);
    if (algorithm == Algorithm::automatic) return build_auto(primitives, context, {false, treelets});
    return build(primitives, algorithm, context);
}

Result<Bvh> BuildRequest::run(std::span<const Primitive> primitives) const {
    return build_requested(primitives, algorithm, context.with_time_limit(time_limit_seconds), refine, treelets);
}

void BuilderFlags::add_refit_to(CLI::App& command) {
    command.add_flag("--refit", refit,
                     "A stored hierarchy whose volumes miss part of their primitives is repaired (each such volume "
                     "refitted, same BV kind, tree kept) instead of refused");
}

namespace {
/// The stored hierarchy if every volume encloses its primitives; with --refit, repaired; else the Error
/// naming the first bad volume's line.
Result<Bvh> checked_stored_hierarchy(const Model& model, const BuilderFlags& flags) {
    std::size_t refitted = 0;
    Result<Bvh> checked =
        enclosing_hierarchy(*model.hierarchy, model.node_lines, model.source, flags.refit, "--refit", &refitted);
    if (checked && refitted > 0)
        fmt::print(stderr, "hbvh: {}: refitted {} of {} volumes that did not enclose their primitives\n", model.source,
                   refitted, model.hierarchy->nodes.size());
    return checked;
}
}  // namespace

Status check_stored_hierarchy(const Model& model, const BuilderFlags& flags) {
    if (!model.hierarchy) return Ok{};
    Result<Bvh> checked = checked_stored_hierarchy(model, flags);
    if (!checked) return checked.error();
    return Ok{};
}

bool BuilderFlags::steer_a_build() const {
    const BuilderFlags defaults;
    return algorithm != defaults.algorithm || quality != defaults.quality || types != defaults.types ||
           type_weights != defaults.type_weights || objective != defaults.objective || refine != defaults.refine ||
           treelet_units != defaults.treelet_units || time_limit_seconds != defaults.time_limit_seconds;
}

std::optional<BuildRequest> resolve_or_report(const BuilderFlags& flags, std::string_view command) {
    Result<BuildRequest> request = flags.resolve();
    if (request) return std::move(request.value());
    fmt::print(stderr, "hbvh {}: {}\n", command, request.error().to_string());
    return std::nullopt;
}

void warn_if_build_flags_unused(const Model& model, const BuilderFlags& flags, bool measured) {
    // stats measures a stored tree and weighs its cost by --type-weight, so that flag is not among the unused.
    BuilderFlags steering = flags;
    if (measured) steering.type_weights.clear();
    if (!model.hierarchy || !steering.steer_a_build()) return;
    fmt::print(stderr,
               "hbvh: warning: {} stores a hierarchy, which is {} as it is: the flags that choose and steer a build "
               "(-a, --quality, --types, {}--objective, --refine, --treelet-units, --time-limit) apply to primitive "
               "sets\n",
               model.source, measured ? "measured" : "used", measured ? "" : "--type-weight, ");
}

Result<Bvh> hierarchy_of(const Model& model, const BuildRequest& request, const BuilderFlags& flags) {
    if (model.hierarchy) {
        warn_if_build_flags_unused(model, flags, /*measured=*/false);
        return checked_stored_hierarchy(model, flags);
    }
    return request.run(model.primitives);
}

}  // namespace hbvh::cli
