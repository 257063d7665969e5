// SPDX-License-Identifier: MIT
// Internal: the capsule fitter's radius search along one axis line, and the filter that lets it read only
// the spheres that can set an end of the segment.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace hbvh::detail {

/// Per-sphere numbers the radius search reads: axial coordinate, own radius and squared distance from the
/// axis line, computed once per direction as plain arrays (the search reads them ~30 times per direction).
struct AxisDistances {
    std::vector<double> axial;
    std::vector<double> radius;
    std::vector<double> distance_squared;
};

// Defined here, inline: the radius search calls these ~500 times per capsule fit, most of them over the few
// spheres of a golden-section bracket, where the call itself weighed (the cannon's build 1.6 % fewer instructions).

/// The ends of the shortest segment on the axis line for capsule radius `radius`, before the fix-up for
/// t1 < t0. Sphere i (distance d_i from the line) is inside iff its centre is within radius - r_i of the
/// segment, i.e. the segment reaches within h_i = sqrt((radius - r_i)^2 - d_i^2) of t_i along the axis:
/// t0 <= t_i + h_i and t1 >= t_i - h_i. So t0 = min(t_i + h_i), t1 = max(t_i - h_i).
[[nodiscard]] inline std::pair<double, double> segment_ends(const AxisDistances& a, double radius) {
    // Two spheres per step in SSE2 lanes (this loop is the capsule fitter's inner loop). min and max are
    // exact, so the lanes' order changes no result.
    using Pair = Eigen::Array2d;
    const std::size_t count = a.axial.size();
    const double* axial = a.axial.data();
    const double* own = a.radius.data();
    const double* d2 = a.distance_squared.data();
    Pair low = Pair::Constant(std::numeric_limits<double>::infinity());
    Pair high = Pair::Constant(-std::numeric_limits<double>::infinity());
    std::size_t i = 0;
    for (; i + 2 <= count; i += 2) {
        const Pair slack = radius - Pair::Map(own + i);
        const Pair h = (slack * slack - Pair::Map(d2 + i)).max(0.0).sqrt();
        low = low.min(Pair::Map(axial + i) + h);
        high = high.max(Pair::Map(axial + i) - h);
    }
    double t0 = std::min(low[0], low[1]);
    double t1 = std::max(high[0], high[1]);
    for (; i < count; ++i) {
        const double slack = radius - own[i];
        const double h = std::sqrt(std::max(0.0, slack * slack - d2[i]));
        t0 = std::min(t0, axial[i] + h);
        t1 = std::max(t1, axial[i] - h);
    }
    return {t0, t1};
}

/// The shortest segment [t0, t1] for capsule radius `radius` (segment_ends); when t1 < t0 any single point
/// of [t1, t0] works and the capsule is a sphere.
[[nodiscard]] inline std::pair<double, double> segment_for_radius(const AxisDistances& a, double radius) {
    auto [t0, t1] = segment_ends(a, radius);
    if (t1 < t0) t0 = t1 = 0.5 * (t0 + t1);
    return {t0, t1};
}

/// The spheres of `all` that can set an end of the segment for some radius in [low, high], into `kept`:
/// for every radius in that range segment_for_radius gives bit for bit the same from `kept` as from `all`.
/// h_i grows with the radius, and so does its computed value (every rounding step is monotone), so the
/// sphere that sets t0 at a radius r has t_i + h_i(low) <= t_i + h_i(r) <= t_j + h_j(r) <= t_j + h_j(high)
/// for every j: a sphere whose t_i + h_i(low) exceeds the smallest t_j + h_j(high) never sets t0 (t1 alike).
/// The radius search evaluates ~25 radii in a bracket; near its ends few spheres compete (4 of 34 on average
/// in FitSmall/capsule/16).
void keep_end_candidates(const AxisDistances& all, double low, double high, AxisDistances& kept);

}  // namespace hbvh::detail
