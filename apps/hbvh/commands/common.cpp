// SPDX-License-Identifier: MIT
// Input, output and error reporting shared by all subcommands.
#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <iterator>

#include "commands/command.hpp"
#include "hbvh/geometry/validation.hpp"
#include "hbvh/io/file.hpp"
#include "hbvh/io/import.hpp"
#include "hbvh/io/mesh_import.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/tree/binary_format.hpp"
#include "hbvh/tree/refit.hpp"

namespace hbvh::cli {

namespace {
/// A binary file's contents as a Model: a primitive set (node count 0) has no hierarchy, and then its
/// primitives move instead of being copied (at 10^6 primitives, 160 MB).
Result<Model> model_of(Result<Bvh> bvh) {
    if (!bvh) return bvh.error();
    if (bvh->nodes.empty()) return Model{std::move(bvh->primitives), std::nullopt, {}, {}, {}};
    std::vector<Primitive> primitives = bvh->primitives;
    return Model{std::move(primitives), std::move(bvh.value()), {}, {}, {}};
}

/// The file as a Model, without checks across primitives (load_model adds those).
Result<Model> read_model(const std::string& path, const std::string& format) {
    // Before any guess from the extension: a directory named "scene.xml" or "tmp.x1y2" is still a directory.
    std::error_code ignored;
    if (path != "-" && std::filesystem::is_directory(path, ignored)) return Error{"is a directory, not a file", path};
    // A plain mesh (no UBX_/USP_/UCP_/UCX_ pieces) is imported only on request: one fitted primitive per
    // mesh node is a guess at the author's intent, not a reading of it.
    if (format == "mesh-nodes") {
        MeshImportOptions options;
        options.one_primitive_per_mesh = true;
        Result<ImportResult> imported = import_mesh(path, options);
        if (!imported) return imported.error();
        return Model{std::move(imported->primitives), std::nullopt, std::move(imported->warnings), {}, {}};
    }
    // The survey format keeps a stored hierarchy; the importers give primitives only.
    static const std::pair<const char*, ImportFormat> formats[] = {
        {"", ImportFormat::automatic}, {"xml", ImportFormat::survey_xml}, {"mjcf", ImportFormat::mjcf},
        {"urdf", ImportFormat::urdf},  {"mesh", ImportFormat::mesh}};
    const auto chosen = std::find_if(std::begin(formats), std::end(formats),
                                     [&](const auto& entry) { return format == entry.first; });
    if (chosen == std::end(formats))
        return Error{"unknown input format '" + format + "' (expected xml, mjcf, urdf, mesh or mesh-nodes)", path};

    const std::string extension = std::filesystem::path(path).extension().string();
    // A .hbvh name, or (stdin, .xml) the binary format's magic bytes: docs/formats.md, "The binary format".
    const bool binary_name = chosen->second == ImportFormat::automatic && lower_case_extension(path) == ".hbvh";
    const bool maybe_survey = binary_name || path == "-" || chosen->second == ImportFormat::survey_xml ||
                              (chosen->second == ImportFormat::automatic && extension == ".xml");
    // A named .hbvh file goes to the binary reader's own file path, which maps a large file instead of copying it.
    if (binary_name && path != "-") return model_of(read_binary_file(path));
    if (maybe_survey) {
        std::string text;
        if (path == "-") {
            text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
        } else {
            Result<std::string> file = read_text_file(path);
            if (!file) return file.error();
            text = std::move(file.value());
        }
        if (binary_name || has_binary_magic(std::as_bytes(std::span(text))))
            return model_of(read_binary(std::as_bytes(std::span(text)), path == "-" ? "<stdin>" : path));
        // An .xml whose root is <mujoco> is MJCF: hand it to the importer below.
        if (path == "-" || chosen->second == ImportFormat::survey_xml || text.find("<mujoco") == std::string::npos) {
            Result<XmlModel> xml = read_xml_string(text, path == "-" ? "<stdin>" : path);
            if (!xml) return xml.error();
            return Model{std::move(xml->primitives), std::move(xml->hierarchy), {}, {}, std::move(xml->node_lines)};
        }
    }
    Result<ImportResult> imported = import_primitives(path, chosen->second);
    if (!imported) return imported.error();
    if (imported->primitives.empty()) {
        // The importer's warnings say why each candidate was skipped (mesh geoms, unnamed meshes, ...); the
        // error is all the user will see, so it carries them.
        std::string message = "the file holds no collision primitives";
        const std::vector<std::string>& skipped = imported->warnings;
        constexpr std::size_t shown = 3;
        for (std::size_t i = 0; i < std::min(skipped.size(), shown); ++i) message += (i == 0 ? ": " : "; ") + skipped[i];
        if (skipped.size() > shown) message += "; and " + std::to_string(skipped.size() - shown) + " more";
        return Error{message, path};
    }
    return Model{std::move(imported->primitives), std::nullopt, std::move(imported->warnings), {}, {}};
}
}  // namespace

Result<Model> load_model(const std::string& path, const std::string& format) {
    Result<Model> model = read_model(path, format);
    if (!model) return model;
    model->source = path == "-" ? "<stdin>" : path;
    // Refused here rather than in build() so that the message names the file.
    if (Status valid = validate_primitives(model->primitives); !valid) return Error{valid.error().message, model->source};
    if (Status finite = check_finite_extent(model->primitives); !finite) return Error{finite.error().message, model->source};
    if (model->hierarchy)
        if (Status structure = check_structure(*model->hierarchy); !structure)
            return Error{structure.error().message, model->source};
    return model;
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
    CLI::Option* algorithm_option =
        command.add_option("-a,--algorithm", algorithm, "Construction algorithm (see `hbvh algorithms`)")
            ->capture_default_str();
    command.add_option("--quality", quality,
                       "Preset instead of -a: fast (builds in about a millisecond for dozens of primitives, trees "
                       "that cost more) or auto (the default: the cheapest trees, in 0.02-0.5 s for up to a few hundred primitives)")
        ->check(CLI::IsMember({"fast", "auto"}))
        ->excludes(algorithm_option);
    command.add_option("--types", types, "Allowed BV types for inner nodes, comma-separated")->capture_default_str();
    command.add_option("--type-weight", type_weights,
                       "Per-type cost weights, e.g. obb=1.5,capsule=1.2 (default 1 each), or @FILE as `hbvh calibrate` writes");
    command.add_option("--objective", objective,
                       "Cost the builder minimises: eq2 (Eq. 2, node volume) or calibrated (node "
                       "measured by its Minkowski sum with a turned copy; docs/metrics.md)")
        ->capture_default_str()
        ->check(CLI::IsMember({"eq2", "calibrated"}));
    command.add_option("--time-limit", time_limit_seconds,
                       "Seconds the build may take (0 = no limit); scale and bnb-exact return their best by then")
        ->check(CLI::NonNegativeNumber);
    command.add_flag("--refine", refine,
                     "Refine the builder's tree by optimal treelet re-arrangement (never costlier; docs/treelets.md)");
    command.add_option("--treelet-units", treelet_units,
                       "Subtrees per treelet for --refine and auto (2^m fits each)")
        ->capture_default_str()
        ->check(CLI::Range(3u, 12u));
}

Result<BuildRequest> BuilderFlags::resolve() const {
    // --quality names a registered builder too: "fast" and "auto".
    const std::string& name = quality.empty() ? algorithm : quality;
    const std::optional<Algorithm> chosen = parse_algorithm(name);
    if (!chosen) return Error{"unknown algorithm '" + name + "' (see `hbvh algorithms`)"};
    Result<VolumePolicy> policy = parse_allowed_types(types);
    if (!policy) return policy.error();
    if (!type_weights.empty()) {
        // "@FILE": the weights `hbvh calibrate -o FILE` wrote, in the same type=weight syntax.
        std::string list = type_weights;
        if (list.starts_with('@')) {
            Result<std::string> text = read_text_file(list.substr(1));
            if (!text) return text.error();
            list = *text;
            while (!list.empty() && std::isspace(static_cast<unsigned char>(list.back()))) list.pop_back();
        }
        policy = parse_type_weights(list, policy.value());
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

int line_of_node(const Model& model, std::uint32_t node) {
    return node < model.node_lines.size() ? model.node_lines[node] : 0;
}

std::string describe_violation(const Bvh& bvh, const ContainmentViolation& violation) {
    const std::string& name = bvh.primitives[violation.primitive].name;
    return fmt::format("volume ({}) does not enclose primitive {}{} by {:.3g}",
                       to_string(type_of(bvh.nodes[violation.node].volume)), violation.primitive,
                       name.empty() ? std::string{} : " ('" + name + "')", violation.protrusion);
}

namespace {
/// The stored hierarchy if every volume encloses its primitives; with --refit, repaired; else the Error
/// naming the first bad volume's line.
Result<Bvh> checked_stored_hierarchy(const Model& model, const BuilderFlags& flags) {
    const Bvh& stored = *model.hierarchy;
    const std::vector<ContainmentViolation> violations = containment_violations(stored);
    if (violations.empty()) return stored;
    if (!flags.refit) {
        std::string message = describe_violation(stored, violations.front());
        if (violations.size() > 1) message += fmt::format(" (and {} more volumes)", violations.size() - 1);
        return Error{message + "; --refit refits them", model.source, line_of_node(model, violations.front().node)};
    }
    Bvh repaired = stored;
    const std::size_t refitted = refit_non_enclosing(repaired);
    if (Status valid = validate(repaired); !valid) return Error{"after --refit: " + valid.error().message, model.source};
    fmt::print(stderr, "hbvh: {}: refitted {} of {} volumes that did not enclose their primitives\n", model.source,
               refitted, stored.nodes.size());
    return repaired;
}
}  // namespace

Status check_stored_hierarchy(const Model& model, const BuilderFlags& flags) {
    if (!model.hierarchy) return Ok{};
    Result<Bvh> checked = checked_stored_hierarchy(model, flags);
    if (!checked) return checked.error();
    return Ok{};
}

Result<Bvh> hierarchy_of(const Model& model, const BuilderFlags& flags) {
    if (model.hierarchy) return checked_stored_hierarchy(model, flags);
    Result<BuildRequest> request = flags.resolve();
    if (!request) return request.error();
    return request->run(model.primitives);
}

}  // namespace hbvh::cli
