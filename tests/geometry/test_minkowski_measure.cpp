// SPDX-License-Identifier: MIT
// surface_area, mean_width and self_minkowski_volume against independent formulas: the Minkowski sum of a
// solid with a turned copy is computed exactly for each sampled turn (a zonotope for boxes, Steiner's formula
// of a parallelogram for capsules, a ball for spheres) and averaged over many seeded turns.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>

#include "hbvh/geometry/bounding_volume.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

constexpr int turns = 20000;  // Monte Carlo error of the mean well under 1 %

/// Volume of the zonotope sum of segments [0, g_i]: the sum of |det(g_i, g_j, g_k)| over i < j < k.
double zonotope_volume(const std::array<Vec3, 6>& generators) {
    double total = 0.0;
    for (std::size_t i = 0; i < 6; ++i)
        for (std::size_t j = i + 1; j < 6; ++j)
            for (std::size_t k = j + 1; k < 6; ++k)
                total += std::abs(generators[i].dot(generators[j].cross(generators[k])));
    return total;
}

/// The mean over seeded turns R of the volume of box + R box, the box given by its frame and full edges.
double mean_box_sum_volume(const Mat3& frame, const Vec3& edges) {
    SplitMix64 rng(7);
    double sum = 0.0;
    for (int t = 0; t < turns; ++t) {
        const Mat3 turned = rng.rotation() * frame;
        std::array<Vec3, 6> generators;
        for (int k = 0; k < 3; ++k) {
            generators[static_cast<std::size_t>(k)] = edges[k] * frame.col(k);
            generators[static_cast<std::size_t>(k + 3)] = edges[k] * turned.col(k);
        }
        sum += zonotope_volume(generators);
    }
    return sum / turns;
}

TEST(MinkowskiMeasure, BoxesMatchTheMeanZonotopeVolume) {
    const Vec3 edges(3.0, 1.0, 0.2);  // a flat box: its own volume says little about how often it is met
    const Aabb aabb{Vec3(1, 2, 3), Vec3(1, 2, 3) + edges};
    EXPECT_NEAR(self_minkowski_volume(aabb) / mean_box_sum_volume(Mat3::Identity(), edges), 1.0, 0.01);

    const Mat3 frame = SplitMix64(3).rotation();
    const Obb obb{Vec3(-4, 0, 9), frame, 0.5 * edges};
    EXPECT_NEAR(self_minkowski_volume(obb) / mean_box_sum_volume(frame, edges), 1.0, 0.01);
    EXPECT_DOUBLE_EQ(surface_area(obb), 2.0 * (3.0 + 0.2 + 0.6));
    EXPECT_DOUBLE_EQ(mean_width(obb), 2.1);
}

TEST(MinkowskiMeasure, CapsulesMatchSteinersFormulaOfTheAxesParallelogram) {
    // capsule + turned capsule = (axis + turned axis) + ball of 2r, a parallelogram P grown by 2r:
    // volume 2 area(P) rho + pi (|u| + |v|) rho^2 + 4/3 pi rho^3 with rho = 2r (Steiner, flat P).
    const Capsule capsule{Vec3(0, 0, 0), Vec3(2, 1, -2), 0.25};
    const Vec3 u = capsule.p1 - capsule.p0;
    const double rho = 2.0 * capsule.radius;
    SplitMix64 rng(11);
    double sum = 0.0;
    for (int t = 0; t < turns; ++t) {
        const Vec3 v = rng.rotation() * u;
        sum += 2.0 * u.cross(v).norm() * rho + std::numbers::pi * (u.norm() + v.norm()) * rho * rho +
               4.0 / 3.0 * std::numbers::pi * rho * rho * rho;
    }
    EXPECT_NEAR(self_minkowski_volume(capsule) / (sum / turns), 1.0, 0.01);
}

TEST(MinkowskiMeasure, SpheresGiveTheBallOfTwiceTheRadius) {
    const Sphere sphere{Vec3(5, 5, 5), 1.5};
    const Sphere doubled{Vec3::Zero(), 3.0};
    EXPECT_NEAR(self_minkowski_volume(sphere), doubled.volume(), 1e-12);
}

}  // namespace
}  // namespace hbvh
