// SPDX-License-Identifier: MIT
// The filter of the capsule fitter's radius search (capsule_segment.hpp; the search's inner loop is inline there).
#include "capsule_segment.hpp"

#include <cmath>

namespace hbvh::detail {

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
