// SPDX-License-Identifier: MIT
// Private helpers shared by the XML-based importers: a parsed file that can turn nodes back into line numbers,
// and strict parsing of whitespace-separated numbers.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <pugixml.hpp>

#include "hbvh/geometry/bounding_volume.hpp"
#include "hbvh/result.hpp"

namespace hbvh::detail {

/// One XML file held in memory. The text is kept so that pugixml offsets map back to 1-based lines.
class XmlSource {
public:
    /// Reads and parses `path`. Errors: unreadable file, or malformed XML (with the line pugixml stopped at).
    [[nodiscard]] static Result<std::unique_ptr<XmlSource>> load(const std::string& path);

    [[nodiscard]] const std::string& path() const { return path_; }
    [[nodiscard]] const std::string& text() const { return text_; }
    [[nodiscard]] const pugi::xml_document& document() const { return document_; }
    /// 1-based line of a byte offset into the text; 0 when unknown (negative offset).
    [[nodiscard]] int line_of_offset(std::ptrdiff_t offset) const;
    /// 1-based line where `node` starts; 0 for nodes not parsed from this file.
    [[nodiscard]] int line_of(const pugi::xml_node& node) const { return line_of_offset(node.offset_debug()); }
    /// An Error located at `node`.
    [[nodiscard]] Error error_at(const pugi::xml_node& node, const std::string& message) const {
        return Error(message, path_, line_of(node));
    }
    /// "file:line: message" for a warning about `node`.
    [[nodiscard]] std::string warning_at(const pugi::xml_node& node, const std::string& message) const {
        return Error(message, path_, line_of(node)).to_string();
    }

private:
    std::string path_;
    std::string text_;
    std::vector<std::size_t> line_starts_;
    pugi::xml_document document_;
};

/// Whether `volume` can be written to the survey format and read back: every coordinate finite, and every size the
/// format stores (full box extents, capsule length, radius) finite too. Near the limit of double a half size can be
/// finite while the full size overflows, and a position composed through several frames can overflow.
[[nodiscard]] bool is_representable(const BoundingVolume& volume);

/// Reads the whole file as bytes; nullopt when it cannot be opened.
[[nodiscard]] std::optional<std::string> read_file_bytes(const std::string& path);

/// Parses whitespace-separated finite numbers (any run of spaces, tabs or newlines between them).
/// nullopt when a token is not a number or is not finite.
[[nodiscard]] std::optional<std::vector<double>> parse_numbers(std::string_view text);

}  // namespace hbvh::detail
