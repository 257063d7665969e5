// SPDX-License-Identifier: MIT
// The capsule fitter's radius search along one axis line (capsule_segment.hpp).
#include "capsule_segment.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace hbvh::detail {

std::pair<double, double> segment_ends(const AxisDistances& a, double radius) {
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

std::pair<double, double> segment_for_radius(const AxisDistances& a, double radius) {
    auto [t0, t1] = segment_ends(a, radius);
    if (t1 < t0) t0 = t1 = 0.5 * (t0 + t1);
    return {t0, t1};
}

void keep_end_candidates(const AxisDistances& all, double low, double high, AxisDistances& kept) {
    const auto [t0_high, t1_high] = segment_ends(all, high);
    kept.axial.clear();
    kept.radius.clear();
    kept.distance_squared.clear();
    for (std::size_t i = 0; i < all.axial.size(); ++i) {
        const double slack = low - all.radius[i];
        const double h = std::sqrt(std::max(0.0, slack * slack - all.distance_squared[i]));
        if (all.axial[i] + h <= t0_high || all.axial[i] - h >= t1_high) {
            kept.axial.push_back(all.axial[i]);
            kept.radius.push_back(all.radius[i]);
            kept.distance_squared.push_back(all.distance_squared[i]);
        }
    }
}

}  // namespace hbvh::detail
