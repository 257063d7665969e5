// SPDX-License-Identifier: MIT
// The survey's XML format (section 4.3, appendix B): primitive sets and hierarchies. The only code that sees pugixml.
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hbvh/geometry/primitive.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// What an XML file holds. docs/formats.md describes the format in full.
struct XmlModel {
    /// The leaf volumes in document order; this order is the input order (primitive index i is the
    /// i-th leaf <volume> of the file). For a flat file these are all its volumes.
    std::vector<Primitive> primitives;
    /// The tree, present exactly when some <volume> nests another. Its primitives equal `primitives`,
    /// its inner nodes carry the file's inner volumes; a volume with a single child is collapsed into
    /// that child (the child's volume is kept). The reader does not check that volumes enclose their
    /// children: run validate() for that.
    std::optional<Bvh> hierarchy;
    /// For a hierarchy: the 1-based line of the <volume> element each node's volume comes from, by node
    /// index, so that a check of the tree (containment_violations) can name the line to fix.
    std::vector<int> node_lines;
};

/// Largest |(M^T M - I)_ij| for which an `orientation` matrix M is accepted and replaced by the nearest
/// rotation (the survey's files print matrices with one decimal, so they are only roughly orthonormal).
inline constexpr double orientation_tolerance = 0.15;

/// Parses `text` (UTF-8 XML). `source_name` is the file name put into every Error ("-" for stdin).
/// Bad input of any kind (malformed XML, unknown types or attributes, wrong number counts, non-finite
/// numbers, negative sizes, a matrix that is no rotation, ...) gives an Error with its 1-based line (a size of
/// zero is allowed: a flat box, a point sphere, a capsule of radius 0);
/// it never crashes and never prints.
[[nodiscard]] Result<XmlModel> read_xml_string(std::string_view text, std::string_view source_name);

/// Reads and parses the file at `path`; errors name the file as given.
[[nodiscard]] Result<XmlModel> read_xml_file(const std::filesystem::path& path);

/// The hierarchy as nested <volume> elements, leaves carrying their primitive's name. Numbers are written
/// in the shortest form that reads back to the same double. Leaves are written in tree order, so reading
/// the output back numbers the primitives in that order (which may differ from bvh.primitives' order).
/// Values no hierarchy should hold (negative sizes, NaN) are written as they are, and the reader will reject them.
/// A tree of a single leaf is written as one volume and so reads back as a one-primitive set;
/// an empty Bvh is written as an empty <hierarchy/>, which the reader rejects.
[[nodiscard]] std::string write_xml(const Bvh& bvh);

/// The primitives as a flat list of <volume> elements (a primitive set), in the given order.
[[nodiscard]] std::string write_primitives_xml(std::span<const Primitive> primitives);

}  // namespace hbvh
