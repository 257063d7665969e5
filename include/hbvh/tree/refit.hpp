// SPDX-License-Identifier: MIT
// refit: repair a hand-written or foreign hierarchy whose volumes miss part of their primitives.
#pragma once

#include <cstddef>

#include "hbvh/tree/bvh.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {

/// Replaces the volume of every node in containment_violations(bvh) by the fit of the same BV kind over
/// the primitives below it (the fitters enclose by construction, with an outward rounding pad); the tree's
/// shape, every other volume and the primitives stay as they are. Returns how many volumes it replaced.
/// Precondition: check_structure(bvh) passed.
std::size_t refit_non_enclosing(Bvh& bvh, double relative_tolerance = default_containment_tolerance);

}  // namespace hbvh
