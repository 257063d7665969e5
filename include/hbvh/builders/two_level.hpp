// SPDX-License-Identifier: MIT
// Two-Level: the games industry's baseline (survey §1) — one root BV over all primitives.
#pragma once

#include <span>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Root = the allowed BV kind that fits all primitives best; every primitive is its child.
/// With only AABBs allowed this is the classic AABB-over-artist-volumes. One primitive: a lone leaf.
[[nodiscard]] Bvh build_two_level(std::span<const Primitive> primitives, const VolumePolicy& policy);

}  // namespace hbvh
