// SPDX-License-Identifier: MIT
// The summed pairwise intersection volume of many boxes, through a uniform grid.
#include "box_overlap.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace hbvh::detail {
namespace {

/// Below this many boxes every pair is compared: the grid costs more than it saves.
constexpr std::size_t pairwise_up_to = 64;
/// A box spanning more cells than this is compared with every other box instead of being binned, so that one
/// huge box among many small ones costs O(n), not O(cells).
constexpr std::uint64_t max_cells_per_box = 64;

double pairwise_brute_force(std::span<const Aabb> boxes) {
    double sum = 0.0;
    for (std::size_t i = 0; i < boxes.size(); ++i)
        for (std::size_t j = i + 1; j < boxes.size(); ++j) sum += intersection_volume(boxes[i], boxes[j]);
    return sum;
}

/// A uniform grid over the boxes' union: cell coordinates of a point, clamped into the grid.
struct Grid {
    Vec3 origin;
    Vec3 inverse_cell;  ///< 1 / cell size per axis (0 on an axis of zero extent: one cell there).
    std::array<std::int64_t, 3> cells{};

    [[nodiscard]] std::array<std::int64_t, 3> cell_of(const Vec3& p) const {
        std::array<std::int64_t, 3> c{};
        for (int k = 0; k < 3; ++k) {
            const double at = (p[k] - origin[k]) * inverse_cell[k];
            // NaN-free input (validated geometry); the clamp keeps rounding at the far faces inside.
            c[k] = std::clamp<std::int64_t>(at > 0.0 ? static_cast<std::int64_t>(at) : 0, 0, cells[k] - 1);
        }
        return c;
    }
    [[nodiscard]] std::uint64_t key(const std::array<std::int64_t, 3>& c) const {
        return static_cast<std::uint64_t>((c[2] * cells[1] + c[1]) * cells[0] + c[0]);
    }
};

}  // namespace

double intersection_volume(const Aabb& a, const Aabb& b) {
    const Vec3 lo = a.min.cwiseMax(b.min);
    const Vec3 hi = a.max.cwiseMin(b.max);
    return (hi - lo).cwiseMax(Vec3::Zero()).prod();
}

double pairwise_intersection_volume(std::span<const Aabb> boxes) {
    if (boxes.size() <= pairwise_up_to) return pairwise_brute_force(boxes);
    Aabb all = Aabb::empty();
    for (const Aabb& box : boxes) all = all.merged(box);
    const Vec3 extent = all.max - all.min;
    // Cubic cells, about one per box over the axes that have an extent, and no smaller than the median box's
    // longest side, so that a typical box spans at most 8 cells (and a thin axis gets one cell).
    int solid_axes = 0;
    double measure = 1.0;
    for (int k = 0; k < 3; ++k)
        if (extent[k] > 0.0) ++solid_axes, measure *= extent[k];
    if (solid_axes == 0) return 0.0;  // every box is the same point: no intersection has a volume
    std::vector<double> sides(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) sides[i] = (boxes[i].max - boxes[i].min).maxCoeff();
    std::nth_element(sides.begin(), sides.begin() + static_cast<std::ptrdiff_t>(sides.size() / 2), sides.end());
    const double cell = std::max(std::pow(measure / static_cast<double>(boxes.size()), 1.0 / solid_axes), sides[sides.size() / 2]);
    Grid grid;
    grid.origin = all.min;
    for (int k = 0; k < 3; ++k) {
        const double count = extent[k] > 0.0 ? std::clamp(std::ceil(extent[k] / cell), 1.0, 1e6) : 1.0;
        grid.cells[static_cast<std::size_t>(k)] = static_cast<std::int64_t>(count);
        grid.inverse_cell[k] = extent[k] > 0.0 ? count / extent[k] : 0.0;
    }

    // Every (cell, box) incidence of the binned boxes, sorted by cell; the large boxes apart.
    struct Entry {
        std::uint64_t cell;
        std::uint32_t box;
    };
    std::vector<Entry> entries;
    std::vector<std::uint32_t> large;
    for (std::uint32_t i = 0; i < boxes.size(); ++i) {
        const auto lo = grid.cell_of(boxes[i].min), hi = grid.cell_of(boxes[i].max);
        std::uint64_t spanned = 1;
        for (std::size_t k = 0; k < 3; ++k) spanned *= static_cast<std::uint64_t>(hi[k] - lo[k] + 1);
        if (spanned > max_cells_per_box) {
            large.push_back(i);
            continue;
        }
        for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
            for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
                for (std::int64_t x = lo[0]; x <= hi[0]; ++x) entries.push_back({grid.key({x, y, z}), i});
    }
    std::sort(entries.begin(), entries.end(),
              [](const Entry& a, const Entry& b) { return a.cell < b.cell || (a.cell == b.cell && a.box < b.box); });

    double sum = 0.0;
    // Binned pairs: in the cell that holds the lower corner of their intersection, which lies in both boxes and
    // so in a cell both were entered in; every other shared cell skips the pair.
    for (std::size_t begin = 0; begin < entries.size();) {
        std::size_t end = begin;
        while (end < entries.size() && entries[end].cell == entries[begin].cell) ++end;
        for (std::size_t a = begin; a < end; ++a)
            for (std::size_t b = a + 1; b < end; ++b) {
                const Aabb& p = boxes[entries[a].box];
                const Aabb& q = boxes[entries[b].box];
                const double v = intersection_volume(p, q);
                if (v > 0.0 && grid.key(grid.cell_of(p.min.cwiseMax(q.min))) == entries[begin].cell) sum += v;
            }
        begin = end;
    }
    // Large boxes: against every binned box, and against each other once.
    std::vector<bool> is_large(boxes.size(), false);
    for (const std::uint32_t i : large) is_large[i] = true;
    for (std::size_t a = 0; a < large.size(); ++a) {
        for (std::uint32_t j = 0; j < boxes.size(); ++j)
            if (!is_large[j]) sum += intersection_volume(boxes[large[a]], boxes[j]);
        for (std::size_t b = a + 1; b < large.size(); ++b) sum += intersection_volume(boxes[large[a]], boxes[large[b]]);
    }
    return sum;
}

}  // namespace hbvh::detail
