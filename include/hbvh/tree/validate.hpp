// SPDX-License-Identifier: MIT
// validate: the whole-tree invariants every builder must keep.
#pragma once

#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Checks: indices in range and children contiguous after their parent; every input primitive in
/// exactly one leaf; no inner node with fewer than 2 children; every node's BV contains every covered
/// primitive (relative tolerance `relative_tolerance` of the node's size); leaves carry their primitive's BV.
/// The Error names the first node that fails.
[[nodiscard]] Status validate(const Bvh& bvh, double relative_tolerance = 1e-9);

}  // namespace hbvh
