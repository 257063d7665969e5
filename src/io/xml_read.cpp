// SPDX-License-Identifier: MIT
// The survey XML reader (Andersen & Bay, section 4.3 and appendix B); the writer is xml_write.cpp.
//
// Reading a large file (docs/formats.md, "Reading and writing large XML") is three passes: pugixml parses the
// text in place; one sequential walk checks the document's structure and lists the <volume> elements in
// pre-order; then each volume is converted on its own, on all cores when there are many. Any problem found is
// the first the original one-pass reader would have met, so messages and lines do not depend on the thread
// count.
#include "hbvh/io/xml.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <mutex>
#include <utility>

#include <pugixml.hpp>

#include "hbvh/assert.hpp"
#include "hbvh/geometry/validation.hpp"
#include "hbvh/io/file.hpp"
#include "../memory/huge_pages.hpp"
#include "xml_fields.hpp"
#include "xml_number.hpp"
#include "xml_source.hpp"
#include "xml_taking.hpp"

namespace hbvh {
namespace {

using detail::aabb_from_fields;
using detail::append_number;
using detail::capsule_from_fields;

// The attributes of a <volume>. Everything else is rejected: silently ignoring a misspelt `orientaton`
// would turn an OBB into an AABB without a word. `position` (the survey's prose) is read as `pos`.
enum class Key : std::uint8_t { type, name, pos, width, depth, height, orientation, radius, direction, length };
constexpr std::size_t key_count = 10;
constexpr std::array<std::string_view, key_count> key_names{"type",   "name",        "pos",    "width",     "depth",
                                                            "height", "orientation", "radius", "direction", "length"};

constexpr std::uint32_t bit(Key key) { return std::uint32_t{1} << static_cast<unsigned>(key); }
constexpr std::uint32_t common_keys = bit(Key::type) | bit(Key::name) | bit(Key::pos);
constexpr std::uint32_t box_keys = bit(Key::width) | bit(Key::depth) | bit(Key::height);

/// The keys a type takes besides type, name and pos.
std::uint32_t keys_of(BvType type) {
    switch (type) {
        case BvType::aabb: return box_keys;
        case BvType::obb: return box_keys | bit(Key::orientation);
        case BvType::sphere: return bit(Key::radius);
        case BvType::capsule: return bit(Key::direction) | bit(Key::length) | bit(Key::radius);
    }
    return 0;
}

std::optional<Key> key_of(std::string_view name) {
    if (name == "position") return Key::pos;
    const auto found = std::find(key_names.begin(), key_names.end(), name);
    if (found == key_names.end()) return std::nullopt;
    return static_cast<Key>(found - key_names.begin());
}

std::string key_name(Key key) { return std::string(key_names[static_cast<std::size_t>(key)]); }

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

/// Where every line of a text starts. Built before pugixml parses the text in place, because that parse
/// rewrites line ends ("\r\n" and newlines inside attribute values); a lookup is a binary search, so an
/// error deep in a large file costs no scan of the text before it.
class LineTable {
public:
    explicit LineTable(std::string_view text) : size_(text.size()) {
        starts_.push_back(0);
        const char* const begin = text.data();
        const char* const end = begin + text.size();
        for (const char* at = begin; at < end; ++at) {
            at = static_cast<const char*>(std::memchr(at, '\n', static_cast<std::size_t>(end - at)));
            if (at == nullptr) break;
            starts_.push_back(static_cast<std::size_t>(at - begin) + 1);
        }
    }

    /// The 1-based line of byte `offset`, clamped into the text (a negative offset is on line 1).
    [[nodiscard]] int line_of(std::ptrdiff_t offset) const {
        const auto at = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(offset, 0, static_cast<std::ptrdiff_t>(size_)));
        return static_cast<int>(std::upper_bound(starts_.begin(), starts_.end(), at) - starts_.begin());
    }

    /// The lines of ascending offsets, in one forward sweep of the table (no search per offset).
    [[nodiscard]] std::vector<int> lines_of_ascending(std::span<const std::ptrdiff_t> offsets) const {
        std::vector<int> lines;
        detail::reserve_on_huge_pages(lines, offsets.size());
        std::size_t line = 1;  // starts_[line - 1] <= offset < starts_[line]
        for (const std::ptrdiff_t offset : offsets) {
            const auto at = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(offset, 0, static_cast<std::ptrdiff_t>(size_)));
            HBVH_ASSERT(at >= starts_[line - 1]);
            while (line < starts_.size() && starts_[line] <= at) ++line;
            lines.push_back(static_cast<int>(line));
        }
        return lines;
    }

private:
    std::size_t size_;
    detail::LargeVector<std::size_t> starts_;  // 8 MB for a 10^6-line file: on huge pages (memory/huge_pages.hpp)
};

/// Whether pugixml's in-place parse can change the white space that opens a text node: a lone '\r' becomes
/// '\n' and a character reference ("&#10;") the white space it stands for. Without either, the newlines at
/// the start of a parsed text are the file's own ("\r\n" becomes one '\n'), so its line can be counted there.
bool parse_can_rewrite_white_space(std::string_view text) {
    if (text.find("&#") != std::string_view::npos) return true;
    for (std::size_t cr = text.find('\r'); cr != std::string_view::npos; cr = text.find('\r', cr + 1))
        if (cr + 1 == text.size() || text[cr + 1] != '\n') return true;
    return false;
}

constexpr std::uint32_t no_parent = UINT32_MAX;

/// Above this many volumes the conversion runs on all cores; below, starting tasks costs more than it saves.
constexpr std::size_t parallel_volume_count = 16384;

/// One <volume> element as the structure walk met it, in document pre-order (which lists the leaves, the
/// primitives, in document order, and every volume after its parent).
struct VolumeElement {
    pugi::xml_node element;
    std::uint32_t parent = no_parent;  ///< Index of the enclosing volume in the walk, or no_parent.
    std::uint32_t slot = 0;            ///< A leaf's primitive index, else the index among the inner volumes.
    bool is_leaf = true;
};

/// What the structure walk found. A problem of structure is reported only if no volume up to and including
/// `problem_after` is bad: that is the order in which the one-pass reader met them.
struct VolumeWalk {
    detail::LargeVector<VolumeElement> volumes;
    std::uint32_t primitive_count = 0;
    std::uint32_t inner_count = 0;
    pugi::xml_node second_top_level;  ///< Null when there is one top-level volume.
    bool nested = false;
    std::optional<Error> problem;
    std::size_t problem_after = 0;
};

/// A volume as read from its element; `name` points into the parsed text.
struct ParsedVolume {
    BoundingVolume volume;
    std::string_view name;
};

/// A <volume>'s attributes by key, each given once; null where absent.
using VolumeAttributes = std::array<pugi::xml_attribute, key_count>;

/// The failure with the lowest order key reported from any thread. Keys grow in document order, so this is
/// the failure a one-pass reader would meet first; work whose key is higher than a known failure's is useless.
class FirstFailure {
public:
    [[nodiscard]] bool is_known_before(std::size_t key) const { return key_.load(std::memory_order_relaxed) < key; }
    void report(std::size_t key, Error error) {
        const std::lock_guard lock(mutex_);
        if (key >= key_.load(std::memory_order_relaxed)) return;
        key_.store(key, std::memory_order_relaxed);
        error_ = std::move(error);
    }
    [[nodiscard]] std::optional<Error> take() && { return std::move(error_); }

private:
    std::atomic<std::size_t> key_{SIZE_MAX};
    std::mutex mutex_;
    std::optional<Error> error_;
};

/// Parses one XML file. Owns the text, which pugixml parses in place.
class Reader {
public:
    Reader(std::string text, std::string_view source) : text_(std::move(text)), lines_(text_), source_(source) {
        if (parse_can_rewrite_white_space(text_)) pristine_ = text_;
    }

    Result<XmlModel> run();

private:
    [[nodiscard]] int line_at(std::ptrdiff_t offset) const { return lines_.line_of(offset); }
    [[nodiscard]] int line_of(const pugi::xml_node& node) const;
    [[nodiscard]] int line_of(const pugi::xml_attribute& attribute, const pugi::xml_node& element) const;
    [[nodiscard]] Error error(int line, std::string message) const { return Error(std::move(message), source_, line); }

    Result<pugi::xml_node> parse_hierarchy();
    std::optional<Error> check_structure_of(const pugi::xml_node& parent, detail::LargeVector<pugi::xml_node>& volumes) const;
    Result<VolumeWalk> walk_volumes(const pugi::xml_node& hierarchy) const;
    std::optional<Error> convert_volumes(const VolumeWalk& walk, std::vector<Primitive>& primitives,
                                         std::vector<BoundingVolume>& inner_volumes) const;
    std::optional<Error> convert_volume(const VolumeElement& volume, std::vector<Primitive>& primitives,
                                        std::vector<BoundingVolume>& inner_volumes) const;
    void assemble_tree(const VolumeWalk& walk, XmlModel& model, std::vector<BoundingVolume> inner_volumes);

    Result<ParsedVolume> read_volume(const pugi::xml_node& element) const;
    Result<VolumeAttributes> collect_attributes(const pugi::xml_node& element, BvType type,
                                                std::string_view type_name) const;
    Result<BoundingVolume> read_round(const pugi::xml_node& element, const VolumeAttributes& attributes, BvType type,
                                      const Vec3& centre, std::string_view type_name) const;
    Result<BoundingVolume> read_box(const pugi::xml_node& element, const VolumeAttributes& attributes,
                                    const Vec3& centre, std::string_view type_name) const;
    Result<pugi::xml_attribute> required(const pugi::xml_node& element, const VolumeAttributes& attributes, Key key,
                                         std::string_view type_name) const;
    template <std::size_t count>
    Result<std::array<double, count>> read_numbers(const pugi::xml_node& element,
                                                   const pugi::xml_attribute& attribute) const;
    Result<Vec3> read_vector(const pugi::xml_node& element, const pugi::xml_attribute& attribute) const;
    /// A size: 0 or a positive normal double (0: a point sphere, a flat box, a capsule of length 0).
    Result<double> read_size(const pugi::xml_node& element, const pugi::xml_attribute& attribute) const;
    Result<Mat3> read_orientation(const pugi::xml_node& element, const pugi::xml_attribute& attribute) const;

    std::string text_;      // parsed in place by doc_, so declared before it
    std::string pristine_;  // an unparsed copy, kept only when parse_can_rewrite_white_space(text)
    LineTable lines_;       // of the text before parsing
    std::string source_;
    pugi::xml_document doc_;
};

/// The line of an element's name, or for text, of its first non-blank character (a stray word usually
/// follows the newline that ends the previous tag).
int Reader::line_of(const pugi::xml_node& node) const {
    const std::ptrdiff_t offset = node.offset_debug();
    if (node.type() != pugi::node_pcdata && node.type() != pugi::node_cdata) return line_at(offset);
    if (!pristine_.empty()) {
        std::ptrdiff_t first = offset;
        while (first >= 0 && first < std::ssize(pristine_) && is_xml_space(pristine_[static_cast<std::size_t>(first)])) ++first;
        return line_at(first);
    }
    // The parsed value starts where the text did, and its leading newlines are the file's own (see
    // parse_can_rewrite_white_space), so they count the lines to its first non-blank character.
    int newlines = 0;
    for (const char* c = node.value(); is_xml_space(*c); ++c) newlines += *c == '\n' ? 1 : 0;
    return line_at(offset) + newlines;
}

/// The line of the attribute itself, which can differ from its element's (appendix B puts `orientation` on
/// the next line). pugixml parses in place, so the attribute's name points into text_ at the attribute's own
/// position (names are never moved); anything else falls back to the element's line.
int Reader::line_of(const pugi::xml_attribute& attribute, const pugi::xml_node& element) const {
    const char* name = attribute.name();
    if (name >= text_.data() && name < text_.data() + text_.size()) return line_at(name - text_.data());
    return line_of(element);
}

Result<XmlModel> Reader::run() {
    Result<pugi::xml_node> hierarchy = parse_hierarchy();
    if (!hierarchy) return hierarchy.error();
    Result<VolumeWalk> walk = walk_volumes(*hierarchy);
    if (!walk) return walk.error();

    XmlModel model;
    detail::reserve_on_huge_pages(model.primitives, walk->primitive_count);
    model.primitives.resize(walk->primitive_count);
    std::vector<BoundingVolume> inner_volumes;
    detail::reserve_on_huge_pages(inner_volumes, walk->inner_count);
    inner_volumes.resize(walk->inner_count);
    if (std::optional<Error> problem = convert_volumes(*walk, model.primitives, inner_volumes)) return *std::move(problem);
    if (!walk->nested) return model;

    // A nested file is one tree. The survey's root is "the first volume element"; a second top-level
    // volume would need a BV nobody wrote, so it is an error rather than a guess.
    if (walk->second_top_level)
        return error(line_of(walk->second_top_level),
                     "a nested hierarchy must have exactly one top-level <volume>, but this is a second one");
    assemble_tree(*walk, model, std::move(inner_volumes));
    return model;
}

/// Parses the text and finds its one top-level element, <hierarchy>, which must have no attributes.
Result<pugi::xml_node> Reader::parse_hierarchy() {
    // Whitespace-only input gets its own message: "no element found" would puzzle.
    std::string_view body = text_;
    if (body.starts_with("\xEF\xBB\xBF")) body.remove_prefix(3);  // a UTF-8 byte order mark
    if (is_blank(body)) return error(1, "file is empty");
    // pugixml stops at a NUL byte and drops text after the root element without a word; either means a damaged
    // or padded file, not a model, so both are refused here. A NUL inside the root ends the parse with an error
    // of its own, so only what follows the last </hierarchy> is searched (a scan of all 230 MB of a 10^6-primitive
    // file cost a quarter of its read).
    const std::size_t root_end = text_.rfind("</hierarchy");
    if (const std::size_t nul = text_.find('\0', root_end == std::string::npos ? 0 : root_end); nul != std::string::npos)
        return error(line_at(static_cast<std::ptrdiff_t>(nul)), "a NUL byte: the file is binary or damaged");
    // Looked for before the parse, which writes into the text: text after the last '>' (reported after the parse,
    // because a file cut short ends in such text too, and that is said better), and whether the root is closed.
    const std::size_t last_tag = text_.rfind('>');
    std::optional<std::size_t> trailing_text;
    if (last_tag != std::string::npos && !is_blank(std::string_view(text_).substr(last_tag + 1)))
        trailing_text = text_.find_first_not_of(" \t\r\n", last_tag + 1);
    const bool root_open = text_.find("<hierarchy") != std::string::npos &&
                           (root_end == std::string::npos || text_.find('>', root_end) == std::string::npos);
    const pugi::xml_parse_result parsed =
        doc_.load_buffer_inplace(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!parsed) {
        // The parser stops where its token began; one that began at or after the last '>' never closed, and with
        // the root opened and not closed, the text ended inside an open tag or element: the file was cut short.
        if (root_open && (last_tag == std::string::npos || parsed.offset >= static_cast<std::ptrdiff_t>(last_tag)))
            return error(line_at(static_cast<std::ptrdiff_t>(text_.size()) - 1),
                         "the file ends inside an unclosed tag or element: it is cut short (" +
                             std::to_string(text_.size()) + " bytes)");
        return error(line_at(parsed.offset), describe_parse_error(parsed));
    }
    if (trailing_text)
        return error(line_at(static_cast<std::ptrdiff_t>(*trailing_text)), "text after the end of the document's last tag");

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
    return hierarchy;
}

/// Collects the <volume> children of `parent` and rejects anything else that holds information
/// (other elements, text). Comments and processing instructions are dropped by the parser already.
std::optional<Error> Reader::check_structure_of(const pugi::xml_node& parent,
                                               detail::LargeVector<pugi::xml_node>& volumes) const {
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

/// Lists every volume in document pre-order with an explicit stack (a deeply nested file must not overflow
/// the call stack), checking what each element contains. Problems inside <hierarchy> itself come first, as
/// they did when this walk and the conversion were one loop; a problem inside a volume is kept for later.
Result<VolumeWalk> Reader::walk_volumes(const pugi::xml_node& hierarchy) const {
    // The arrays over every volume are on huge pages (memory/huge_pages.hpp), as are the primitives below.
    detail::LargeVector<pugi::xml_node> top_level;
    if (auto problem = check_structure_of(hierarchy, top_level)) return *std::move(problem);
    if (top_level.empty()) return error(line_of(hierarchy), "<hierarchy> contains no <volume> elements");
    VolumeWalk walk;
    walk.volumes.reserve(top_level.size());
    if (top_level.size() > 1) walk.second_top_level = top_level[1];

    detail::LargeVector<std::pair<pugi::xml_node, std::uint32_t>> stack;  // (element, parent volume)
    for (auto it = top_level.rbegin(); it != top_level.rend(); ++it) stack.emplace_back(*it, no_parent);
    detail::LargeVector<pugi::xml_node> children;
    while (!stack.empty()) {
        const auto [element, parent] = stack.back();
        stack.pop_back();
        const auto index = static_cast<std::uint32_t>(walk.volumes.size());
        VolumeElement& volume = walk.volumes.emplace_back(VolumeElement{element, parent});
        children.clear();
        if (auto problem = check_structure_of(element, children)) {
            volume.slot = walk.primitive_count++;  // converted like the volumes before it, then dropped
            walk.problem = std::move(problem);
            walk.problem_after = index;
            break;
        }
        volume.is_leaf = children.empty();
        volume.slot = volume.is_leaf ? walk.primitive_count++ : walk.inner_count++;
        walk.nested = walk.nested || !volume.is_leaf;
        for (auto it = children.rbegin(); it != children.rend(); ++it) stack.emplace_back(*it, index);
    }
    return walk;
}

/// Converts every walked volume into its primitive or inner volume, on all cores for a large file. Each
/// volume has two order keys, 2i for its own problems and 2i + 1 for a problem of structure found inside it,
/// so the error returned is the one the one-pass reader met first, whatever the thread count.
std::optional<Error> Reader::convert_volumes(const VolumeWalk& walk, std::vector<Primitive>& primitives,
                                             std::vector<BoundingVolume>& inner_volumes) const {
    FirstFailure first;
    if (walk.problem) first.report(2 * walk.problem_after + 1, *walk.problem);
    const auto convert_range = [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end && !first.is_known_before(2 * i); ++i)
            if (std::optional<Error> problem = convert_volume(walk.volumes[i], primitives, inner_volumes))
                first.report(2 * i, *std::move(problem));
    };
    const std::size_t count = walk.volumes.size();
    if (count < parallel_volume_count) {
        convert_range(0, count);
    } else {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1024),
                          [&](const tbb::blocked_range<std::size_t>& range) { convert_range(range.begin(), range.end()); });
    }
    return std::move(first).take();
}

/// Reads one volume into its own slot (each slot belongs to one volume, so threads never share one).
std::optional<Error> Reader::convert_volume(const VolumeElement& volume, std::vector<Primitive>& primitives,
                                            std::vector<BoundingVolume>& inner_volumes) const {
    Result<ParsedVolume> parsed = read_volume(volume.element);
    if (!parsed) return parsed.error();
    // Each number can be finite while what is derived from them is not (a box's centre from corners near
    // 1e308, a capsule's length beyond 1e154); such a volume could not be written back or fitted.
    if (!detail::is_representable(parsed->volume))
        return error(line_of(volume.element), "volume's centre, length or extents overflow the range of double");
    if (volume.is_leaf) {
        primitives[volume.slot] = Primitive{std::move(parsed->volume), std::string(parsed->name)};
    } else {
        inner_volumes[volume.slot] = std::move(parsed->volume);
    }
    return std::nullopt;
}

/// Builds the tree of a nested file and each node's line. The leaves are the primitives, numbered in
/// document order, which `model.primitives` already holds.
void Reader::assemble_tree(const VolumeWalk& walk, XmlModel& model, std::vector<BoundingVolume> inner_volumes) {
    const auto& volumes = walk.volumes;
    detail::LargeVector<std::ptrdiff_t> offsets;  // ascending: pre-order is document order
    offsets.reserve(volumes.size());
    for (const VolumeElement& volume : volumes) offsets.push_back(volume.element.offset_debug());
    const std::vector<int> element_lines = lines_.lines_of_ascending(offsets);
    // The document and its text are no longer needed; the tree needs memory of its own.
    doc_.reset();
    std::string().swap(text_);
    std::string().swap(pristine_);

    // Each volume's children in document order, as ranges of one array (pre-order lists them in order).
    detail::LargeVector<std::uint32_t> first_child(volumes.size() + 1, 0);
    for (const VolumeElement& volume : volumes)
        if (volume.parent != no_parent) ++first_child[volume.parent + 1];
    for (std::size_t i = 0; i < volumes.size(); ++i) first_child[i + 1] += first_child[i];
    detail::LargeVector<std::uint32_t> children(volumes.size());
    detail::LargeVector<std::uint32_t> filled(first_child.begin(), first_child.end() - 1);
    for (std::uint32_t i = 0; i < volumes.size(); ++i)
        if (volumes[i].parent != no_parent) children[filled[volumes[i].parent]++] = i;

    // Children come after their parent in pre-order, so walking backwards meets every child before its
    // parent, as TreeAssembler::add_group needs. It also collapses single-child volumes.
    TreeAssembler assembler(model.primitives);
    assembler.reserve(volumes.size());
    detail::LargeVector<std::uint32_t> id(volumes.size(), 0);
    std::vector<std::uint32_t> child_ids;
    for (std::size_t i = volumes.size(); i-- > 0;) {
        if (volumes[i].is_leaf) {
            id[i] = assembler.add_leaf(volumes[i].slot);
            continue;
        }
        child_ids.clear();
        for (std::uint32_t c = first_child[i]; c < first_child[i + 1]; ++c) child_ids.push_back(id[children[c]]);
        id[i] = assembler.add_group(child_ids, std::move(inner_volumes[volumes[i].slot]));
    }
    std::vector<std::uint32_t> assembler_id_of_node;
    model.hierarchy = std::move(assembler).finish(id[0], &assembler_id_of_node);

    detail::LargeVector<std::uint32_t> volume_of_assembler_id(volumes.size());
    for (std::uint32_t i = 0; i < volumes.size(); ++i) volume_of_assembler_id[id[i]] = i;
    detail::reserve_on_huge_pages(model.node_lines, assembler_id_of_node.size());
    for (const std::uint32_t assembler_id : assembler_id_of_node)
        model.node_lines.push_back(element_lines[volume_of_assembler_id[assembler_id]]);
}

Result<ParsedVolume> Reader::read_volume(const pugi::xml_node& element) const {
    // Stage 1: the type decides which attributes are allowed.
    const pugi::xml_attribute type_attribute = element.attribute("type");
    if (!type_attribute) return error(line_of(element), "missing attribute 'type' on <volume>");
    const std::string_view type_name = type_attribute.value();
    const std::optional<BvType> type = parse_bv_type(type_name);
    if (!type)
        return error(line_of(type_attribute, element),
                     "unknown volume type \"" + excerpt(type_name) + "\" (expected aabb, obb, sphere or capsule)");

    // Stage 2: every attribute is known, allowed for this type and given once.
    Result<VolumeAttributes> attributes = collect_attributes(element, *type, type_name);
    if (!attributes) return attributes.error();
    const pugi::xml_attribute position = (*attributes)[static_cast<std::size_t>(Key::pos)];
    if (!position) return error(line_of(element), "missing attribute 'pos' on <volume type=\"" + std::string(type_name) + "\">");
    const std::string_view name = (*attributes)[static_cast<std::size_t>(Key::name)].value();

    // Stage 3: read the numbers.
    const Result<Vec3> centre = read_vector(element, position);
    if (!centre) return centre.error();
    Result<BoundingVolume> volume = *type == BvType::sphere || *type == BvType::capsule
                                        ? read_round(element, *attributes, *type, *centre, type_name)
                                        : read_box(element, *attributes, *centre, type_name);
    if (!volume) return volume.error();
    return ParsedVolume{std::move(volume).value(), name};
}

/// Each attribute of `element` by its key, in one pass; the first unknown, misplaced or repeated one is an
/// error at its own line.
Result<VolumeAttributes> Reader::collect_attributes(const pugi::xml_node& element, BvType type,
                                                    std::string_view type_name) const {
    const std::uint32_t allowed = common_keys | keys_of(type);
    VolumeAttributes attributes{};
    for (const pugi::xml_attribute& attribute : element.attributes()) {
        const std::string_view spelled = attribute.name();
        const std::optional<Key> key = key_of(spelled);
        const auto line = [&] { return line_of(attribute, element); };
        if (!key)
            return error(line(), "unknown attribute '" + excerpt(spelled) + "' on <volume type=\"" +
                                     std::string(type_name) + "\">");
        if ((allowed & bit(*key)) == 0)
            return error(line(), "attribute '" + key_name(*key) + "' does not apply to type=\"" + std::string(type_name) + "\"");
        pugi::xml_attribute& earlier = attributes[static_cast<std::size_t>(*key)];
        if (earlier) {
            if (std::string_view(earlier.name()) != spelled) return error(line(), "both 'pos' and 'position' given; use one");
            return error(line(), "attribute '" + key_name(*key) + "' given twice");
        }
        earlier = attribute;
    }
    return attributes;
}

Result<pugi::xml_attribute> Reader::required(const pugi::xml_node& element, const VolumeAttributes& attributes, Key key,
                                             std::string_view type_name) const {
    const pugi::xml_attribute attribute = attributes[static_cast<std::size_t>(key)];
    if (!attribute)
        return error(line_of(element),
                     "missing attribute '" + key_name(key) + "' on <volume type=\"" + std::string(type_name) + "\">");
    return attribute;
}

/// A sphere, or a capsule: `pos` is the centre of its segment.
Result<BoundingVolume> Reader::read_round(const pugi::xml_node& element, const VolumeAttributes& attributes, BvType type,
                                          const Vec3& centre, std::string_view type_name) const {
    const Result<pugi::xml_attribute> radius_attribute = required(element, attributes, Key::radius, type_name);
    if (!radius_attribute) return radius_attribute.error();
    // Radius 0 (a point, a segment) is a valid primitive in the library, and build() keeps it: the file must
    // be able to hold what the writer writes.
    const Result<double> radius = read_size(element, *radius_attribute);
    if (!radius) return radius.error();
    if (type == BvType::sphere) return BoundingVolume(Sphere{centre, *radius});

    const Result<pugi::xml_attribute> direction_attribute = required(element, attributes, Key::direction, type_name);
    if (!direction_attribute) return direction_attribute.error();
    const Result<Vec3> direction = read_vector(element, *direction_attribute);
    if (!direction) return direction.error();
    // stableNorm: a tiny but valid direction like (1e-200, 0, 0) must not underflow to zero.
    const double norm = direction->stableNorm();
    if (!(norm > 0.0) || !std::isfinite(norm))
        return error(line_of(*direction_attribute, element), "attribute 'direction' must not be the zero vector");
    const Result<pugi::xml_attribute> length_attribute = required(element, attributes, Key::length, type_name);
    if (!length_attribute) return length_attribute.error();
    // Length 0 is a sphere written as a capsule; that is still a valid capsule.
    const Result<double> length = read_size(element, *length_attribute);
    if (!length) return length.error();
    const Capsule capsule = capsule_from_fields(centre, *direction, *length, *radius);
    if (!capsule.p0.allFinite() || !capsule.p1.allFinite())
        return error(line_of(element), "capsule ends overflow the range of double");
    return BoundingVolume(capsule);
}

/// A box: full extents along its local x, y, z axes; an OBB when it has an orientation, else an AABB.
Result<BoundingVolume> Reader::read_box(const pugi::xml_node& element, const VolumeAttributes& attributes,
                                        const Vec3& centre, std::string_view type_name) const {
    Vec3 extents;
    constexpr std::array<Key, 3> axes{Key::width, Key::depth, Key::height};
    for (int axis = 0; axis < 3; ++axis) {
        const Result<pugi::xml_attribute> attribute =
            required(element, attributes, axes[static_cast<std::size_t>(axis)], type_name);
        if (!attribute) return attribute.error();
        const Result<double> extent = read_size(element, *attribute);  // 0: a flat box
        if (!extent) return extent.error();
        extents[axis] = *extent;
    }
    const Vec3 half = 0.5 * extents;
    // The survey's footnote 4: "AABBs are OBBs with no orientation".
    const pugi::xml_attribute orientation_attribute = attributes[static_cast<std::size_t>(Key::orientation)];
    if (!orientation_attribute) {
        // Stored as corners, an AABB can lose what the file says: far from the origin a small extent
        // rounds away, and a huge one overflows. Refuse instead of returning a flat or infinite box.
        const Aabb box = aabb_from_fields(centre, extents);
        if (!box.min.allFinite() || !box.max.allFinite())
            return error(line_of(element), "box corners overflow the range of double");
        if (((box.max - box.min).array() <= 0.0 && extents.array() > 0.0).any())
            return error(line_of(element), "box extents vanish in rounding: they are too small for its position");
        return BoundingVolume(box);
    }
    // An OBB stores half sizes: a positive size whose half is 0 or subnormal would be a box the writer gives back
    // as another (width="0") or one the library refuses without naming the line.
    if ((half.array() < std::numeric_limits<double>::min() && extents.array() > 0.0).any())
        return error(line_of(element), "box sizes are too small: half of each must be a normal double (sizes of at "
                                       "least 4.5e-308)");
    const Result<Mat3> rotation = read_orientation(element, orientation_attribute);
    if (!rotation) return rotation.error();
    return BoundingVolume(Obb{centre, *rotation, half});
}

/// Exactly `count` whitespace-separated finite numbers, parsed straight from the attribute's text.
template <std::size_t count>
Result<std::array<double, count>> Reader::read_numbers(const pugi::xml_node& element,
                                                       const pugi::xml_attribute& attribute) const {
    const auto line = [&] { return line_of(attribute, element); };
    const auto key = [&] { return std::string(attribute.name()); };
    const auto needs = [&] { return "attribute '" + key() + "' needs " + std::to_string(count) + (count == 1 ? " number" : " numbers"); };
    // Tokens are cut from the value's C string as it is scanned: measuring it first would read it twice.
    const char* rest = attribute.value();
    std::array<double, count> numbers{};
    std::size_t found = 0;
    for (;;) {
        while (is_xml_space(*rest)) ++rest;
        if (*rest == '\0') break;
        const char* token_end = rest;
        while (*token_end != '\0' && !is_xml_space(*token_end)) ++token_end;
        const std::string_view token(rest, static_cast<std::size_t>(token_end - rest));
        rest = token_end;
        if (found == count) return error(line(), needs() + ", found more (extra \"" + excerpt(token) + "\")");
        // from_chars refuses a leading '+', which people do write; accept it unless a sign follows.
        std::string_view digits = token;
        if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-' && digits[1] != '+') digits.remove_prefix(1);
        double value = 0.0;
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
        if (ec == std::errc::result_out_of_range)
            return error(line(), "attribute '" + key() + "': \"" + excerpt(token) + "\" is out of the range of double");
        if (ec != std::errc{} || end != digits.data() + digits.size())
            return error(line(), "attribute '" + key() + "': \"" + excerpt(token) + "\" is not a number");
        if (!std::isfinite(value))
            return error(line(), "attribute '" + key() + "': \"" + excerpt(token) + "\" is not a finite number");
        numbers[found++] = value;
    }
    if (found != count) return error(line(), needs() + ", found " + std::to_string(found));
    return numbers;
}

Result<Vec3> Reader::read_vector(const pugi::xml_node& element, const pugi::xml_attribute& attribute) const {
    const Result<std::array<double, 3>> numbers = read_numbers<3>(element, attribute);
    if (!numbers) return numbers.error();
    return Vec3((*numbers)[0], (*numbers)[1], (*numbers)[2]);
}

Result<double> Reader::read_size(const pugi::xml_node& element, const pugi::xml_attribute& attribute) const {
    const Result<std::array<double, 1>> numbers = read_numbers<1>(element, attribute);
    if (!numbers) return numbers.error();
    const double value = (*numbers)[0];
    // A subnormal size is refused here, with its line, as validate_primitives() would refuse it without one.
    if (value > 0.0 && value < std::numeric_limits<double>::min())
        return error(line_of(attribute, element), "attribute '" + std::string(attribute.name()) + "' is " +
                                                      attribute.value() +
                                                      ", below the smallest normal double (2.2e-308); sizes are 0 or normal");
    if (value >= 0.0) return value;
    return error(line_of(attribute, element),
                 "attribute '" + std::string(attribute.name()) + "' must be >= 0, found " + attribute.value());
}

Result<Mat3> Reader::read_orientation(const pugi::xml_node& element, const pugi::xml_attribute& attribute) const {
    const Result<std::array<double, 9>> numbers = read_numbers<9>(element, attribute);
    if (!numbers) return numbers.error();
    Mat3 m;
    for (int row = 0; row < 3; ++row)
        for (int column = 0; column < 3; ++column) m(row, column) = (*numbers)[static_cast<std::size_t>(3 * row + column)];

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
    // A matrix that is a rotation to the library's own tolerance (what hbvh writes, with every digit) is kept
    // bit for bit, so that reading a file hbvh wrote gives back its volumes and a rewrite is the same file
    // (replacing every matrix by its polar factor changed the last bits of each OBB on every pass).
    if (rotation_problem(m).empty()) return m;
    // det(M) > 0 and R^T R near I (checked above) make the polar factor a proper rotation.
    return nearest_rotation(m);
}

// Writing. The text is what pugixml's save(format_indent, two spaces) wrote when the writer built a DOM:
// the declaration, one element per line, children indented by two spaces, empty elements closed by " />".

}  // namespace

Result<XmlModel> read_xml_string(std::string_view text, std::string_view source_name) {
    return Reader(std::string(text), source_name).run();
}

Result<XmlModel> read_xml_file(const std::filesystem::path& path) {
    Result<std::string> text = read_text_file(path);
    if (!text) return text.error();
    return detail::read_xml_taking(std::move(text).value(), path.string());
}

namespace detail {
Result<XmlModel> read_xml_taking(std::string text, std::string_view source_name) {
    return Reader(std::move(text), source_name).run();
}
}  // namespace detail

}  // namespace hbvh
