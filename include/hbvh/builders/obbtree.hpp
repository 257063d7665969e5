// SPDX-License-Identifier: MIT
// Gottschalk et al.'s OBB-tree construction (survey §2.2): split at the mean centre along the OBB's longest axis.
#pragma once

#include <span>

#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_obbtree.
struct ObbTreeOptions {
    /// true: every inner node gets the covariance OBB, as in the original OBB-tree (the policy is then
    /// ignored for inner nodes). false (default): the covariance OBB only chooses the split; the node BV
    /// is fit_best under the policy, so the hierarchy stays heterogeneous.
    bool covariance_obb_volumes = false;
};

/// Binary hierarchy: at each node fit_obb_covariance over the covered primitives; cut perpendicular to
/// its longest axis at the mean of the primitives' centres (projected), assigning each primitive by the
/// side of its centre. If one side is empty, the other two axes are tried (longest first), then a median
/// cut along the longest axis. Recursion stops at single primitives.
/// The cost does not depend on the order of `primitives`. Deadline: checked at every node.
[[nodiscard]] Result<Bvh> build_obbtree(std::span<const Primitive> primitives, const BuildContext& context,
                                        const ObbTreeOptions& options = {});

}  // namespace hbvh
