// SPDX-License-Identifier: MIT
// Graphviz writer for the tree view of a hierarchy.
#include "hbvh/io/export_dot.hpp"

#include <cstdio>

#include "hbvh/io/level_view.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

/// A DOT double-quoted string body: quotes and backslashes escaped, newlines as DOT's centred "\n".
std::string escape(const std::string& text) {
    std::string out;
    for (char c : text) {
        if (c == '"' || c == '\\') out += '\\';
        if (c == '\n') {
            out += "\\n";
            continue;
        }
        out += c;
    }
    return out;
}

std::string format_number(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.4g", value);
    return buffer;
}

/// Halfway to white, so black text stays readable on every level colour.
std::string light(const Rgb& color) {
    return to_hex({0.5 + 0.5 * color[0], 0.5 + 0.5 * color[1], 0.5 + 0.5 * color[2]});
}

std::string label(const Bvh& bvh, std::uint32_t index) {
    const Node& node = bvh.nodes[index];
    const std::string type(to_string(type_of(node.volume)));
    const std::string volume_text = "V = " + format_number(volume(node.volume));
    if (!node.is_leaf())
        return type + "\n" + volume_text + "\n" + std::to_string(node.child_count) + " children";
    const Primitive& primitive = bvh.primitives[node.primitive];
    std::string first = "#" + std::to_string(node.primitive);
    if (!primitive.name.empty()) first += " " + primitive.name;
    return first + "\n" + type + "\n" + volume_text;
}

}  // namespace

std::string export_dot(const Bvh& bvh, const DotOptions& options) {
    std::string out = "digraph hbvh {\n";
    if (bvh.empty()) return out + "}\n";
    const std::vector<LevelView> views = level_views(bvh);
    const auto height = static_cast<std::uint32_t>(views.size() - 1);
    const Stats stats = compute_stats(bvh);
    out += "  graph [rankdir=TB, ranksep=0.35, nodesep=0.12, fontname=\"Helvetica\", fontsize=12, labelloc=t, label=\"" +
           escape(std::to_string(stats.nodes) + (stats.nodes == 1 ? " node (" : " nodes (") + std::to_string(stats.leaves) +
                  (stats.leaves == 1 ? " primitive), height " : " primitives), height ") +
                  std::to_string(stats.height) + ", cost " + format_number(stats.cost)) +
           "\"];\n";
    out += "  node [shape=box, style=\"rounded,filled\", fontname=\"Helvetica\", fontsize=9, margin=\"0.06,0.03\"];\n";
    out += "  edge [arrowhead=none, color=\"#555555\"];\n";

    // Stage 1: nodes, one rank per depth. With carried leaves every primitive goes to the bottom rank.
    for (const LevelView& view : views) {
        std::string rank = "  { rank=same;";
        for (std::uint32_t index : view.nodes) {
            const bool leaf = bvh.nodes[index].is_leaf();
            const std::uint32_t drawn_depth = leaf && options.carry_leaves ? height : view.depth;
            if (drawn_depth != view.depth) continue;  // drawn with the bottom rank
            rank += " n" + std::to_string(index) + ";";
        }
        if (options.carry_leaves && view.depth == height)
            for (std::uint32_t index : view.carried) rank += " n" + std::to_string(index) + ";";
        for (std::uint32_t index : view.carried)
            if (options.carry_leaves && view.depth < height)
                rank += " c" + std::to_string(index) + "_" + std::to_string(view.depth) + ";";
        out += rank + " }\n";
    }
    for (const LevelView& view : views)
        for (std::uint32_t index : view.nodes)
            out += "  n" + std::to_string(index) + " [label=\"" + escape(label(bvh, index)) + "\", fillcolor=\"" +
                   light(level_color(view.depth)) + "\"];\n";

    // Stage 2: edges. A leaf at depth d < height reaches the bottom through grey copies at d..height-1,
    // so each level still shows the complete cover (see LevelView).
    std::vector<std::uint32_t> depth(bvh.nodes.size(), 0);
    for (const LevelView& view : views)
        for (std::uint32_t index : view.nodes) depth[index] = view.depth;
    for (std::uint32_t parent = 0; parent < bvh.nodes.size(); ++parent) {
        const Node& node = bvh.nodes[parent];
        const std::uint32_t depth_of_children = depth[parent] + 1;
        for (std::uint32_t c = 0; c < node.child_count; ++c) {
            const std::uint32_t child = node.first_child + c;
            std::string from = "n" + std::to_string(parent);
            if (options.carry_leaves && bvh.nodes[child].is_leaf()) {
                for (std::uint32_t level = depth_of_children; level < height; ++level) {
                    const std::string copy = "c" + std::to_string(child) + "_" + std::to_string(level);
                    out += "  " + copy + " [label=\"" + escape(label(bvh, child)) +
                           "\", fillcolor=\"#e6e6e6\", color=\"#999999\", fontcolor=\"#666666\", style=\"rounded,filled,dashed\"];\n";
                    out += "  " + from + " -> " + copy + ";\n";
                    from = copy;
                }
            }
            out += "  " + from + " -> n" + std::to_string(child) + ";\n";
        }
    }
    return out + "}\n";
}

}  // namespace hbvh
