// SPDX-License-Identifier: MIT
// Internal: a cheap volume below which no capsule around a set of spheres can go, so that fit_best can
// skip the (expensive) capsule fitter when a kind it already has is smaller.
#pragma once

#include <limits>
#include <span>

#include "frames.hpp"

namespace hbvh::detail {

/// A lower bound on the volume of every capsule containing the proxy's spheres. `planes` are frames
/// whose coordinate planes are tried as cross-sections (any frames are valid; the axes of a tight box
/// around the set give the strongest bound). Proof sketch, for a capsule of radius r and length L:
///  * its diameter is L + 2r, so L + 2r >= D, the set's diameter (or any lower bound of it: large sets use
///    the farthest pair among extremal spheres);
///  * every plane P through the origin contains a direction u perpendicular to the capsule's axis, and
///    the capsule's width along such a u is 2r, so 2r >= the smallest width of the set along P;
///  * the volume pi r^2 L + 4/3 pi r^3 >= pi r^2 max(0, D - 2r) + 4/3 pi r^3, which grows with r.
/// The planes are tried in order and the search stops once the bound reaches `enough` (a caller that only
/// asks "can a capsule beat this?" then pays for few planes).
[[nodiscard]] double capsule_volume_lower_bound(const SphereProxy& proxy, std::span<const Mat3> planes,
                                                double enough = std::numeric_limits<double>::infinity());

}  // namespace hbvh::detail
