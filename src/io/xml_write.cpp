// SPDX-License-Identifier: MIT
// The survey XML writer: the text formatted directly (no DOM), byte for byte as pugixml's `save` wrote it, large
// inputs in chunks on all cores (docs/formats.md, "Reading and writing large XML"). The reader is xml_read.cpp.
#include "hbvh/io/xml.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "hbvh/assert.hpp"
#include "../memory/huge_pages.hpp"
#include "../tree/utf8.hpp"
#include "xml_fields.hpp"
#include "xml_number.hpp"

namespace hbvh {
namespace {

using detail::AabbFields;
using detail::append_number;
using detail::CapsuleFields;
using detail::exact_aabb_fields;
using detail::exact_capsule_fields;

constexpr std::string_view declaration = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";

/// An attribute value as pugixml escapes it: & < " as entities (not >, which needs none in a value), tab, line
/// feed and carriage return as "&#NN;" (two digits, so that attribute normalisation keeps them), everything else,
/// UTF-8 included, as it is; except the other control characters, which XML 1.0 allows in no form, not even as a
/// reference (libxml2 and expat refuse "&#01;", where pugixml read it), so they are written as U+FFFD, as a name
/// that is no UTF-8 is. pugixml took the value as a C string, so a name ends at its first NUL.
template <class Out>
void append_escaped(Out& out, std::string_view text) {
    text = text.substr(0, text.find('\0'));
    for (const char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '"': out += "&quot;"; break;
            default:
                if (const auto code = static_cast<unsigned char>(c); code < 32 && code != '\t' && code != '\n' && code != '\r') {
                    out += "\xEF\xBF\xBD";  // U+FFFD
                } else if (code < 32) {
                    out += "&#";
                    out += static_cast<char>('0' + code / 10);
                    out += static_cast<char>('0' + code % 10);
                    out += ';';
                } else {
                    out += c;
                }
        }
    }
}

/// ` key="n0 n1 ..."`, each number in its shortest round-trip form.
template <class Out>
void append_numbers(Out& out, std::string_view key, std::initializer_list<double> values) {
    out += ' ';
    out += key;
    out += "=\"";
    bool first = true;
    for (const double value : values) {
        if (!first) out += ' ';
        first = false;
        append_number(out, value);
    }
    out += '"';
}

template <class Out>
void append_vector(Out& out, std::string_view key, const Vec3& v) { append_numbers(out, key, {v.x(), v.y(), v.z()}); }

template <class Out>
void append_indent(Out& out, std::size_t depth) { out.append(2 * depth, ' '); }

/// One <volume> start tag on its own line, `depth` levels deep. Attribute order: type, name (if any), pos,
/// then the type's own. It is closed at once (" />") unless children follow.
template <class Out>
void append_volume(Out& out, const BoundingVolume& bv, std::string_view name, std::size_t depth, bool has_children) {
    append_indent(out, depth);
    out += "<volume type=\"";
    out += to_string(type_of(bv));
    out += '"';
    if (!name.empty()) {
        out += " name=\"";
        // The declaration promises UTF-8: a name that is none (from a Latin-1 asset) is written repaired.
        std::size_t bad_at = 0;
        if (detail::utf8_problem(name, bad_at).empty())
            append_escaped(out, name);
        else
            append_escaped(out, detail::utf8_name(name));
        out += '"';
    }
    std::visit(Overloaded{
                   [&](const Aabb& box) {
                       // Fields the reader turns back into these very corners (xml_fields.hpp).
                       const AabbFields fields = exact_aabb_fields(box);
                       append_vector(out, "pos", fields.centre);
                       append_numbers(out, "width", {fields.extents.x()});
                       append_numbers(out, "depth", {fields.extents.y()});
                       append_numbers(out, "height", {fields.extents.z()});
                   },
                   [&](const Obb& box) {
                       const Vec3 extents = 2.0 * box.half_extents;
                       const Mat3& r = box.rotation;
                       append_vector(out, "pos", box.center);
                       append_numbers(out, "width", {extents.x()});
                       append_numbers(out, "depth", {extents.y()});
                       append_numbers(out, "height", {extents.z()});
                       append_numbers(out, "orientation",
                                      {r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)});
                   },
                   [&](const Sphere& sphere) {
                       append_vector(out, "pos", sphere.center);
                       append_numbers(out, "radius", {sphere.radius});
                   },
                   [&](const Capsule& capsule) {
                       const CapsuleFields fields = exact_capsule_fields(capsule);  // these very ends, read back
                       append_vector(out, "pos", fields.centre);
                       append_vector(out, "direction", fields.direction);
                       append_numbers(out, "length", {fields.length});
                       append_numbers(out, "radius", {capsule.radius});
                   },
               },
               bv);
    out += has_children ? ">\n" : " />\n";
}

template <class Out>
void append_end_tag(Out& out, std::size_t depth) {
    append_indent(out, depth);
    out += "</volume>\n";
}

/// The subtree under `root` as nested volumes, `depth` levels deep. Explicit stack: a degenerate
/// (list-like) tree can be deeper than the call stack allows.
template <class Out>
void append_subtree(Out& out, const Bvh& bvh, std::uint32_t root, std::size_t depth) {
    struct Step {
        std::uint32_t node;
        std::size_t depth;
        bool closes;  ///< The end tag of an inner node, after its children.
    };
    std::vector<Step> stack{{root, depth, false}};
    while (!stack.empty()) {
        const Step step = stack.back();
        stack.pop_back();
        if (step.closes) {
            append_end_tag(out, step.depth);
            continue;
        }
        const Node& node = bvh.nodes[step.node];
        // Broken indices are a bug in whoever built the tree, not bad input.
        HBVH_ASSERT(node.is_leaf() ? node.primitive < bvh.primitives.size()
                                   : std::size_t{node.first_child} + node.child_count <= bvh.nodes.size());
        if (node.is_leaf()) {
            const Primitive& primitive = bvh.primitives[node.primitive];
            append_volume(out, primitive.volume, primitive.name, step.depth, false);
            continue;
        }
        append_volume(out, node.volume, {}, step.depth, true);
        stack.push_back({step.node, step.depth, true});
        // Pushed in reverse so that they pop, and are written, in child order.
        for (std::uint32_t c = node.child_count; c-- > 0;) stack.push_back({node.first_child + c, step.depth + 1, false});
    }
}

/// A formatting chunk's text, on huge pages from 4 MiB on (memory/huge_pages.hpp): at 10^6 volumes the chunks
/// and the joined text are 460 MB of fresh memory, and in 4 KiB pages their faults were half the formatting.
using ChunkText = std::basic_string<char, std::char_traits<char>, detail::HugePageAllocator<char>>;

/// Appends the text of items [0, count) to `out`, `append_item(text, i)` writing item i. Many items are
/// formatted in chunks on all cores (shortest-form numbers are most of the work) and joined in order, so
/// the text is the same for any thread count. Each chunk reserves `chunk_reserve` bytes at once where its size
/// is known roughly: growing to it by doubling would touch twice as much memory, in small pages.
template <class AppendItem>
void append_items(std::string& out, std::size_t count, std::size_t items_per_chunk, std::size_t chunk_reserve,
                  const AppendItem& append_item) {
    const std::size_t chunk_count = (count + items_per_chunk - 1) / items_per_chunk;
    if (chunk_count <= 1) {
        for (std::size_t i = 0; i < count; ++i) append_item(out, i);
        return;
    }
    std::vector<ChunkText> chunks(chunk_count);
    tbb::parallel_for(std::size_t{0}, chunk_count, [&](std::size_t chunk) {
        chunks[chunk].reserve(chunk_reserve);
        const std::size_t end = std::min(count, (chunk + 1) * items_per_chunk);
        for (std::size_t i = chunk * items_per_chunk; i < end; ++i) append_item(chunks[chunk], i);
    });
    std::size_t size = out.size();
    for (const ChunkText& chunk : chunks) size += chunk.size();
    out.reserve(size + 64);  // room for the closing tags
    detail::advise_huge_pages(out.data(), out.capacity());
    for (ChunkText& chunk : chunks) {
        out.append(chunk.data(), chunk.size());
        ChunkText().swap(chunk);
    }
}

/// Volumes per formatting chunk of a primitive set: about 4 MB of text, enough to make a task worth starting
/// and to fill whole huge pages; and the bytes such a chunk reserves (an OBB's line is about 400 bytes, a
/// sphere's 130; capacity never touched costs nothing).
constexpr std::size_t volumes_per_chunk = 16384;
constexpr std::size_t set_chunk_reserve = volumes_per_chunk * 512;
/// From this many nodes on, a tree's subtrees are formatted on all cores.
constexpr std::size_t parallel_tree_nodes = 4096;

}  // namespace

std::string write_xml(const Bvh& bvh) {
    std::string out(declaration);
    if (bvh.empty()) return out + "<hierarchy />\n";
    out += "<hierarchy>\n";
    const Node& root = bvh.root();
    if (root.is_leaf()) {
        append_subtree(out, bvh, 0, 1);
    } else {
        // The root's subtrees are formatted side by side, in groups of consecutive children: enough groups
        // to keep every core busy under a wide root, one subtree each under a binary one.
        append_volume(out, root.volume, {}, 1, true);
        const bool is_large = bvh.nodes.size() >= parallel_tree_nodes;
        const std::size_t per_group = is_large ? std::max<std::size_t>(1, root.child_count / 64) : root.child_count;
        append_items(out, root.child_count, per_group, 0, [&](auto& text, std::size_t c) {
            append_subtree(text, bvh, root.first_child + static_cast<std::uint32_t>(c), 2);
        });
        append_end_tag(out, 1);
    }
    out += "</hierarchy>\n";
    return out;
}

std::string write_primitives_xml(std::span<const Primitive> primitives) {
    std::string out(declaration);
    if (primitives.empty()) return out + "<hierarchy />\n";
    out += "<hierarchy>\n";
    append_items(out, primitives.size(), volumes_per_chunk, set_chunk_reserve, [&](auto& text, std::size_t i) {
        append_volume(text, primitives[i].volume, primitives[i].name, 1, false);
    });
    out += "</hierarchy>\n";
    return out;
}

}  // namespace hbvh
