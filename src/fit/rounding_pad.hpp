// SPDX-License-Identifier: MIT
// Internal: the pad the fitters add to a computed size so that containment survives re-evaluation.
#pragma once

namespace hbvh::detail {

/// A tiny relative pad (about 4 ulps of `magnitude`). Fitted centres and extents are rounded, and callers
/// may re-evaluate containment with different rounding (fused multiply-add contraction), so a size that is
/// merely tight could miss a generating sphere by an ulp. `magnitude` is that of the numbers the rounding
/// happened on: the size when the fit works on differences of nearby points (local box coordinates,
/// distances), the coordinates themselves when it rounds them (fit_aabb's centre -/+ radius), so that the
/// pad holds however far from the origin the set lies.
inline double rounding_pad(double magnitude) { return magnitude * 0x1.0p-50; }

}  // namespace hbvh::detail
