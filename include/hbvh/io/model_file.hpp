// SPDX-License-Identifier: MIT
// Any file hbvh reads, by one call: the survey XML, the .hbvh binary format, MJCF, URDF and meshes. The CLI and
// the Python module read their inputs through it, so a file is read, and refused, the same way everywhere.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hbvh/geometry/primitive.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// What a file holds: its primitives, the hierarchy stored in it (a nested survey XML or a .hbvh tree; none from
/// the importers), the importers' notes about what they skipped, and each stored node's line in a survey XML.
struct ModelFile {
    std::vector<Primitive> primitives;
    std::optional<Bvh> hierarchy;  ///< Its primitives are `primitives`, in the same order.
    std::vector<std::string> warnings;
    std::vector<int> node_lines;  ///< XmlModel::node_lines; empty for other formats.
    /// Read by an importer (MJCF, URDF, a mesh): the file holds more than its primitives, and neither survey XML
    /// nor .hbvh written in its place would keep it.
    bool imported = false;
};

/// The line of stored node `node` in its file, from ModelFile::node_lines; 0 when unknown (a binary file, a node
/// past the list).
[[nodiscard]] int line_of_node(std::span<const int> node_lines, std::uint32_t node);

/// Reads `path` as `format` says: "" decides by the name and the content (.hbvh, or bytes that start with
/// binary_magic: the binary format; .xml: MJCF when its root is <mujoco>, else the survey format; .urdf; the mesh
/// extensions of import_primitives; any other name, a pipe's among them: .hbvh bytes or survey XML by the bytes,
/// else an error), "hbvh", "xml" (survey XML or .hbvh bytes), "mjcf", "urdf", "mesh", or "mesh-nodes" (a plain
/// mesh, one fitted primitive per mesh node). A large .hbvh file is mapped rather than copied. Errors
/// name the file: a directory, an unknown format, the reader's or importer's own error, and a file that yields
/// no primitive (with the first three candidates the importer skipped, and why). Nothing is checked across
/// primitives or nodes: validate_primitives, check_structure and containment_violations are the caller's.
[[nodiscard]] Result<ModelFile> read_model_file(const std::string& path, std::string_view format = {});
/// Empty when read_model_file reads `format` ("" for by extension, hbvh, xml, mjcf, urdf, mesh, mesh-nodes);
/// otherwise "unknown input format '...' (expected ...)", for callers that check the argument before any file.
[[nodiscard]] std::string input_format_problem(std::string_view format);

/// The checks to make on what read_model_file returns before using it, as the CLI and the Python module make them:
/// the primitives (validate_primitives, check_finite_extent) and a stored hierarchy's structure
/// (check_structure). Errors carry `source` as their file.
[[nodiscard]] Status check_model_file(const ModelFile& model, const std::string& source);

/// Ok, or an Error at the line of the first node whose volume overflows double precision: finite numbers can still
/// make an infinite volume (a sphere of radius 1e200), and then the cost is inf (null in JSON) and every comparison
/// of trees a tie. Built trees are kept from it by the builders' check of the primitives' extent.
[[nodiscard]] Status check_finite_volumes(const Bvh& bvh, std::span<const int> node_lines, const std::string& source);

/// A stored hierarchy fit to query: the tree itself when every volume encloses its primitives. A volume whose size
/// overflows double precision (finite numbers, infinite volume) is an Error at its line. Otherwise, without
/// `refit`, an Error naming the first volume that does not (at its line in a survey XML, from `node_lines`) and
/// how many more there are, and saying that `refit_option` (the caller's name for the repair: "--refit" in the
/// CLI) refits them; with `refit`, the tree with each such volume refitted (same kind, tree kept; refit.hpp), and
/// in `*refitted` how many were. Precondition: `stored` passed check_structure (check_model_file). The tree is
/// taken by value: move it in when it is not needed afterwards (at 10^6 primitives a copy is 300 MB).
[[nodiscard]] Result<Bvh> enclosing_hierarchy(Bvh stored, std::span<const int> node_lines,
                                              const std::string& source, bool refit, std::string_view refit_option,
                                              std::size_t* refitted = nullptr);

/// Survey XML or .hbvh bytes already in memory (an asset taken from an archive, standard input), read as
/// read_model_file reads such a file; `name` goes into errors.
[[nodiscard]] Result<ModelFile> read_model_bytes(std::string_view bytes, const std::string& name);

}  // namespace hbvh
