// SPDX-License-Identifier: MIT
// Level covers and the shared colour scheme of the exporters.
#include "hbvh/io/level_view.hpp"

#include <algorithm>
#include <cmath>

namespace hbvh {

std::vector<LevelView> level_views(const Bvh& bvh) {
    const std::vector<std::vector<std::uint32_t>> by_depth = levels(bvh);
    std::vector<LevelView> views(by_depth.size());
    // Leaves seen so far; each later level carries all of them.
    std::vector<std::uint32_t> leaves_above;
    for (std::uint32_t depth = 0; depth < by_depth.size(); ++depth) {
        LevelView& view = views[depth];
        view.depth = depth;
        view.nodes = by_depth[depth];
        std::sort(view.nodes.begin(), view.nodes.end());
        view.carried = leaves_above;
        std::sort(view.carried.begin(), view.carried.end());
        for (std::uint32_t index : view.nodes) {
            const Node& node = bvh.nodes[index];
            view.volume += volume(node.volume);
            if (node.is_leaf()) {
                leaves_above.push_back(index);
            } else {
                ++view.inner_count;
                view.cost += node.child_count * volume(node.volume);
            }
        }
    }
    return views;
}

Rgb level_color(std::uint32_t depth) {
    // Hand-picked to stay apart from each other and from the carried grey, light enough for black text.
    static constexpr std::array<Rgb, 8> palette{{
        {0.89, 0.29, 0.24},  // red
        {0.96, 0.62, 0.13},  // orange
        {0.30, 0.69, 0.31},  // green
        {0.18, 0.52, 0.90},  // blue
        {0.60, 0.38, 0.85},  // violet
        {0.09, 0.74, 0.74},  // teal
        {0.90, 0.42, 0.69},  // pink
        {0.62, 0.60, 0.12},  // olive
    }};
    return palette[depth % palette.size()];
}

Rgb carried_color() { return {0.62, 0.62, 0.62}; }

std::string to_hex(const Rgb& color) {
    static constexpr char digits[] = "0123456789abcdef";
    std::string out = "#000000";
    for (std::size_t k = 0; k < 3; ++k) {
        const auto byte = static_cast<unsigned>(std::lround(std::clamp(color[k], 0.0, 1.0) * 255.0));
        out[1 + 2 * k] = digits[byte >> 4];
        out[2 + 2 * k] = digits[byte & 15u];
    }
    return out;
}

}  // namespace hbvh
