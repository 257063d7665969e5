// SPDX-License-Identifier: MIT
// Two-Level: the games industry's baseline (survey §1) — one root BV over all primitives.
#pragma once

#include <span>

#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_two_level (none; kept for the common builder shape).
struct TwoLevelOptions {};

/// Root = the allowed BV kind that fits all primitives best; every primitive is its child.
/// With only AABBs allowed this is the classic AABB-over-artist-volumes. One primitive: a lone leaf.
[[nodiscard]] Result<Bvh> build_two_level(std::span<const Primitive> primitives, const BuildContext& context,
                                          const TwoLevelOptions& options = {});

}  // namespace hbvh
