// SPDX-License-Identifier: MIT
// Internal: validate()'s words for a volume that misses a primitive below it, one text for both of its overloads
// (a Bvh's, and a QueryTree's in query/).
#pragma once

#include <cstdint>

#include "hbvh/geometry/bounding_volume.hpp"
#include "hbvh/result.hpp"

namespace hbvh::detail {

/// "node N: its KIND does not contain primitive P (by D)", D to three significant digits.
[[nodiscard]] Error containment_error(std::uint32_t node, BvType kind, std::uint32_t primitive, double protrusion);

}  // namespace hbvh::detail
