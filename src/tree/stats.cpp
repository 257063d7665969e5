// SPDX-License-Identifier: MIT
#include "hbvh/tree/stats.hpp"

#include <algorithm>
#include <limits>
#include <vector>

#include "box_overlap.hpp"

namespace hbvh {
namespace {
/// Accumulates min / mean / max.
class SummaryBuilder {
public:
    void add(double value) {
        min_ = std::min(min_, value);
        max_ = std::max(max_, value);
        sum_ += value;
        ++count_;
    }
    [[nodiscard]] bool empty() const { return count_ == 0; }
    [[nodiscard]] Summary summary() const {
        if (count_ == 0) return {};
        return {min_, sum_ / static_cast<double>(count_), max_};
    }

private:
    double min_ = std::numeric_limits<double>::infinity();
    double max_ = -std::numeric_limits<double>::infinity();
    double sum_ = 0.0;
    std::uint64_t count_ = 0;
};

}  // namespace

double cost(const Bvh& bvh, const VolumePolicy& policy) {
    double total = 0.0;
    for (const Node& node : bvh.nodes)
        if (!node.is_leaf()) total += node.child_count * policy.weighted_volume(node.volume);
    return total;
}

std::vector<std::uint32_t> node_depths(const Bvh& bvh) {
    std::vector<std::uint32_t> depth(bvh.nodes.size(), 0);
    for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i)
        for (std::uint32_t c = 0; c < bvh.nodes[i].child_count; ++c) depth[bvh.nodes[i].first_child + c] = depth[i] + 1;
    return depth;
}

std::uint32_t height(const Bvh& bvh) {
    const std::vector<std::uint32_t> depth = node_depths(bvh);
    return depth.empty() ? 0 : *std::max_element(depth.begin(), depth.end());
}

Stats compute_stats(const Bvh& bvh, const VolumePolicy& policy) {
    Stats stats;
    stats.nodes = static_cast<std::uint32_t>(bvh.nodes.size());
    stats.cost = cost(bvh, policy);
    VolumePolicy calibrated = policy;
    calibrated.measure = NodeMeasure::minkowski;
    stats.calibrated_cost = cost(bvh, calibrated);
    SummaryBuilder branching, tightness, leaf_depth;
    double overlap_volume = 0.0, sibling_volume = 0.0;

    const std::vector<std::uint32_t> depth = node_depths(bvh);
    std::vector<Aabb> child_boxes;
    for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
        const Node& node = bvh.nodes[i];
        ++stats.types[static_cast<std::size_t>(type_of(node.volume))];
        stats.height = std::max(stats.height, depth[i]);
        if (node.is_leaf()) {
            ++stats.leaves;
            leaf_depth.add(depth[i]);
            continue;
        }
        ++stats.inner_nodes;
        branching.add(node.child_count);
        double children_volume = 0.0;
        child_boxes.clear();
        for (std::uint32_t c = 0; c < node.child_count; ++c) {
            const Node& child = bvh.nodes[node.first_child + c];
            children_volume += volume(child.volume);
            child_boxes.push_back(world_aabb(child.volume));
            sibling_volume += child_boxes.back().volume();
        }
        // Sibling overlap: pairwise intersection of the children's world AABBs (docs/metrics.md).
        overlap_volume += detail::pairwise_intersection_volume(child_boxes);
        // Eq. 1 as it stands: a node with volume over children without any (flat boxes, points) is infinitely
        // loose, not left out (until 2026-12-07 such nodes were dropped, and a tree of only them read 0, "perfectly
        // tight"). A node without volume over children without volume has no ratio at all.
        const double own_volume = volume(node.volume);
        if (children_volume > 0.0)
            tightness.add(own_volume / children_volume);
        else if (own_volume > 0.0)
            tightness.add(std::numeric_limits<double>::infinity());
    }
    stats.branching = branching.summary();
    stats.tightness = tightness.summary();
    // Inner nodes, yet not one ratio (every volume 0): undefined, not 0.
    if (stats.inner_nodes > 0 && tightness.empty())
        stats.tightness = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::quiet_NaN()};
    stats.leaf_depth = leaf_depth.summary();
    stats.overlap = sibling_volume > 0.0 ? overlap_volume / sibling_volume : 0.0;
    return stats;
}

}  // namespace hbvh
