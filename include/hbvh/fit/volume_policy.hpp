// SPDX-License-Identifier: MIT
// VolumePolicy: which BV kinds a builder may use and how much each one's volume counts.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string_view>

#include "hbvh/geometry/bounding_volume.hpp"
#include "hbvh/result.hpp"

namespace hbvh {

/// How a node's size enters the cost.
enum class NodeMeasure : std::uint8_t {
    volume,     ///< The survey's Eq. 2: the BV's volume.
    minkowski,  ///< self_minkowski_volume: the calibrated objective's measure (docs/metrics.md).
};

/// The BV kinds a hierarchy may use for inner nodes, with a weight per kind and the measure of a node.
/// A weighted measure (weight x volume, by default) is what fit_best minimises and what the cost sums: the
/// survey's §6.1 idea of charging complex BVs for their slower overlap tests. All weights default to 1.
struct VolumePolicy {
    std::array<bool, bv_type_count> allowed{true, true, true, true};
    std::array<double, bv_type_count> weight{1.0, 1.0, 1.0, 1.0};
    NodeMeasure measure = NodeMeasure::volume;

    [[nodiscard]] bool is_allowed(BvType type) const { return allowed[static_cast<std::size_t>(type)]; }
    [[nodiscard]] double weight_of(BvType type) const { return weight[static_cast<std::size_t>(type)]; }
    /// The measure of bv (its volume unless `measure` says otherwise), without the kind's weight.
    [[nodiscard]] double unweighted_measure(const BoundingVolume& bv) const {
        return measure == NodeMeasure::volume ? volume(bv) : self_minkowski_volume(bv);
    }
    /// weight(type of bv) x the measure of bv.
    [[nodiscard]] double weighted_volume(const BoundingVolume& bv) const {
        return weight_of(type_of(bv)) * unweighted_measure(bv);
    }

    /// Every kind allowed, weight 1.
    [[nodiscard]] static VolumePolicy all() { return {}; }
    /// Only `type` allowed.
    [[nodiscard]] static VolumePolicy only(BvType type);
};

/// The range of a kind's weight. Weights are ratios of test costs (`hbvh calibrate` measures 0.4-1.3); outside
/// [1e-6, 1e6] they only push a tree's cost towards overflow (weights of 1e308 made costs infinite, and
/// `optimal` and `auto` then never pruned) or underflow (1e-320: subnormal costs that compare as ties).
inline constexpr double min_type_weight = 1e-6;
inline constexpr double max_type_weight = 1e6;

/// Ok, or the Error that refuses a policy no builder can work with: no kind allowed, or an allowed kind whose
/// weight is not a number from min_type_weight to max_type_weight (a NaN weight made comparisons fail and
/// builders recurse without end). Every builder checks it before it starts, as it checks the primitives.
[[nodiscard]] Status validate_policy(const VolumePolicy& policy);
/// Parses "aabb,obb,sphere,capsule" (any non-empty subset, any order). Error names the bad word.
[[nodiscard]] Result<VolumePolicy> parse_allowed_types(std::string_view list, VolumePolicy base = {});
/// Parses "obb=1.5,capsule=1.2" into weights (from min_type_weight to max_type_weight, each kind at most once).
/// Error names the bad entry.
[[nodiscard]] Result<VolumePolicy> parse_type_weights(std::string_view list, VolumePolicy base = {});
/// Reads the weights `hbvh calibrate -o FILE` writes: parse_type_weights' entries, separated by commas, blanks
/// or lines, after '#' comments (its table of pairs) are dropped, a byte order mark allowed. Errors name the file.
[[nodiscard]] Result<VolumePolicy> read_type_weights_file(const std::filesystem::path& path, VolumePolicy base = {});
/// The CLI's --type-weight argument: "@FILE" reads read_type_weights_file(FILE), anything else is a list for
/// parse_type_weights.
[[nodiscard]] Result<VolumePolicy> type_weights_from(std::string_view list_or_file, VolumePolicy base = {});

}  // namespace hbvh
