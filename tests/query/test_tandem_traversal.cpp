// SPDX-License-Identifier: MIT
// Tandem traversal and the two-level baseline against brute force, for every registered builder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <functional>
#include <limits>
#include <string>
#include <variant>
#include <type_traits>

#include "hbvh/assert.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/builders/optimal.hpp"
#include "hbvh/geometry/overlap.hpp"
#include "hbvh/geometry/validation.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

using Pairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

/// Every primitive pair tested with overlaps(), in a's model frame as the query defines it.
Pairs brute_force(const Bvh& a, const RigidTransform& pose_a, const Bvh& b, const RigidTransform& pose_b) {
    const RigidTransform t = relative_transform(pose_a, pose_b);
    Pairs pairs;
    for (std::uint32_t j = 0; j < b.primitives.size(); ++j) {
        const BoundingVolume moved = transformed(b.primitives[j].volume, t);
        for (std::uint32_t i = 0; i < a.primitives.size(); ++i)
            if (overlaps(a.primitives[i].volume, moved)) pairs.emplace_back(i, j);
    }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
}

Vec3 scene_center(const Bvh& bvh) {
    Aabb box = Aabb::empty();
    for (const Primitive& p : bvh.primitives) box = box.merged(world_aabb(p.volume));
    return box.center();
}

double scene_radius(const Bvh& bvh) {
    Aabb box = Aabb::empty();
    for (const Primitive& p : bvh.primitives) box = box.merged(world_aabb(p.volume));
    return 0.5 * (box.max - box.min).norm();
}

/// A pose of b whose centre lands within `spread` x (radius of a) of a's centre, randomly rotated, so
/// that the roots overlap most of the time and the scenes interpenetrate to varying depths.
RigidTransform pose_near(const Bvh& a, const RigidTransform& pose_a, const Bvh& b, std::uint64_t seed, double spread) {
    SplitMix64 rng(seed);
    const RigidTransform spin{rng.rotation(), Vec3::Zero()};
    const Vec3 offset = spread * scene_radius(a) * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const RigidTransform to_origin{Mat3::Identity(), -scene_center(b)};
    const RigidTransform to_target{Mat3::Identity(), pose_a.apply(scene_center(a)) + offset};
    return to_target * spin * to_origin;
}

/// A containing BV of kind `kind` (0..3) around the spheres: exact-enough fits written here so that the
/// traversal is tested on deep, heterogeneous trees whatever the registered builders produce.
BoundingVolume containing_volume(const std::vector<Sphere>& spheres, int kind, SplitMix64& rng) {
    Aabb box = Aabb::empty();
    for (const Sphere& s : spheres) box = box.merged({s.center - Vec3::Constant(s.radius), s.center + Vec3::Constant(s.radius)});
    const Vec3 m = box.center();
    switch (kind) {
        case 0: return box;
        case 1: {
            const Mat3 r = rng.rotation();
            Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
            for (const Sphere& s : spheres) {
                const Vec3 local = r.transpose() * s.center;
                lo = lo.cwiseMin(local - Vec3::Constant(s.radius));
                hi = hi.cwiseMax(local + Vec3::Constant(s.radius));
            }
            return Obb{r * (0.5 * (lo + hi)), r, 0.5 * (hi - lo)};
        }
        case 2: {
            double radius = 0.0;
            for (const Sphere& s : spheres) radius = std::max(radius, (s.center - m).norm() + s.radius);
            return Sphere{m, radius};
        }
        default: {
            int axis = 0;
            (box.max - box.min).maxCoeff(&axis);
            const Vec3 u = Vec3::Unit(axis);
            double t0 = 1e300, t1 = -1e300;
            for (const Sphere& s : spheres) {
                t0 = std::min(t0, (s.center - m).dot(u));
                t1 = std::max(t1, (s.center - m).dot(u));
            }
            Capsule c{m + t0 * u, m + t1 * u, 0.0};
            for (const Sphere& s : spheres) c.radius = std::max(c.radius, (s.center - c.closest_axis_point(s.center)).norm() + s.radius);
            return c;
        }
    }
}

/// Test-only builder: binary or ternary median splits along the longest centroid axis, each inner node
/// a random BV kind, padded by 1e-9 so that containment survives rounding.
std::uint32_t add_subtree(TreeAssembler& assembler, std::span<const Primitive> primitives,
                          std::vector<std::uint32_t> ids, SplitMix64& rng) {
    if (ids.size() == 1) return assembler.add_leaf(ids.front());
    Aabb spread = Aabb::empty();
    std::vector<Sphere> spheres;
    for (const std::uint32_t id : ids) {
        const Vec3 c = world_aabb(primitives[id].volume).center();
        spread = spread.merged({c, c});
        append_generating_spheres(primitives[id].volume, spheres);
    }
    for (Sphere& s : spheres) s.radius += 1e-9;
    int axis = 0;
    (spread.max - spread.min).maxCoeff(&axis);
    std::sort(ids.begin(), ids.end(), [&](std::uint32_t x, std::uint32_t y) {
        return world_aabb(primitives[x].volume).center()[axis] < world_aabb(primitives[y].volume).center()[axis];
    });
    const std::size_t parts = ids.size() >= 6 && rng.uniform() < 0.3 ? 3 : 2;
    std::vector<std::uint32_t> children;
    for (std::size_t p = 0; p < parts; ++p) {
        const std::size_t lo = p * ids.size() / parts, hi = (p + 1) * ids.size() / parts;
        children.push_back(add_subtree(assembler, primitives, {ids.begin() + lo, ids.begin() + hi}, rng));
    }
    return assembler.add_group(children, containing_volume(spheres, static_cast<int>(rng.below(4)), rng));
}

Bvh build_deep_mixed(std::span<const Primitive> primitives, std::uint64_t seed) {
    SplitMix64 rng(seed);
    TreeAssembler assembler(primitives);
    std::vector<std::uint32_t> ids(primitives.size());
    for (std::uint32_t i = 0; i < ids.size(); ++i) ids[i] = i;
    const std::uint32_t root = add_subtree(assembler, primitives, ids, rng);
    return std::move(assembler).finish(root);
}

struct Case {
    std::uint32_t count_a, count_b;
    std::uint64_t seed;
};

/// One builder's trees over the shared cases: all, first and two-level against brute force.
/// Work over all queries of check_builder: primitive tests run by pure descent (flat limit 0: the default
/// tests small and concentric pairs flat on purpose) vs primitive pairs that exist.
struct Work {
    std::uint64_t primitive_tests = 0, primitive_pairs = 0;
};

/// `max_count`: cases with a bigger object are skipped.
Work check_builder(const std::string& name, const std::function<Bvh(std::span<const Primitive>, std::uint64_t)>& make,
                   std::uint32_t max_count = std::numeric_limits<std::uint32_t>::max()) {
    // Up to the survey's largest object (27 primitives): builders such as branch and bound may be
    // exponential, and the suite must stay fast. Two copies of one object share one build.
    const std::array cases{Case{1, 1, 3}, Case{2, 5, 4}, Case{13, 13, 5}, Case{27, 27, 6}, Case{27, 9, 7}, Case{20, 20, 8}};
    std::uint64_t queries = 0, intersecting = 0, root_overlaps = 0;
    Work work;
    {
        for (const Case& c : cases) {
            if (std::max(c.count_a, c.count_b) > max_count) continue;
            const auto prims_a = generate_scene({.count = c.count_a, .seed = c.seed});
            const auto prims_b = c.count_a == c.count_b ? prims_a : generate_scene({.count = c.count_b, .seed = c.seed + 100});
            const Bvh a = make(prims_a, c.seed);
            const Bvh b = c.count_a == c.count_b ? a : make(prims_b, c.seed + 1);
            const QueryTree qa(a), qb(b);
            CollideResult reused;
            for (std::uint64_t k = 0; k < 300; ++k) {
                const RigidTransform pose_a = random_transform(1000 * c.seed + k, 10.0);
                const RigidTransform pose_b = pose_near(a, pose_a, b, 7777 * c.seed + k, k % 3 == 0 ? 0.2 : 1.0);
                const Pairs expected = brute_force(a, pose_a, b, pose_b);
                const std::string where = name + " case " + std::to_string(c.seed) + " pose " + std::to_string(k);

                // Pure descent (no pair tested flat) and pure flat (the roots' leaves tested pairwise) must agree
                // with the default's mix.
                for (const std::uint64_t flat_limit : {std::uint64_t{0}, std::numeric_limits<std::uint64_t>::max()}) {
                    collide(qa, pose_a, qb, pose_b, CollideMode::all, reused, flat_limit);
                    EXPECT_EQ(reused.pairs, expected) << where << " flat limit " << flat_limit;
                    if (flat_limit == 0) work.primitive_tests += reused.primitive_tests;  // the hierarchy's own pruning
                }
                collide(qa, pose_a, qb, pose_b, CollideMode::all, reused);
                EXPECT_EQ(reused.pairs, expected) << where;
                EXPECT_EQ(reused.intersecting, !expected.empty()) << where;
                EXPECT_LE(reused.primitive_tests, std::uint64_t{c.count_a} * c.count_b) << where;

                const CollideResult first = collide(qa, pose_a, qb, pose_b, CollideMode::first);
                EXPECT_EQ(first.intersecting, !expected.empty()) << where;
                EXPECT_EQ(first.pairs.size(), expected.empty() ? 0u : 1u) << where;
                if (!first.pairs.empty()) {
                    EXPECT_TRUE(std::binary_search(expected.begin(), expected.end(), first.pairs.front())) << where;
                }

                const CollideResult baseline = collide_two_level(qa, pose_a, qb, pose_b, CollideMode::all);
                EXPECT_EQ(baseline.pairs, expected) << where;
                const CollideResult baseline_first = collide_two_level(qa, pose_a, qb, pose_b, CollideMode::first);
                EXPECT_EQ(baseline_first.intersecting, !expected.empty()) << where;

                work.primitive_pairs += std::uint64_t{c.count_a} * c.count_b;
                ++queries;
                intersecting += expected.empty() ? 0 : 1;
                root_overlaps += reused.nodes_visited > 0 ? 1 : 0;
            }
        }
    }
    // The poses must exercise the traversal: mostly overlapping roots, a mix of hits and misses.
    EXPECT_GT(root_overlaps, queries * 3 / 4);
    EXPECT_GT(intersecting, queries / 4);
    EXPECT_LT(intersecting, queries);
    return work;
}

/// One CTest entry per builder, so that the slow builders' cases run in parallel with the rest.
class TandemTraversalPerBuilder : public testing::TestWithParam<AlgorithmInfo> {};

TEST_P(TandemTraversalPerBuilder, MatchesBruteForce) {
    const AlgorithmInfo& info = GetParam();
    // Above its limit optimal builds bnb-exact's tree (optimal.hpp), which bnb-exact's own entry checks on the
    // same cases, so optimal's entry keeps the cases it solves itself: its 20- and 27-primitive builds were
    // bnb-exact's again, most of its 55-90 s under the sanitizers. The branch-and-bound builders stop at 20
    // primitives: their trees there have the same mixed kinds and several levels, and the two 27-primitive builds
    // were most of their 20-34 s (bnb-exact builds the tie interceptor's 27 primitives in 15 s under the sanitizers).
    std::uint32_t max_count = std::numeric_limits<std::uint32_t>::max();
    const Algorithm algorithm = info.algorithm();
    if (algorithm == Algorithm::optimal)
        max_count = OptimalOptions{}.max_primitives;
    else if (algorithm == Algorithm::bnb_exact || algorithm == Algorithm::bnb_tightest ||
             algorithm == Algorithm::bnb_enlarge)
        max_count = 20;
    check_builder(std::string(info.name), [&](std::span<const Primitive> primitives, std::uint64_t) {
        auto built = build(primitives, info.algorithm());
        HBVH_ASSERT(built.has_value());
        return std::move(built).value();
    }, max_count);
}

INSTANTIATE_TEST_SUITE_P(EveryAlgorithm, TandemTraversalPerBuilder,
                         testing::ValuesIn(algorithms().begin(), algorithms().end()),
                         [](const testing::TestParamInfo<AlgorithmInfo>& param) {
                             std::string name(param.param.name);
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

/// Copies on top of each other: the roots nearly share a centre, so every leaf pair is tested directly (one BV
/// test, the roots'), with the brute-force answer; moved aside by more than half the smaller root sphere's
/// radius, or with the flat limit at 0, the same pair of trees is descended again.
TEST(TandemTraversal, ConcentricRootsAreTestedLeafByLeaf) {
    const std::vector<Primitive> primitives = generate_scene({.count = 13, .seed = 21});
    const Result<Bvh> built = build(primitives, Algorithm::split);
    ASSERT_TRUE(built.has_value());
    const QueryTree tree(*built);
    const double radius = tree.nodes()[0].sphere_radius;
    const RigidTransform pose_a = RigidTransform::identity();
    const RigidTransform turned{Eigen::AngleAxisd(0.3, Vec3(0, 0, 1)).toRotationMatrix(), Vec3::Zero()};
    // A turn about the root sphere's centre keeps the centres together.
    const Vec3 centre = tree.nodes()[0].center;
    const RigidTransform concentric{turned.rotation, centre - turned.rotation * centre + Vec3(0.2 * radius, 0, 0)};
    const RigidTransform aside{turned.rotation, concentric.translation + Vec3(0.4 * radius, 0, 0)};
    for (const bool together : {true, false}) {
        const RigidTransform& pose_b = together ? concentric : aside;
        const CollideResult result = collide(tree, pose_a, tree, pose_b, CollideMode::all);
        EXPECT_EQ(result.pairs, brute_force(*built, pose_a, *built, pose_b));
        EXPECT_FALSE(result.pairs.empty());
        if (together) {
            EXPECT_EQ(result.bv_tests, 1u);
            EXPECT_EQ(result.primitive_tests, primitives.size() * primitives.size());
        } else {
            EXPECT_GT(result.bv_tests, 1u);
        }
        CollideResult descended;
        collide(tree, pose_a, tree, pose_b, CollideMode::all, descended, 0);
        EXPECT_EQ(descended.pairs, result.pairs);
        EXPECT_GT(descended.bv_tests, 1u);
    }
}

/// Spheres of radius `radius` on a circle of radius 10 about the origin in the z = 0 plane, at the angles
/// 2 pi (i + offset) / 100.
std::vector<Primitive> ring(std::uint32_t count, double offset, double radius) {
    std::vector<Primitive> spheres;
    for (std::uint32_t i = 0; i < count; ++i) {
        const double angle = 2.0 * 3.14159265358979323846 * (i + offset) / 100.0;
        spheres.push_back({Sphere{Vec3(10.0 * std::cos(angle), 10.0 * std::sin(angle), 0.0), radius}, ""});
    }
    return spheres;
}

TEST(TandemTraversal, LargeConcentricRootsAreProbedLeafByLeafInModeFirst) {
    // Above the concentric rule's limit (100 x 100 leaf pairs), mode first tries a few leaf pairs before it
    // descends: copies on top of each other then meet at once, with the roots' test the only inner one.
    const std::vector<Primitive> primitives = generate_scene({.count = 100, .seed = 21});
    const Bvh bvh = build(primitives, Algorithm::split).value();
    const QueryTree tree(bvh);
    const Vec3 centre = tree.nodes()[0].center;
    const Mat3 turn = Eigen::AngleAxisd(0.05, Vec3(0, 0, 1)).toRotationMatrix();
    const RigidTransform concentric{turn, centre - turn * centre};
    const Pairs all = brute_force(bvh, RigidTransform::identity(), bvh, concentric);
    ASSERT_FALSE(all.empty());
    const CollideResult first = collide(tree, RigidTransform::identity(), tree, concentric, CollideMode::first);
    ASSERT_EQ(first.pairs.size(), 1u);
    EXPECT_TRUE(std::binary_search(all.begin(), all.end(), first.pairs.front()));
    EXPECT_EQ(first.bv_tests, 1u);
    EXPECT_LE(first.primitive_tests, 64u);
    // Mode all keeps its limit (1024 pairs) and descends.
    const CollideResult every = collide(tree, RigidTransform::identity(), tree, concentric, CollideMode::all);
    EXPECT_EQ(every.pairs, all);
    EXPECT_GT(every.bv_tests, 1u);

    // Two concentric rings, a's 100 spheres interleaved with b's 41, which meet a's only where b's sphere 20
    // is moved onto a's sphere 20 (and b's central sphere meets nothing): the probe's pairs all miss, and the
    // descent must still find the one contact, or none once it is moved away again.
    const std::vector<Primitive> ring_a = ring(100, 0.0, 0.1);
    std::vector<Primitive> ring_b = ring(41, 0.5, 0.1);
    ring_b.push_back({Sphere{Vec3::Zero(), 2.0}, ""});
    const Bvh tree_a = build(ring_a, Algorithm::split).value();
    for (const bool touching : {true, false}) {
        ring_b[20].volume = ring(21, touching ? 0.0 : 0.5, 0.1)[20].volume;
        const Bvh tree_b = build(ring_b, Algorithm::split).value();
        const Pairs expected = brute_force(tree_a, RigidTransform::identity(), tree_b, RigidTransform::identity());
        ASSERT_EQ(expected.size(), touching ? 1u : 0u);
        const CollideResult probed = collide(QueryTree(tree_a), RigidTransform::identity(), QueryTree(tree_b),
                                             RigidTransform::identity(), CollideMode::first);
        EXPECT_EQ(probed.pairs, expected) << touching;
        EXPECT_GT(probed.bv_tests, 1u) << touching;  // the probe did not answer: the descent did
        EXPECT_GE(probed.primitive_tests, 64u) << touching;
    }
}

TEST(TandemTraversal, SmallConcentricRootsTryTheCheapestLeafPairsFirstInModeFirst) {
    // Boxes, oriented boxes and capsules around one small sphere, listed first in no order of kind: on a
    // copy of itself (concentric roots, few leaf pairs) mode first tests every leaf pair in contact order,
    // so the sphere against its copy answers at the first leaf test, wherever the builder put it.
    const Mat3 tilt = Eigen::AngleAxisd(0.4, Vec3(1, 1, 0).normalized()).toRotationMatrix();
    std::vector<Primitive> primitives;
    for (int i = 0; i < 12; ++i) {
        const Vec3 at(std::cos(0.5 * i) * 2.0, std::sin(0.5 * i) * 2.0, 0.1 * i);
        if (i % 3 == 0) primitives.push_back({Aabb{at - Vec3(0.5, 0.4, 0.3), at + Vec3(0.5, 0.4, 0.3)}, ""});
        else if (i % 3 == 1) primitives.push_back({Obb{at, tilt, Vec3(0.6, 0.3, 0.2)}, ""});
        else primitives.push_back({Capsule{at - Vec3(0.3, 0.0, 0.0), at + Vec3(0.3, 0.0, 0.0), 0.2}, ""});
    }
    primitives.push_back({Sphere{Vec3(0.0, 0.0, 0.6), 0.05}, ""});
    const std::uint32_t sphere = static_cast<std::uint32_t>(primitives.size() - 1);
    const Bvh bvh = build(primitives, Algorithm::split).value();
    const QueryTree tree(bvh);

    // The order holds every leaf once, kinds in the order of their exact test's cost.
    std::vector<std::uint32_t> order(tree.contact_order().begin(), tree.contact_order().end());
    std::vector<std::uint32_t> leaves(tree.leaves().begin(), tree.leaves().end());
    std::sort(order.begin(), order.end());
    std::sort(leaves.begin(), leaves.end());
    EXPECT_EQ(order, leaves);
    ASSERT_FALSE(tree.contact_order().empty());
    EXPECT_EQ(tree.nodes()[tree.contact_order().front()].primitive, sphere);
    ASSERT_NE(tree.leaves().front(), tree.contact_order().front());  // else the test would not tell the orders apart

    const CollideResult first = collide(tree, RigidTransform::identity(), tree, RigidTransform::identity(), CollideMode::first);
    ASSERT_EQ(first.pairs.size(), 1u);
    EXPECT_EQ(first.pairs.front(), std::make_pair(sphere, sphere));
    EXPECT_EQ(first.primitive_tests, 1u);

    // Moved so that the spheres miss (and many other pairs do not): the answer is still a pair brute force finds.
    const RigidTransform shifted{Eigen::AngleAxisd(0.3, Vec3(0, 0, 1)).toRotationMatrix(), Vec3(0.05, 0.0, 0.2)};
    const Pairs all = brute_force(bvh, RigidTransform::identity(), bvh, shifted);
    ASSERT_FALSE(all.empty());
    ASSERT_FALSE(std::binary_search(all.begin(), all.end(), std::make_pair(sphere, sphere)));
    const CollideResult moved = collide(tree, RigidTransform::identity(), tree, shifted, CollideMode::first);
    ASSERT_EQ(moved.pairs.size(), 1u);
    EXPECT_TRUE(std::binary_search(all.begin(), all.end(), moved.pairs.front()));
    EXPECT_EQ(moved.bv_tests, 1u);  // the roots' test alone: the pairs were tested flat
}

TEST(TandemTraversal, MatchesBruteForceOnDeepMixedTrees) {
    const Work work = check_builder("deep-mixed", build_deep_mixed);
    // A real hierarchy must prune: far fewer primitive tests than the two-level method's all pairs.
    EXPECT_LT(work.primitive_tests, work.primitive_pairs / 2);
}

/// Every primitive pair, both primitives moved to the world by their own object's pose: the definition of
/// the answer, independent of relative_transform and of the query's frame.
Pairs world_brute_force(const Bvh& a, const RigidTransform& pose_a, const Bvh& b, const RigidTransform& pose_b) {
    Pairs pairs;
    for (std::uint32_t i = 0; i < a.primitives.size(); ++i) {
        const BoundingVolume world_a = transformed(a.primitives[i].volume, pose_a);
        for (std::uint32_t j = 0; j < b.primitives.size(); ++j)
            if (overlaps(world_a, transformed(b.primitives[j].volume, pose_b))) pairs.emplace_back(i, j);
    }
    return pairs;  // ascending by construction
}

TEST(TandemTraversal, BvhOverloadAndEmptyTrees) {
    // Multi-level trees (a one-level tree would leave the traversal's descent untested), from builders
    // that merge, split and insert differently.
    const auto prims = generate_scene({.count = 13, .seed = 21});
    const auto others = generate_scene({.count = 9, .seed = 22});
    for (const Algorithm algorithm :
         {Algorithm::split, Algorithm::insertion, Algorithm::merge, Algorithm::bnb_exact, Algorithm::scale}) {
        const std::string name(to_string(algorithm));
        const Bvh bvh = build(prims, algorithm).value();
        const Bvh other = build(others, algorithm).value();
        ASSERT_GE(compute_stats(bvh).height, 2u) << name;
        ASSERT_GE(compute_stats(other).height, 2u) << name;
        const RigidTransform pose = RigidTransform::identity();
        // Identical poses: every primitive touches at least itself.
        const CollideResult r = collide(bvh, pose, bvh, pose, CollideMode::all);
        EXPECT_TRUE(r.intersecting) << name;
        for (std::uint32_t i = 0; i < prims.size(); ++i)
            EXPECT_TRUE(std::binary_search(r.pairs.begin(), r.pairs.end(), std::pair{i, i})) << name << " " << i;
        EXPECT_EQ(r.pairs, world_brute_force(bvh, pose, bvh, pose)) << name;
        // Random poses, the two objects interpenetrating to varying depths.
        int hits = 0;
        for (std::uint64_t k = 0; k < 40; ++k) {
            const RigidTransform pose_a = random_transform(300 + k, 10.0);
            const RigidTransform pose_b = pose_near(bvh, pose_a, other, 900 + k, k % 2 == 0 ? 0.3 : 1.0);
            const Pairs expected = world_brute_force(bvh, pose_a, other, pose_b);
            const std::string where = name + " pose " + std::to_string(k);
            const CollideResult all = collide(bvh, pose_a, other, pose_b, CollideMode::all);
            EXPECT_EQ(all.pairs, expected) << where;
            EXPECT_EQ(all.intersecting, !expected.empty()) << where;
            EXPECT_EQ(collide(bvh, pose_a, other, pose_b, CollideMode::first).intersecting, !expected.empty()) << where;
            EXPECT_EQ(collide_two_level(bvh, pose_a, other, pose_b, CollideMode::all).pairs, expected) << where;
            hits += expected.empty() ? 0 : 1;
        }
        EXPECT_GT(hits, 0) << name;   // the poses produce contacts
        EXPECT_LT(hits, 40) << name;  // and misses
    }
    const Bvh bvh = build(prims, Algorithm::split).value();
    const RigidTransform pose = RigidTransform::identity();
    const Bvh empty;
    EXPECT_FALSE(collide(empty, pose, bvh, pose).intersecting);
    EXPECT_FALSE(collide_two_level(bvh, pose, empty, pose).intersecting);
}

// A pose accepted within rotation_tolerance but not orthonormal to rounding is read as its nearest rotation, on every
// path of the query. A user's construction (2026-12-07): 40 boxes sharing a face at x = 1e6 + 0.01, b's pose
// diag(1 + 4e-10, 1 - 4e-10, 1) with translation (-1e6, 0, 0), a sphere 1e-4 beyond box 20's face under the nearest
// rotation (the identity) and 3e-4 inside it under the matrix as given. R^T taken as the inverse moved one path's
// geometry by 4e-4: the two-level tree reported the pair and every deeper tree did not. Now every builder's tree
// gives what brute force gives under the nearest rotation.
TEST(TandemTraversal, APoseNearlyARotationIsReadAsItsNearestRotation) {
    constexpr double epsilon = 4e-10;
    std::vector<Primitive> boxes;
    for (int k = 0; k < 40; ++k)
        boxes.push_back({Aabb{Vec3(1e6 - 0.01, 0.01 * k - 0.004, -0.01), Vec3(1e6 + 0.01, 0.01 * k + 0.004, 0.01)}, ""});
    const double face = (1.0 + epsilon) * (1e6 + 0.01) - 1e6;
    const std::vector<Primitive> sphere{{Sphere{Vec3(face + 1e-3 - 3e-4, 0.2 * (1.0 - epsilon), 0.0), 1e-3}, ""}};
    RigidTransform pose_b{Mat3(Vec3(1.0 + epsilon, 1.0 - epsilon, 1.0).asDiagonal()), Vec3(-1e6, 0.0, 0.0)};
    ASSERT_TRUE(validate_pose(pose_b));  // accepted, within rotation_tolerance
    const RigidTransform nearest{nearest_rotation(pose_b.rotation), pose_b.translation};
    ASSERT_TRUE(nearest.rotation.isApprox(Mat3::Identity(), 1e-15));
    for (const Algorithm algorithm : {Algorithm::two_level, Algorithm::split, Algorithm::automatic, Algorithm::fast,
                                      Algorithm::obb_tree, Algorithm::merge, Algorithm::binned}) {
        const std::string name(to_string(algorithm));
        const Bvh a = build(sphere, algorithm).value();
        const Bvh b = build(boxes, algorithm).value();
        const Pairs expected = world_brute_force(a, RigidTransform::identity(), b, nearest);
        EXPECT_EQ(collide(a, RigidTransform::identity(), b, pose_b).pairs, expected) << name;
        EXPECT_EQ(collide_two_level(a, RigidTransform::identity(), b, pose_b).pairs, expected) << name;
    }
}

TEST(QueryTreeValidate, AgreesWithTheBvhsValidateWordForWord) {
    // validate(QueryTree), for trees loaded straight into the query layout, against validate(Bvh) (the oracle)
    // on sound trees of several builders and on each of them with one inner volume shrunk.
    const std::vector<Primitive> primitives = generate_scene({.count = 40, .seed = 8});
    std::size_t refused = 0;
    for (const Algorithm algorithm : {Algorithm::split, Algorithm::binned, Algorithm::two_level, Algorithm::fast}) {
        Result<Bvh> bvh = build(primitives, algorithm);
        ASSERT_TRUE(bvh.has_value()) << bvh.error().to_string();
        EXPECT_TRUE(validate(QueryTree(*bvh))) << to_string(algorithm);
        for (std::uint32_t i = 0; i < bvh->nodes.size(); ++i) {
            if (bvh->nodes[i].is_leaf()) continue;
            Bvh shrunk = *bvh;
            // The node's volume, moved by a tenth of its size: some primitive below then sticks out.
            std::visit([&](auto& v) {
                using Kind = std::decay_t<decltype(v)>;
                const double shift = 0.1 * size_scale(shrunk.nodes[i].volume);
                if constexpr (std::is_same_v<Kind, Aabb>) v.min.x() += shift, v.max.x() += shift;
                else if constexpr (std::is_same_v<Kind, Capsule>) v.p0.x() += shift, v.p1.x() += shift;
                else v.center.x() += shift;
            }, shrunk.nodes[i].volume);
            const Status by_bvh = validate(shrunk);
            const Status by_query_tree = validate(QueryTree(shrunk));
            ASSERT_EQ(by_bvh.has_value(), by_query_tree.has_value()) << "node " << i;
            if (!by_bvh) {
                EXPECT_EQ(by_query_tree.error().message, by_bvh.error().message);
                ++refused;
            }
        }
    }
    EXPECT_GT(refused, 10u);
}

TEST(TandemTraversal, StackBoundCoversTwoLevelFanOut) {
    // A two-level tree over 300 primitives needs a stack beyond the built-in 256 entries.
    const auto prims = generate_scene({.count = 300, .seed = 5});
    const Bvh bvh = build(prims, Algorithm::two_level).value();
    const QueryTree tree(bvh);
    EXPECT_EQ(tree.stack_bound(), 300u);
    const RigidTransform pose = RigidTransform::identity();
    const CollideResult r = collide(tree, pose, tree, pose, CollideMode::all);
    EXPECT_EQ(r.pairs, brute_force(bvh, pose, bvh, pose));
}

TEST(TandemTraversal, HeapStackBeyondTheLocalCapacity) {
    // Two two-level trees over 600 primitives: 1201 stack entries, beyond the 1024 kept on the machine stack.
    const auto prims = generate_scene({.count = 600, .seed = 6});
    const Bvh bvh = build(prims, Algorithm::two_level).value();
    const QueryTree tree(bvh);
    ASSERT_GT(2 * tree.stack_bound() + 1, 1024u);
    const RigidTransform pose_b = pose_near(bvh, RigidTransform::identity(), bvh, 11, 0.3);
    const CollideResult r = collide(tree, RigidTransform::identity(), tree, pose_b, CollideMode::all);
    EXPECT_EQ(r.pairs, brute_force(bvh, RigidTransform::identity(), bvh, pose_b));
}

TEST(QueryTree, EnclosingSpheresContainEveryNode) {
    // The sphere pre-test may only reject pairs whose BVs are apart: each node's sphere (centre, padded
    // radius) must contain its BV, checked on the BV's generating spheres, for every kind of BV.
    for (const std::uint64_t seed : {1u, 2u, 3u}) {
        const auto prims = generate_scene({.count = 27, .seed = seed});
        const Bvh bvh = build_deep_mixed(prims, seed);
        const QueryTree tree(bvh);
        ASSERT_EQ(tree.nodes().size(), bvh.nodes.size());
        for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
            const QueryNode& node = tree.nodes()[i];
            EXPECT_EQ(node.type, type_of(bvh.nodes[i].volume));
            for (const Sphere& s : generating_spheres(bvh.nodes[i].volume))
                EXPECT_LE((s.center - node.center).norm() + s.radius, node.sphere_radius) << "node " << i;
        }
    }
}

TEST(QueryTree, EnclosingBoxesContainEveryNode) {
    // The box test may only reject pairs whose BVs are apart: each node's box (centre, axes, half extents)
    // must contain its BV, checked on the BV's generating spheres in the box's frame, for every kind.
    for (const std::uint64_t seed : {1u, 2u, 3u}) {
        const auto prims = generate_scene({.count = 27, .seed = seed});
        const Bvh bvh = build_deep_mixed(prims, seed);
        const QueryTree tree(bvh);
        std::array<int, 4> kinds{};
        for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
            const QueryNode& node = tree.nodes()[i];
            ++kinds[static_cast<std::size_t>(node.type)];
            EXPECT_LT((node.rotation.transpose() * node.rotation - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-12);
            EXPECT_EQ(node.axis_aligned, node.rotation == Mat3::Identity()) << "node " << i;
            for (const Sphere& s : generating_spheres(bvh.nodes[i].volume)) {
                const Vec3 local = node.rotation.transpose() * (s.center - node.center);
                EXPECT_TRUE((local.cwiseAbs().array() + s.radius <= node.half_extents.array()).all())
                    << "node " << i << " sphere at " << s.center.transpose();
            }
        }
        for (const int count : kinds) EXPECT_GT(count, 0);  // every kind of BV was checked
    }
}

TEST(QueryTree, LeafRangesAreEachSubtreesLeaves) {
    // Each node's [leaf_begin, leaf_begin + leaf_count) of leaves() must be exactly the leaves below it,
    // found here by walking the Bvh's child ranges.
    const auto prims = generate_scene({.count = 27, .seed = 5});
    const Bvh bvh = build_deep_mixed(prims, 5);
    const QueryTree tree(bvh);
    ASSERT_EQ(tree.leaves().size(), prims.size());
    for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
        std::vector<std::uint32_t> below, pending{i};
        while (!pending.empty()) {
            const std::uint32_t n = pending.back();
            pending.pop_back();
            if (bvh.nodes[n].is_leaf()) below.push_back(n);
            for (std::uint32_t c = 0; c < bvh.nodes[n].child_count; ++c) pending.push_back(bvh.nodes[n].first_child + c);
        }
        const QueryNode& node = tree.nodes()[i];
        ASSERT_LE(std::size_t{node.leaf_begin} + node.leaf_count, tree.leaves().size());
        std::vector<std::uint32_t> range(tree.leaves().begin() + node.leaf_begin,
                                         tree.leaves().begin() + node.leaf_begin + node.leaf_count);
        std::sort(below.begin(), below.end());
        std::sort(range.begin(), range.end());
        EXPECT_EQ(range, below) << "node " << i;
    }
}

TEST(QueryTree, PreTestsNeverRejectAnExactOverlap) {
    // Random pairs of single-node trees of every kind, moved so that they touch or overlap: whatever the
    // kinds, collide() on inner-node-free trees is the exact test, and on trees whose roots are inner
    // nodes the conservative tests must still reach every overlapping primitive pair (brute force).
    SplitMix64 rng(31);
    for (int n = 0; n < 200; ++n) {
        const auto prims = generate_scene({.count = 2 + static_cast<std::uint32_t>(rng.below(6)), .seed = 500u + n});
        const Bvh bvh = build_deep_mixed(prims, 900u + n);
        const QueryTree tree(bvh);
        for (int k = 0; k < 10; ++k) {
            const RigidTransform pose_b = pose_near(bvh, RigidTransform::identity(), bvh, 10000u * n + k, 0.5);
            EXPECT_EQ(collide(tree, RigidTransform::identity(), tree, pose_b).pairs,
                      brute_force(bvh, RigidTransform::identity(), bvh, pose_b))
                << "tree " << n << " pose " << k;
        }
    }
}

}  // namespace
}  // namespace hbvh
