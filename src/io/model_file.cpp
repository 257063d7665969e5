// SPDX-License-Identifier: MIT
// read_model_file: the one reader of every input format, shared by the CLI and the Python module.
#include "hbvh/io/model_file.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <span>
#include <string_view>
#include <system_error>
#include <utility>

#include "hbvh/io/file.hpp"
#include "hbvh/io/import.hpp"
#include "hbvh/io/mesh_import.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/geometry/validation.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/tree/binary_format.hpp"
#include "hbvh/tree/refit.hpp"
#include "hbvh/tree/validate.hpp"
#include "import_format.hpp"
#include "xml_taking.hpp"

namespace hbvh {
namespace {

/// A .hbvh file's contents: a primitive set (node count 0) has no hierarchy, and then its primitives move
/// instead of being copied (at 10^6 primitives, 160 MB).
Result<ModelFile> from_binary(Result<Bvh> bvh) {
    if (!bvh) return bvh.error();
    ModelFile model;
    if (bvh->nodes.empty()) {
        model.primitives = std::move(bvh->primitives);
    } else {
        model.primitives = bvh->primitives;
        model.hierarchy = std::move(bvh.value());
    }
    return model;
}

/// Whether the regular file at `path` begins with the .hbvh magic bytes (false when it cannot be read: the
/// importer that reads it next says why; and for pipes, whose bytes a peek would take from the importer).
bool starts_with_binary_magic(const std::string& path) {
    std::error_code ignored;
    if (!std::filesystem::is_regular_file(path, ignored)) return false;
    std::ifstream file(path, std::ios::binary);
    std::array<char, 8> head{};
    file.read(head.data(), head.size());
    return has_binary_magic(std::as_bytes(std::span(head.data(), static_cast<std::size_t>(file.gcount()))));
}

/// The name of the first element of an XML text, after a byte order mark, blanks, the declaration, processing
/// instructions, comments and a DOCTYPE; empty when the text does not start like XML. Reads only that prolog.
std::string_view root_element_name(std::string_view text) {
    if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
    const auto skip_past = [&](std::string_view end) {
        const std::size_t at = text.find(end);
        text.remove_prefix(at == std::string_view::npos ? text.size() : at + end.size());
    };
    for (;;) {
        const std::size_t start = text.find_first_not_of(" \t\r\n");
        if (start == std::string_view::npos) return {};
        text.remove_prefix(start);
        if (text.starts_with("<?")) skip_past("?>");
        else if (text.starts_with("<!--")) skip_past("-->");
        else if (text.starts_with("<!")) skip_past(">");
        else break;
    }
    if (!text.starts_with('<')) return {};
    text.remove_prefix(1);
    const std::size_t end = text.find_first_of(" \t\r\n/>");
    return text.substr(0, end == std::string_view::npos ? text.size() : end);
}

/// A survey XML file's contents.
Result<ModelFile> from_xml(Result<XmlModel> xml) {
    if (!xml) return xml.error();
    ModelFile model;
    model.primitives = std::move(xml->primitives);
    model.hierarchy = std::move(xml->hierarchy);
    model.node_lines = std::move(xml->node_lines);
    return model;
}

/// The importers' result; a file they found nothing in is an error that carries their reasons, since the error
/// is all a user of the CLI will see.
Result<ModelFile> from_import(Result<ImportResult> imported, const std::string& path) {
    if (!imported) return imported.error();
    if (imported->primitives.empty()) {
        std::string message = "the file holds no collision primitives";
        const std::vector<std::string>& skipped = imported->warnings;
        constexpr std::size_t shown = 3;
        for (std::size_t i = 0; i < std::min(skipped.size(), shown); ++i) message += (i == 0 ? ": " : "; ") + skipped[i];
        if (skipped.size() > shown) message += "; and " + std::to_string(skipped.size() - shown) + " more";
        return Error{message, path};
    }
    ModelFile model;
    model.primitives = std::move(imported->primitives);
    model.warnings = std::move(imported->warnings);
    model.imported = true;
    return model;
}

}  // namespace

std::string input_format_problem(std::string_view format) {
    static constexpr std::string_view known[] = {"", "hbvh", "xml", "mjcf", "urdf", "mesh", "mesh-nodes"};
    if (std::find(std::begin(known), std::end(known), format) != std::end(known)) return {};
    return "unknown input format '" + std::string(format) + "' (expected hbvh, xml, mjcf, urdf, mesh or mesh-nodes)";
}

Result<ModelFile> read_model_file(const std::string& path, std::string_view format) {
    // Before any guess from the extension: a directory named "scene.xml" is still a directory.
    std::error_code ignored;
    if (std::filesystem::is_directory(path, ignored)) return Error{"is a directory, not a file", path};
    // A plain mesh (no UBX_/USP_/UCP_/UCX_ pieces) is imported only on request: one fitted primitive per mesh
    // node is a guess at the author's intent, not a reading of it.
    if (format == "mesh-nodes") {
        MeshImportOptions options;
        options.one_primitive_per_mesh = true;
        return from_import(import_mesh(path, options), path);
    }
    if (format == "hbvh") return from_binary(read_binary_file(path));
    // The survey format keeps a stored hierarchy; the importers give primitives only.
    static const std::pair<std::string_view, ImportFormat> formats[] = {
        {"", ImportFormat::automatic}, {"xml", ImportFormat::survey_xml}, {"mjcf", ImportFormat::mjcf},
        {"urdf", ImportFormat::urdf},  {"mesh", ImportFormat::mesh}};
    const auto chosen = std::find_if(std::begin(formats), std::end(formats),
                                     [&](const auto& entry) { return format == entry.first; });
    if (chosen == std::end(formats)) return Error{input_format_problem(format), path};

    const bool automatic = chosen->second == ImportFormat::automatic;
    const std::string extension = lower_case_extension(path);
    // A .hbvh name goes to the binary reader's own file path, which maps a large file instead of copying it.
    if (automatic && extension == ".hbvh") return from_binary(read_binary_file(path));
    // A name that tells nothing (a pipe such as /dev/stdin or <(...), a file without an extension) is read once
    // and decided by its bytes, for the two formats read from bytes: .hbvh and survey XML. The importers take
    // paths (MJCF's includes, meshes' textures), so for those --format must name the format.
    const bool by_bytes = automatic && !detail::is_import_extension(extension);
    if (chosen->second == ImportFormat::survey_xml || (automatic && extension == ".xml") || by_bytes) {
        Result<std::string> text = read_text_file(path);
        if (!text) return text.error();
        const std::span<const std::byte> raw = std::as_bytes(std::span(text.value()));
        if (has_binary_magic(raw)) return from_binary(read_binary(raw, path));
        // An .xml whose root is <mujoco> (MJCF) or <robot> (URDF) goes to the importer below, unless the format
        // says otherwise; the root's name, not a search of the text, which a comment could fool either way.
        const std::string_view root = root_element_name(text.value());
        // An empty file of any name goes to the XML reader too, whose "file is empty" says what is wrong.
        const bool blank = text->find_first_not_of(" \t\r\n") == std::string::npos;
        const bool survey =
            !automatic || blank || (by_bytes ? root == "hierarchy" : root != "mujoco" && root != "robot");
        // The XML reader takes the text over: a 230 MB file is parsed where it was read, not copied.
        if (survey) return from_xml(detail::read_xml_taking(std::move(text).value(), path));
        if (by_bytes)
            return Error{"unknown file type '" + extension +
                             "': neither .hbvh bytes nor survey XML (<hierarchy>); name the format (the CLI's --format, --input-format "
                             "in hbvh export, Python's format=: hbvh, xml, mjcf, urdf, mesh or mesh-nodes) or give the file one of the extensions "
                             ".hbvh, .xml, .urdf, .gltf, .glb, .obj, .fbx, .dae, .stl, .ply",
                         path};
    }
    // An importer would read a binary hierarchy as XML or a mesh and report a "line" of it; say what it is instead.
    if (!automatic && starts_with_binary_magic(path))
        return Error{"the file is an .hbvh hierarchy (its first bytes say so), not " + std::string(format) +
                         "; drop the format (--format, Python's format=), or name it hbvh",
                     path};
    return from_import(import_primitives(path, chosen->second), path);
}

int line_of_node(std::span<const int> node_lines, std::uint32_t node) {
    return node < node_lines.size() ? node_lines[node] : 0;
}

Status check_model_file(const ModelFile& model, const std::string& source) {
    if (Status valid = validate_primitives(model.primitives); !valid) return Error{valid.error().message, source};
    if (Status finite = check_finite_extent(model.primitives); !finite) return Error{finite.error().message, source};
    if (model.hierarchy)
        if (Status structure = check_structure(*model.hierarchy); !structure) return Error{structure.error().message, source};
    return Ok{};
}

Status check_finite_volumes(const Bvh& bvh, std::span<const int> node_lines, const std::string& source) {
    for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
        const BoundingVolume& bv = bvh.nodes[i].volume;
        if (!std::isfinite(volume(bv)))
            return Error{"volume (" + std::string(to_string(type_of(bv))) +
                             ") is too large: its volume overflows double precision; scale the model down",
                         source, line_of_node(node_lines, i)};
    }
    return Ok{};
}

Result<Bvh> enclosing_hierarchy(Bvh stored, std::span<const int> node_lines, const std::string& source,
                                bool refit, std::string_view refit_option, std::size_t* refitted) {
    if (refitted != nullptr) *refitted = 0;
    if (Status finite = check_finite_volumes(stored, node_lines, source); !finite) return finite.error();
    const std::vector<ContainmentViolation> violations = containment_violations(stored);
    if (violations.empty()) return stored;
    if (!refit) {
        const ContainmentViolation& first = violations.front();
        std::string message = describe_violation(stored, first);
        if (violations.size() > 1) message += " (and " + std::to_string(violations.size() - 1) + " more volumes)";
        return Error{message + "; " + std::string(refit_option) + " refits them", source,
                     line_of_node(node_lines, first.node)};
    }
    const std::size_t count = refit_non_enclosing(stored);
    if (Status valid = validate(stored); !valid)
        return Error{"after " + std::string(refit_option) + ": " + valid.error().message, source};
    if (refitted != nullptr) *refitted = count;
    return stored;
}

Result<ModelFile> read_model_bytes(std::string_view bytes, const std::string& name) {
    // Binary bytes under any name: docs/formats.md, "The binary format".
    const std::span<const std::byte> raw = std::as_bytes(std::span(bytes.data(), bytes.size()));
    if (has_binary_magic(raw)) return from_binary(read_binary(raw, name));
    return from_xml(read_xml_string(bytes, name));
}

}  // namespace hbvh
