// SPDX-License-Identifier: MIT
// The lower bounds behind the treelets' fits on demand: below every fitted volume (fit_best recomputed here)
// under every policy, equal to Steiner's closed form where the hull of the spheres is a polytope grown by a
// ball, and refining with them gives the costs of fitting every set, with fewer fits.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "builders/treelet_bounds.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/builders/treelet.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/tree/stats.hpp"
#include "support/bundled_models.hpp"
#include "support/tree_properties.hpp"

namespace hbvh {
namespace {

using test_support::generated_scene;

std::vector<VolumePolicy> policies() {
    VolumePolicy weighted = VolumePolicy::all();
    weighted.weight = {1.0, 1.3, 0.45, 1.8};
    VolumePolicy minkowski = VolumePolicy::all();
    minkowski.measure = NodeMeasure::minkowski;
    return {VolumePolicy::all(), weighted, minkowski, VolumePolicy::only(BvType::obb),
            VolumePolicy::only(BvType::sphere), VolumePolicy::only(BvType::capsule), VolumePolicy::only(BvType::aabb)};
}

/// The bounds of every mask of `units` (disjoint sets of primitive indices), each from the mask's own points and
/// built up unit by unit as the refiner does, against fit_best over the mask's primitives. Returns the ratios
/// bound / fit.
std::vector<double> check_masks(std::span<const Primitive> primitives,
                                const std::vector<std::vector<std::uint32_t>>& units, const VolumePolicy& policy,
                                const std::string& what) {
    const double scale = detail::bound_scale(policy);
    const std::size_t subsets = std::size_t{1} << units.size();
    std::vector<std::vector<std::uint32_t>> sets(subsets);
    std::vector<detail::SetBound> built(subsets);
    std::vector<double> ratios;
    for (std::uint32_t mask = 1; mask < subsets; ++mask) {
        const std::uint32_t rest = mask & (mask - 1u);
        const std::uint32_t lowest = mask & ~rest;
        if (rest == 0) {
            sets[mask] = units[static_cast<std::size_t>(std::countr_zero(mask))];
            built[mask] = detail::bound_set(primitives, sets[mask], scale);
        } else {
            sets[mask] = sets[rest];
            sets[mask].insert(sets[mask].end(), sets[lowest].begin(), sets[lowest].end());
            std::sort(sets[mask].begin(), sets[mask].end());
            built[mask] = detail::bound_union(primitives, built[rest], sets[rest], built[lowest], sets[lowest], scale);
        }
        FitInput input;
        for (std::uint32_t p : sets[mask]) input.add(primitives[p].volume);
        const double fitted = policy.weighted_volume(fit_best(input.spheres, policy, input.hint_axes));
        const double own = detail::bound_set(primitives, sets[mask], scale).bound;
        EXPECT_LE(built[mask].bound, fitted) << what << ", mask " << mask;
        EXPECT_LE(own, fitted) << what << ", mask " << mask;
        EXPECT_GE(built[mask].bound, 0.0) << what << ", mask " << mask;
        ratios.push_back(built[mask].bound / fitted);
    }
    return ratios;
}

TEST(TreeletBounds, NeverAboveTheFittedVolumeUnderAnyPolicy) {
    std::mt19937_64 random(11);
    std::vector<double> ratios;
    for (bool clustered : {true, false}) {
        for (std::uint64_t seed = 1; seed <= 4; ++seed) {
            const std::vector<Primitive> primitives = generated_scene(24, seed, clustered);
            // Five units of random disjoint primitives, each of one to four.
            std::vector<std::uint32_t> order(primitives.size());
            for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
            std::shuffle(order.begin(), order.end(), random);
            std::vector<std::vector<std::uint32_t>> units;
            std::size_t next = 0;
            for (int u = 0; u < 5; ++u) {
                const std::size_t size = 1 + random() % 4;
                units.emplace_back(order.begin() + static_cast<std::ptrdiff_t>(next),
                                   order.begin() + static_cast<std::ptrdiff_t>(next + size));
                std::sort(units.back().begin(), units.back().end());
                next += size;
            }
            for (const VolumePolicy& policy : policies()) {
                const std::vector<double> some = check_masks(primitives, units, policy, "seed " + std::to_string(seed));
                ratios.insert(ratios.end(), some.begin(), some.end());
            }
        }
    }
    // Not a trivial bound: the median mask's bound is a sizeable share of its fit (a bound of 0 would pass the
    // check above and prune nothing).
    std::nth_element(ratios.begin(), ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2), ratios.end());
    EXPECT_GT(ratios[ratios.size() / 2], 0.2);
}

TEST(TreeletBounds, MatchesSteinersFormulaForBallsAtACubesCorners) {
    // Eight balls of radius r at the corners of a unit cube: the hull of their union is the cube grown by r,
    // of volume 1 + 6 r + 3 pi r^2 + 4/3 pi r^3. The bound takes each edge's right angle as its chord
    // (2 sin 45 degrees instead of pi / 2), so it lies a little below.
    for (double r : {0.05, 0.3, 1.0}) {
        std::vector<Primitive> primitives;
        for (int corner = 0; corner < 8; ++corner)
            primitives.push_back(Primitive{Sphere{Vec3(corner & 1, corner >> 1 & 1, corner >> 2 & 1), r}, ""});
        const std::vector<std::uint32_t> low{0, 1, 2, 3};
        const std::vector<std::uint32_t> high{4, 5, 6, 7};
        const std::vector<std::uint32_t> all{0, 1, 2, 3, 4, 5, 6, 7};
        const double scale = detail::bound_scale(VolumePolicy::all());
        const detail::SetBound low_bound = detail::bound_set(primitives, low, scale);
        const detail::SetBound high_bound = detail::bound_set(primitives, high, scale);
        EXPECT_EQ(low_bound.margin, r);
        const double both = detail::bound_union(primitives, low_bound, low, high_bound, high, scale).bound;
        const double pi = std::numbers::pi;
        const double exact = 1.0 + 6.0 * r + 3.0 * pi * r * r + 4.0 / 3.0 * pi * r * r * r;
        const double with_chords = 1.0 + 6.0 * r + 3.0 * pi * r * r * (2.0 * std::sin(pi / 4.0) / (pi / 2.0)) +
                                   4.0 / 3.0 * pi * r * r * r;
        EXPECT_NEAR(both, with_chords, 1e-5 * exact) << "r " << r;
        EXPECT_LT(both, exact) << "r " << r;
        EXPECT_NEAR(detail::bound_set(primitives, all, scale).bound, both, 1e-9 * exact) << "r " << r;
        // Each half is a flat square of balls: no solid hull of centres, so the bound is the unit square grown
        // by r, 2 r + 2 pi r^2 + 4/3 pi r^3 (its edges' exterior angles are exactly pi).
        EXPECT_NEAR(low_bound.bound, 2.0 * r + 2.0 * pi * r * r + 4.0 / 3.0 * pi * r * r * r, 1e-5 * exact) << "r " << r;
    }
}

TEST(TreeletBounds, FlatSetsGetTheirPolygonsBoundNeverAboveTheFit) {
    // Capsules and balls of one radius whose axes and centres lie in a plane (a walker's legs, a hand's
    // fingers) span no solid: the bound is their polygon grown by the radius, not one ball. Exactly flat,
    // off the plane by 1e-9, by 1e-4 (then the margin left shrinks), and on one line (a capsule).
    std::mt19937_64 random(5);
    std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
    std::vector<double> ratios;
    for (double wobble : {0.0, 1e-9, 1e-4}) {
        for (bool line : {false, true}) {
            const double r = 0.05;
            std::vector<Primitive> primitives;
            const auto point = [&] {
                const double y = line ? 0.0 : coordinate(random);
                return Vec3(coordinate(random), y, wobble * coordinate(random));
            };
            for (int i = 0; i < 6; ++i) {
                if (i % 3 == 2)
                    primitives.push_back(Primitive{Sphere{point(), r}, ""});
                else
                    primitives.push_back(Primitive{Capsule{point(), point(), r}, ""});
            }
            std::vector<std::vector<std::uint32_t>> units;
            for (std::uint32_t i = 0; i < primitives.size(); ++i) units.push_back({i});
            for (const VolumePolicy& policy : policies()) {
                const std::string what = "wobble " + std::to_string(wobble) + (line ? " on a line" : "");
                const std::vector<double> some = check_masks(primitives, units, policy, what);
                ratios.insert(ratios.end(), some.begin(), some.end());
            }
            // Above the ball the bound was before: a polygon's bound grows with its area and perimeter.
            const std::vector<std::uint32_t> all{0, 1, 2, 3, 4, 5};
            const double scale = detail::bound_scale(VolumePolicy::all());
            const double ball = 4.0 / 3.0 * std::numbers::pi * r * r * r * scale;
            EXPECT_GT(detail::bound_set(primitives, all, scale).bound, 10.0 * ball);
        }
    }
    std::nth_element(ratios.begin(), ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2), ratios.end());
    EXPECT_GT(ratios[ratios.size() / 2], 0.2);
}

TEST(TreeletBounds, RefiningWithThemGivesTheCostsOfFittingEverySetWithFewerFits) {
    std::vector<std::pair<std::string, std::vector<Primitive>>> inputs;
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        inputs.emplace_back("clustered " + std::to_string(seed), generated_scene(30, seed));
        inputs.emplace_back("uniform " + std::to_string(seed), generated_scene(30, seed, false));
    }
    for (auto& [name, primitives] : test_support::bundled_models()) inputs.emplace_back(name, primitives);
    VolumePolicy minkowski = VolumePolicy::all();
    minkowski.measure = NodeMeasure::minkowski;
    const std::vector<VolumePolicy> policies{VolumePolicy::all(), minkowski, VolumePolicy::only(BvType::sphere)};
    std::vector<std::uint64_t> fits_on_demand(policies.size(), 0);
    std::vector<std::uint64_t> fits_of_every_set(policies.size(), 0);
    for (const auto& [name, primitives] : inputs) {
        for (std::size_t k = 0; k < policies.size(); ++k) {
            const VolumePolicy& policy = policies[k];
            BuildContext context;
            context.policy = policy;
            Result<Bvh> built = build(primitives, Algorithm::insertion, context);
            ASSERT_TRUE(built.has_value()) << name;
            TreeletOptions every_set;
            every_set.bound_fits = false;
            TreeletReport on_demand_report;
            TreeletReport every_set_report;
            const Bvh on_demand = refine_treelets(*built, policy, {}, &on_demand_report);
            const Bvh fitted_all = refine_treelets(*built, policy, every_set, &every_set_report);
            EXPECT_NEAR(cost(on_demand, policy), cost(fitted_all, policy), 1e-12 * cost(fitted_all, policy)) << name;
            EXPECT_LE(on_demand_report.fits, every_set_report.fits) << name;
            fits_on_demand[k] += on_demand_report.fits;
            fits_of_every_set[k] += every_set_report.fits;
        }
    }
    // Under Eq. 2 with every kind, 6 557 of 10 205 fits when written (on the bundled models alone 2-10x fewer).
    EXPECT_LT(fits_on_demand[0], 0.8 * static_cast<double>(fits_of_every_set[0]));
    // Spheres only: the fits are cheap and are all made (docs/treelets.md, "Fits on demand").
    EXPECT_EQ(fits_on_demand[2], fits_of_every_set[2]);
}

}  // namespace
}  // namespace hbvh
