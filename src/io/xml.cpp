// SPDX-License-Identifier: MIT
// XML reader and writer for the survey's format (Andersen & Bay, section 4.3 and appendix B).
#include "hbvh/io/xml.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <utility>

#include <Eigen/SVD>
#include <pugixml.hpp>

#include "hbvh/assert.hpp"
#include "hbvh/io/file.hpp"
#include "xml_source.hpp"

namespace hbvh {
namespace {

// The attributes each type takes besides type, name and pos/position. Everything else is rejected:
// silently ignoring a misspelt `orientaton` would turn an OBB into an AABB without a word.
constexpr std::array<std::string_view, 3> box_attributes{"width", "depth", "height"};
constexpr std::array<std::string_view, 4> obb_attributes{"width", "depth", "height", "orientation"};
constexpr std::array<std::string_view, 1> sphere_attributes{"radius"};
constexpr std::array<std::string_view, 3> capsule_attributes{"direction", "length", "radius"};
constexpr std::array<std::string_view, 3> common_attributes{"type", "name", "pos"};

bool is_xml_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

bool is_blank(std::string_view text) { return std::all_of(text.begin(), text.end(), is_xml_space); }

/// `text` shortened for quoting in a message, so one bad attribute can't produce a megabyte of error.
std::string excerpt(std::string_view text) {
    constexpr std::size_t limit = 40;
    return text.size() <= limit ? std::string(text) : std::string(text.substr(0, limit)) + "...";
}

/// Our wording for pugixml's parse failures; pugixml's own descriptions are kept for the rare rest.
std::string describe_parse_error(const pugi::xml_parse_result& result) {
    switch (result.status) {
        case pugi::status_unrecognized_tag: return "malformed XML: a '<' that starts no valid tag";
        case pugi::status_bad_pi: return "malformed XML: bad declaration or processing instruction";
        case pugi::status_bad_comment: return "malformed XML: bad comment";
        case pugi::status_bad_cdata: return "malformed XML: bad CDATA section";
        case pugi::status_bad_doctype: return "malformed XML: bad DOCTYPE";
        case pugi::status_bad_pcdata: return "malformed XML: bad text content";
        case pugi::status_bad_start_element: return "malformed XML: bad start tag (unclosed tag or stray character?)";
        case pugi::status_bad_attribute:
            return "malformed XML: bad attribute (expected name=\"value\", or the tag is not closed)";
        case pugi::status_bad_end_element: return "malformed XML: bad end tag";
        case pugi::status_end_element_mismatch:
            return "malformed XML: end tag does not match the open element (misspelt or missing tag?)";
        case pugi::status_no_document_element: return "malformed XML: no element found";
        default: return std::string("malformed XML: ") + result.description();
    }
}

/// Shortest decimal text that reads back as exactly `value` (std::to_chars' round-trip guarantee).
void append_number(std::string& out, double value) {
    std::array<char, 32> digits{};
    const auto [end, ec] = std::to_chars(digits.data(), digits.data() + digits.size(), value);
    out.append(digits.data(), ec == std::errc{} ? end : digits.data());
}

std::string format_numbers(std::initializer_list<double> values) {
    std::string out;
    for (double value : values) {
        if (!out.empty()) out += ' ';
        append_number(out, value);
    }
    return out;
}

std::string format_vector(const Vec3& v) { return format_numbers({v.x(), v.y(), v.z()}); }

/// Parses one XML file. Keeps the text so that byte offsets from pugixml become line numbers.
class Reader {
public:
    Reader(std::string_view text, std::string_view source) : text_(text), source_(source), buffer_(text) {}

    Result<XmlModel> run();

private:
    /// One <volume> as read, in document (pre-)order.
    struct Item {
        BoundingVolume volume;
        std::string name;
        std::vector<std::uint32_t> children;  ///< Indices of the child items, in document order.
        std::ptrdiff_t offset = 0;            ///< The element's byte offset, for its line.
    };

    [[nodiscard]] int line_at(std::ptrdiff_t offset) const {
        const auto end = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(offset, 0, std::ssize(text_)));
        return 1 + static_cast<int>(std::count(text_.begin(), text_.begin() + static_cast<std::ptrdiff_t>(end), '\n'));
    }
    /// The line of an element's name, or for text, of its first non-blank character (a stray word
    /// usually follows the newline that ends the previous tag).
    [[nodiscard]] int line_of(const pugi::xml_node& node) const {
        std::ptrdiff_t offset = node.offset_debug();
        if (node.type() == pugi::node_pcdata || node.type() == pugi::node_cdata)
            while (offset >= 0 && offset < std::ssize(text_) && is_xml_space(text_[static_cast<std::size_t>(offset)])) ++offset;
        return line_at(offset);
    }
    /// The line of the attribute itself, which can differ from its element's (appendix B puts
    /// `orientation` on the next line). pugixml parses in place, so the attribute's name points into
    /// buffer_ at the attribute's own position; anything else falls back to the element's line.
    [[nodiscard]] int line_of(const pugi::xml_attribute& attribute, const pugi::xml_node& element) const {
        const char* name = attribute.name();
        if (name >= buffer_.data() && name < buffer_.data() + buffer_.size()) return line_at(name - buffer_.data());
        return line_of(element);
    }
    [[nodiscard]] Error error(int line, std::string message) const { return Error(std::move(message), source_, line); }

    std::optional<Error> check_structure_of(const pugi::xml_node& parent, std::vector<pugi::xml_node>& volumes) const;
    Result<BoundingVolume> read_volume(const pugi::xml_node& element, std::string& name) const;
    Result<std::vector<double>> read_numbers(const pugi::xml_node& element, const pugi::xml_attribute& attribute,
                                             std::size_t count) const;
    Result<double> read_size(const pugi::xml_node& element, const pugi::xml_attribute& attribute,
                             bool zero_allowed) const;
    Result<Mat3> read_orientation(const pugi::xml_node& element, const pugi::xml_attribute& attribute) const;

    std::string_view text_;
    std::string source_;
    std::string buffer_;  // pugixml's in-place copy; declared before doc_ so it outlives it
    pugi::xml_document doc_;
};

Result<XmlModel> Reader::run() {
    // Stage 1: parse. Whitespace-only input gets its own message: "no element found" would puzzle.
    std::string_view body = text_;
    if (body.starts_with("\xEF\xBB\xBF")) body.remove_prefix(3);  // a UTF-8 byte order mark
    if (is_blank(body)) return error(1, "file is empty");
    const pugi::xml_parse_result parsed =
        doc_.load_buffer_inplace(buffer_.data(), buffer_.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!parsed) return error(line_at(parsed.offset), describe_parse_error(parsed));

    // Stage 2: exactly one top-level element, and it is <hierarchy>.
    pugi::xml_node hierarchy;
    for (const pugi::xml_node& node : doc_.children()) {
        if (node.type() != pugi::node_element) continue;
        if (hierarchy) return error(line_of(node), "more than one top-level element; the file must hold one <hierarchy>");
        hierarchy = node;
    }
    if (!hierarchy) return error(1, "no <hierarchy> element");
    if (std::string_view(hierarchy.name()) != "hierarchy")
        return error(line_of(hierarchy),
                     "expected <hierarchy> as the top-level element, found <" + excerpt(hierarchy.name()) + ">");
    if (hierarchy.first_attribute())
        return error(line_of(hierarchy.first_attribute(), hierarchy),
                     "unknown attribute '" + excerpt(hierarchy.first_attribute().name()) + "' on <hierarchy>");

    // Stage 3: read every volume in document pre-order with an explicit stack (a deeply nested file
    // must not overflow the call stack). Pre-order visits the leaves in document order.
    std::vector<pugi::xml_node> top_level;
    if (auto problem = check_structure_of(hierarchy, top_level)) return *problem;
    if (top_level.empty()) return error(line_of(hierarchy), "<hierarchy> contains no <volume> elements");

    std::vector<Item> items;
    std::vector<std::pair<pugi::xml_node, std::uint32_t>> stack;  // (element, parent item or UINT32_MAX)
    constexpr std::uint32_t no_parent = UINT32_MAX;
    for (auto it = top_level.rbegin(); it != top_level.rend(); ++it) stack.emplace_back(*it, no_parent);
    bool nested = false;
    while (!stack.empty()) {
        const auto [element, parent] = stack.back();
        stack.pop_back();
        std::string name;
        Result<BoundingVolume> volume = read_volume(element, name);
        if (!volume) return volume.error();
        // Each number can be finite while what is derived from them is not (a box's centre from corners near
        // 1e308, a capsule's length beyond 1e154); such a volume could not be written back or fitted.
        if (!detail::is_representable(*volume))
            return error(line_of(element), "volume's centre, length or extents overflow the range of double");
        const auto index = static_cast<std::uint32_t>(items.size());
        items.push_back({std::move(volume).value(), std::move(name), {}, element.offset_debug()});
        if (parent != no_parent) items[parent].children.push_back(index);

        std::vector<pugi::xml_node> children;
        if (auto problem = check_structure_of(element, children)) return *problem;
        nested = nested || !children.empty();
        for (auto it = children.rbegin(); it != children.rend(); ++it) stack.emplace_back(*it, index);
    }

    // Stage 4: the leaves are the primitives, numbered in document order.
    XmlModel model;
    std::vector<std::uint32_t> primitive_of(items.size(), 0);
    for (std::uint32_t i = 0; i < items.size(); ++i) {
        if (!items[i].children.empty()) continue;
        primitive_of[i] = static_cast<std::uint32_t>(model.primitives.size());
        model.primitives.push_back({items[i].volume, std::move(items[i].name)});
    }
    if (!nested) return model;

    // Stage 5: a nested file is one tree. The survey's root is "the first volume element"; a second
    // top-level volume would need a BV nobody wrote, so it is an error rather than a guess.
    if (top_level.size() > 1)
        return error(line_of(top_level[1]),
                     "a nested hierarchy must have exactly one top-level <volume>, but this is a second one");
    // Children come after their parent in pre-order, so walking backwards meets every child before its
    // parent, as TreeAssembler::add_group needs. It also collapses single-child volumes.
    TreeAssembler assembler(model.primitives);
    std::vector<std::uint32_t> id(items.size(), 0);
    for (std::size_t i = items.size(); i-- > 0;) {
        Item& item = items[i];
        if (item.children.empty()) {
            id[i] = assembler.add_leaf(primitive_of[i]);
            continue;
        }
        std::vector<std::uint32_t> child_ids;
        child_ids.reserve(item.children.size());
        for (std::uint32_t child : item.children) child_ids.push_back(id[child]);
        id[i] = assembler.add_group(child_ids, item.volume);
    }
    std::vector<std::uint32_t> assembler_id_of_node;
    model.hierarchy = std::move(assembler).finish(id[0], &assembler_id_of_node);
    // Every node's line in one pass over the text: item offsets grow in pre-order, so sorting the nodes by
    // offset lets one forward scan count the newlines (line_at per node would be quadratic in big files).
    std::vector<std::uint32_t> item_of_assembler_id(items.size());
    for (std::uint32_t i = 0; i < items.size(); ++i) item_of_assembler_id[id[i]] = i;
    std::vector<std::pair<std::ptrdiff_t, std::uint32_t>> offsets;  // (offset, node)
    offsets.reserve(assembler_id_of_node.size());
    for (std::uint32_t n = 0; n < assembler_id_of_node.size(); ++n)
        offsets.emplace_back(items[item_of_assembler_id[assembler_id_of_node[n]]].offset, n);
    std::sort(offsets.begin(), offsets.end());
    model.node_lines.assign(offsets.size(), 0);
    std::ptrdiff_t scanned = 0;
    int line = 1;
    for (const auto& [offset, node] : offsets) {
        const std::ptrdiff_t end = std::clamp<std::ptrdiff_t>(offset, scanned, std::ssize(text_));
        line += static_cast<int>(std::count(text_.begin() + scanned, text_.begin() + end, '\n'));
        scanned = end;
        model.node_lines[node] = line;
    }
    return model;
}

/// Collects the <volume> children of `parent` and rejects anything else that holds information
/// (other elements, text). Comments and processing instructions are dropped by the parser already.
std::optional<Error> Reader::check_structure_of(const pugi::xml_node& parent, std::vector<pugi::xml_node>& volumes) const {
    for (const pugi::xml_node& child : parent.children()) {
        switch (child.type()) {
            case pugi::node_element:
                if (std::string_view(child.name()) != "volume")
                    return error(line_of(child), "unexpected element <" + excerpt(child.name()) + "> inside <" +
                                                     parent.name() + ">; only <volume> elements may appear there");
                volumes.push_back(child);
                break;
            case pugi::node_pcdata:
            case pugi::node_cdata:
                if (!is_blank(child.value()))
                    return error(line_of(child), "unexpected text \"" + excerpt(child.value()) + "\" inside <" +
                                                     parent.name() + ">");
                break;
            default: break;
        }
    }
    return std::nullopt;
}

Result<BoundingVolume> Reader::read_volume(const pugi::xml_node& element, std::string& name) const {
    // Lines are found by counting newlines from the start, so they are computed only for an error.
    const auto element_line = [&] { return line_of(element); };

    // Stage 1: the type decides which attributes are allowed.
    const pugi::xml_attribute type_attribute = element.attribute("type");
    if (!type_attribute) return error(element_line(), "missing attribute 'type' on <volume>");
    const std::string_view type_name = type_attribute.value();
    const std::optional<BvType> type = parse_bv_type(type_name);
    if (!type)
        return error(line_of(type_attribute, element),
                     "unknown volume type \"" + excerpt(type_name) + "\" (expected aabb, obb, sphere or capsule)");
    std::span<const std::string_view> specific;
    switch (*type) {
        case BvType::aabb: specific = box_attributes; break;
        case BvType::obb: specific = obb_attributes; break;
        case BvType::sphere: specific = sphere_attributes; break;
        case BvType::capsule: specific = capsule_attributes; break;
    }

    // Stage 2: every attribute is known, allowed for this type and given once. `position` is the
    // survey's prose spelling of `pos`, so both count as the same attribute.
    pugi::xml_attribute position;
    for (const pugi::xml_attribute& attribute : element.attributes()) {
        std::string_view key = attribute.name();
        const auto line = [&] { return line_of(attribute, element); };
        if (key == "position") key = "pos";
        const bool is_common = std::find(common_attributes.begin(), common_attributes.end(), key) != common_attributes.end();
        const bool is_specific = std::find(specific.begin(), specific.end(), key) != specific.end();
        if (!is_common && !is_specific) {
            const bool elsewhere = std::find(obb_attributes.begin(), obb_attributes.end(), key) != obb_attributes.end() ||
                                   key == "radius" || key == "direction" || key == "length";
            if (elsewhere)
                return error(line(), "attribute '" + std::string(key) + "' does not apply to type=\"" +
                                       std::string(type_name) + "\"");
            return error(line(), "unknown attribute '" + excerpt(attribute.name()) + "' on <volume type=\"" +
                                   std::string(type_name) + "\">");
        }
        for (pugi::xml_attribute earlier = element.first_attribute(); earlier != attribute;
             earlier = earlier.next_attribute()) {
            std::string_view earlier_key = earlier.name();
            if (earlier_key == "position") earlier_key = "pos";
            if (earlier_key != key) continue;
            if (std::string_view(earlier.name()) != attribute.name())
                return error(line(), "both 'pos' and 'position' given; use one");
            return error(line(), "attribute '" + std::string(key) + "' given twice");
        }
        if (key == "pos") position = attribute;
    }
    auto required = [&](std::string_view key) -> Result<pugi::xml_attribute> {
        const pugi::xml_attribute attribute = element.attribute(std::string(key).c_str());
        if (!attribute)
            return error(element_line(),
                         "missing attribute '" + std::string(key) + "' on <volume type=\"" + std::string(type_name) + "\">");
        return attribute;
    };
    if (!position) return error(element_line(), "missing attribute 'pos' on <volume type=\"" + std::string(type_name) + "\">");
    name = element.attribute("name").value();

    // Stage 3: read the numbers.
    const Result<std::vector<double>> centre_numbers = read_numbers(element, position, 3);
    if (!centre_numbers) return centre_numbers.error();
    const Vec3 centre(centre_numbers.value()[0], centre_numbers.value()[1], centre_numbers.value()[2]);

    if (*type == BvType::sphere || *type == BvType::capsule) {
        const Result<pugi::xml_attribute> radius_attribute = required("radius");
        if (!radius_attribute) return radius_attribute.error();
        const Result<double> radius = read_size(element, *radius_attribute, false);
        if (!radius) return radius.error();
        if (*type == BvType::sphere) return BoundingVolume(Sphere{centre, *radius});

        const Result<pugi::xml_attribute> direction_attribute = required("direction");
        if (!direction_attribute) return direction_attribute.error();
        const Result<std::vector<double>> direction_numbers = read_numbers(element, *direction_attribute, 3);
        if (!direction_numbers) return direction_numbers.error();
        const Vec3 direction(direction_numbers.value()[0], direction_numbers.value()[1], direction_numbers.value()[2]);
        // stableNorm: a tiny but valid direction like (1e-200, 0, 0) must not underflow to zero.
        const double norm = direction.stableNorm();
        if (!(norm > 0.0) || !std::isfinite(norm))
            return error(line_of(*direction_attribute, element), "attribute 'direction' must not be the zero vector");
        const Result<pugi::xml_attribute> length_attribute = required("length");
        if (!length_attribute) return length_attribute.error();
        // Length 0 is a sphere written as a capsule; that is still a valid capsule.
        const Result<double> length = read_size(element, *length_attribute, true);
        if (!length) return length.error();
        const Vec3 half_axis = (0.5 * *length) * Vec3(direction / norm);
        const Capsule capsule{centre - half_axis, centre + half_axis, *radius};
        if (!capsule.p0.allFinite() || !capsule.p1.allFinite())
            return error(element_line(), "capsule ends overflow the range of double");
        return BoundingVolume(capsule);
    }

    // Boxes: full extents along the local x, y, z axes.
    Vec3 extents;
    for (int axis = 0; axis < 3; ++axis) {
        const Result<pugi::xml_attribute> attribute = required(box_attributes[static_cast<std::size_t>(axis)]);
        if (!attribute) return attribute.error();
        const Result<double> extent = read_size(element, *attribute, false);
        if (!extent) return extent.error();
        extents[axis] = *extent;
    }
    const Vec3 half = 0.5 * extents;
    // The survey's footnote 4: "AABBs are OBBs with no orientation".
    const pugi::xml_attribute orientation_attribute = element.attribute("orientation");
    if (!orientation_attribute) {
        // Stored as corners, an AABB can lose what the file says: far from the origin a small extent
        // rounds away, and a huge one overflows. Refuse instead of returning a flat or infinite box.
        const Aabb box{centre - half, centre + half};
        if (!box.min.allFinite() || !box.max.allFinite())
            return error(element_line(), "box corners overflow the range of double");
        if (((box.max - box.min).array() <= 0.0).any())
            return error(element_line(), "box extents vanish in rounding: they are too small for its position");
        return BoundingVolume(box);
    }
    const Result<Mat3> rotation = read_orientation(element, orientation_attribute);
    if (!rotation) return rotation.error();
    return BoundingVolume(Obb{centre, *rotation, half});
}

Result<std::vector<double>> Reader::read_numbers(const pugi::xml_node& element, const pugi::xml_attribute& attribute,
                                                 std::size_t count) const {
    const auto line = [&] { return line_of(attribute, element); };
    const std::string key = attribute.name();
    std::string_view rest = attribute.value();
    std::vector<double> numbers;
    for (;;) {
        while (!rest.empty() && is_xml_space(rest.front())) rest.remove_prefix(1);
        if (rest.empty()) break;
        std::size_t length = 0;
        while (length < rest.size() && !is_xml_space(rest[length])) ++length;
        std::string_view token = rest.substr(0, length);
        rest.remove_prefix(length);
        if (numbers.size() == count) {
            return error(line(), "attribute '" + key + "' needs " + std::to_string(count) +
                                     (count == 1 ? " number" : " numbers") + ", found more (extra \"" +
                                   excerpt(token) + "\")");
        }
        // from_chars refuses a leading '+', which people do write; accept it unless a sign follows.
        std::string_view digits = token;
        if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-' && digits[1] != '+') digits.remove_prefix(1);
        double value = 0.0;
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
        if (ec == std::errc::result_out_of_range)
            return error(line(), "attribute '" + key + "': \"" + excerpt(token) + "\" is out of the range of double");
        if (ec != std::errc{} || end != digits.data() + digits.size())
            return error(line(), "attribute '" + key + "': \"" + excerpt(token) + "\" is not a number");
        if (!std::isfinite(value))
            return error(line(), "attribute '" + key + "': \"" + excerpt(token) + "\" is not a finite number");
        numbers.push_back(value);
    }
    if (numbers.size() != count) {
        return error(line(), "attribute '" + key + "' needs " + std::to_string(count) +
                                 (count == 1 ? " number" : " numbers") + ", found " + std::to_string(numbers.size()));
    }
    return numbers;
}

Result<double> Reader::read_size(const pugi::xml_node& element, const pugi::xml_attribute& attribute,
                                 bool zero_allowed) const {
    const Result<std::vector<double>> numbers = read_numbers(element, attribute, 1);
    if (!numbers) return numbers.error();
    const double value = numbers.value()[0];
    if (value > 0.0 || (zero_allowed && value == 0.0)) return value;
    return error(line_of(attribute, element), "attribute '" + std::string(attribute.name()) + "' must be " +
                                                  (zero_allowed ? ">= 0" : "> 0") + ", found " + attribute.value());
}

Result<Mat3> Reader::read_orientation(const pugi::xml_node& element, const pugi::xml_attribute& attribute) const {
    const Result<std::vector<double>> numbers = read_numbers(element, attribute, 9);
    if (!numbers) return numbers.error();
    Mat3 m;
    for (int row = 0; row < 3; ++row)
        for (int column = 0; column < 3; ++column) m(row, column) = numbers.value()[static_cast<std::size_t>(3 * row + column)];

    // Files print matrices rounded (appendix B uses one decimal), so accept what is clearly meant as a
    // rotation and replace it by the nearest one; refuse what is not, rather than guess.
    const double deviation = (m.transpose() * m - Mat3::Identity()).cwiseAbs().maxCoeff();
    if (!(deviation <= orientation_tolerance)) {
        std::string shown;
        append_number(shown, std::round(deviation * 1000.0) / 1000.0);
        return error(line_of(attribute, element), "attribute 'orientation' is not a rotation matrix: R^T R differs from the identity by " +
                               shown + " (at most 0.15 is accepted)");
    }
    const double determinant = m.determinant();
    if (!(determinant > 0.0)) {
        std::string shown;
        append_number(shown, std::round(determinant * 1000.0) / 1000.0);
        return error(line_of(attribute, element), "attribute 'orientation' is a reflection (determinant " + shown + "), not a rotation");
    }
    // Polar decomposition M = (U V^T)(V S V^T): U V^T is the rotation nearest to M in the Frobenius norm.
    // det(M) > 0 and S near 1 make det(U V^T) = +1, so this is a proper rotation.
    const Eigen::JacobiSVD<Mat3> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    return Mat3(svd.matrixU() * svd.matrixV().transpose());
}

/// Sets the attributes of one <volume> for `bv`. Attribute order: type, name, pos, then the type's own.
void write_volume(pugi::xml_node element, const BoundingVolume& bv, const std::string& name) {
    element.append_attribute("type").set_value(std::string(to_string(type_of(bv))).c_str());
    if (!name.empty()) element.append_attribute("name").set_value(name.c_str());
    auto set = [&](const char* key, const std::string& value) { element.append_attribute(key).set_value(value.c_str()); };
    std::visit(Overloaded{
                   [&](const Aabb& box) {
                       const Vec3 extents = box.max - box.min;
                       set("pos", format_vector(box.center()));
                       set("width", format_numbers({extents.x()}));
                       set("depth", format_numbers({extents.y()}));
                       set("height", format_numbers({extents.z()}));
                   },
                   [&](const Obb& box) {
                       const Vec3 extents = 2.0 * box.half_extents;
                       const Mat3& r = box.rotation;
                       set("pos", format_vector(box.center));
                       set("width", format_numbers({extents.x()}));
                       set("depth", format_numbers({extents.y()}));
                       set("height", format_numbers({extents.z()}));
                       set("orientation", format_numbers({r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2),
                                                          r(2, 0), r(2, 1), r(2, 2)}));
                   },
                   [&](const Sphere& sphere) {
                       set("pos", format_vector(sphere.center));
                       set("radius", format_numbers({sphere.radius}));
                   },
                   [&](const Capsule& capsule) {
                       set("pos", format_vector(capsule.center()));
                       set("direction", format_vector(capsule.direction()));
                       set("length", format_numbers({capsule.length()}));
                       set("radius", format_numbers({capsule.radius}));
                   },
               },
               bv);
}

/// Collects pugixml's output in a string.
class StringWriter final : public pugi::xml_writer {
public:
    void write(const void* data, std::size_t size) override { text.append(static_cast<const char*>(data), size); }
    std::string text;
};

/// A document with its declaration and an empty <hierarchy>, ready to be filled.
pugi::xml_node start_document(pugi::xml_document& doc) {
    pugi::xml_node declaration = doc.append_child(pugi::node_declaration);
    declaration.append_attribute("version").set_value("1.0");
    declaration.append_attribute("encoding").set_value("UTF-8");
    return doc.append_child("hierarchy");
}

std::string save(const pugi::xml_document& doc) {
    StringWriter writer;
    doc.save(writer, "  ", pugi::format_indent, pugi::encoding_utf8);
    return std::move(writer.text);
}

}  // namespace

Result<XmlModel> read_xml_string(std::string_view text, std::string_view source_name) {
    return Reader(text, source_name).run();
}

Result<XmlModel> read_xml_file(const std::filesystem::path& path) {
    Result<std::string> text = read_text_file(path);
    if (!text) return text.error();
    return read_xml_string(*text, path.string());
}

std::string write_xml(const Bvh& bvh) {
    pugi::xml_document doc;
    pugi::xml_node hierarchy = start_document(doc);
    if (bvh.empty()) return save(doc);
    // Explicit stack: a degenerate (list-like) tree can be deeper than the call stack allows.
    std::vector<std::pair<std::uint32_t, pugi::xml_node>> stack{{0u, hierarchy}};
    while (!stack.empty()) {
        auto [index, parent] = stack.back();
        stack.pop_back();
        const Node& node = bvh.nodes[index];
        // Broken indices are a bug in whoever built the tree, not bad input.
        HBVH_ASSERT(node.is_leaf() ? node.primitive < bvh.primitives.size()
                                   : std::size_t{node.first_child} + node.child_count <= bvh.nodes.size());
        pugi::xml_node element = parent.append_child("volume");
        if (node.is_leaf()) {
            const Primitive& primitive = bvh.primitives[node.primitive];
            write_volume(element, primitive.volume, primitive.name);
            continue;
        }
        write_volume(element, node.volume, {});
        // Pushed in reverse so that they pop, and are appended, in child order.
        for (std::uint32_t c = node.child_count; c-- > 0;) stack.emplace_back(node.first_child + c, element);
    }
    return save(doc);
}

std::string write_primitives_xml(std::span<const Primitive> primitives) {
    pugi::xml_document doc;
    pugi::xml_node hierarchy = start_document(doc);
    for (const Primitive& primitive : primitives) write_volume(hierarchy.append_child("volume"), primitive.volume, primitive.name);
    return save(doc);
}

}  // namespace hbvh
