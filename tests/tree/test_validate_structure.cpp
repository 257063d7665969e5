// SPDX-License-Identifier: MIT
// check_structure, containment_violations, protrusion and refit_non_enclosing: malformed trees are refused
// without reading out of bounds, violations match a brute force over sampled points, refits repair them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "hbvh/builders/build.hpp"
#include "hbvh/geometry/overlap.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/refit.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {
namespace {

Primitive structure_box_at(double x) { return {Aabb{Vec3(x, 0, 0), Vec3(x + 1, 1, 1)}, "box"}; }

/// Four unit boxes grouped ((0,1),(2,3)), laid out by hand: 0 root, 1-2 groups, 3-6 leaves.
Bvh hand_laid_pairs() {
    Bvh bvh;
    for (int i = 0; i < 4; ++i) bvh.primitives.push_back(structure_box_at(2.0 * i));
    bvh.nodes.push_back({Aabb{Vec3(0, 0, 0), Vec3(7, 1, 1)}, 1, 2, 0});
    bvh.nodes.push_back({Aabb{Vec3(0, 0, 0), Vec3(3, 1, 1)}, 3, 2, 0});
    bvh.nodes.push_back({Aabb{Vec3(4, 0, 0), Vec3(7, 1, 1)}, 5, 2, 0});
    for (std::uint32_t i = 0; i < 4; ++i) bvh.nodes.push_back({bvh.primitives[i].volume, 0, 0, i});
    return bvh;
}

/// check_structure's message, or "" when it passes; also checks QueryTree refuses the same trees.
std::string structure_problem(const Bvh& bvh) {
    const Status status = check_structure(bvh);
    EXPECT_EQ(status.has_value(), QueryTree::create(bvh).has_value());
    if (!status) {
        EXPECT_FALSE(validate(bvh));  // validate() checks the structure first, and safely
    }
    return status ? std::string{} : status.error().message;
}

TEST(CheckStructure, AcceptsAHandLaidBreadthFirstTree) { EXPECT_EQ(structure_problem(hand_laid_pairs()), ""); }

TEST(CheckStructure, RefusesChildRangesPastTheEndWithoutReadingThem) {
    Bvh bvh = hand_laid_pairs();
    bvh.nodes[2].first_child = 6;  // 6 + 2 > 7 nodes
    EXPECT_NE(structure_problem(bvh).find("past the end"), std::string::npos);
}

TEST(CheckStructure, RefusesAChildRangeWhoseEndOverflows32Bits) {
    Bvh bvh = hand_laid_pairs();
    bvh.nodes[2].first_child = 5;
    bvh.nodes[2].child_count = UINT32_MAX - 2;  // 5 + count wraps to 2 in 32 bits
    EXPECT_NE(structure_problem(bvh).find("past the end"), std::string::npos);
}

TEST(CheckStructure, RefusesANonBreadthFirstOrder) {
    // Swapping the two groups' child ranges keeps every index in range and every node with one parent,
    // but node 1's children no longer come first: depth-first-like orders break the level layout.
    Bvh bvh = hand_laid_pairs();
    std::swap(bvh.nodes[1].first_child, bvh.nodes[2].first_child);
    std::swap(bvh.nodes[1].volume, bvh.nodes[2].volume);
    EXPECT_NE(structure_problem(bvh).find("breadth-first"), std::string::npos);
    // A child range pointing back at the root (a cycle).
    Bvh cycle = hand_laid_pairs();
    cycle.nodes[1].first_child = 0;
    EXPECT_NE(structure_problem(cycle), "");
}

TEST(CheckStructure, RefusesMissingDuplicateAndOutOfRangePrimitives) {
    Bvh duplicate = hand_laid_pairs();
    duplicate.nodes[6].primitive = 0;
    EXPECT_NE(structure_problem(duplicate).find("two leaves"), std::string::npos);
    Bvh missing = hand_laid_pairs();
    missing.nodes[6].primitive = 99;
    EXPECT_NE(structure_problem(missing).find("missing primitive"), std::string::npos);
    Bvh extra = hand_laid_pairs();
    extra.primitives.push_back(structure_box_at(20));
    EXPECT_NE(structure_problem(extra).find("in no leaf"), std::string::npos);
}

TEST(CheckStructure, RefusesBadGeometryInANodeOrAPrimitive) {
    Bvh nan_node = hand_laid_pairs();
    nan_node.nodes[1].volume = Sphere{Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0), 5.0};
    EXPECT_NE(structure_problem(nan_node).find("node 1"), std::string::npos);
    Bvh negative = hand_laid_pairs();
    negative.primitives[2].volume = Sphere{Vec3(4, 0, 0), -1.0};
    EXPECT_NE(structure_problem(negative).find("primitive 2"), std::string::npos);
}

/// A two-level tree over `count` unit boxes in a row: the root and one leaf per box.
Bvh wide_row(std::uint32_t count) {
    Bvh bvh;
    for (std::uint32_t i = 0; i < count; ++i) bvh.primitives.push_back(structure_box_at(2.0 * i));
    bvh.nodes.push_back({Aabb{Vec3(0, 0, 0), Vec3(2.0 * count - 1.0, 1, 1)}, 1, count, 0});
    for (std::uint32_t i = 0; i < count; ++i) bvh.nodes.push_back({bvh.primitives[i].volume, 0, 0, i});
    return bvh;
}

TEST(CheckStructure, LargeTreesReportTheSameProblemsInTheSameOrder) {
    // From 2^14 nodes the primitives and the nodes are checked by two tasks; the answer must be the one
    // the sequential order gives: the primitives' problem first, then the nodes', then the leaves' coverage.
    for (const std::uint32_t count : {100u, 40'000u}) {
        SCOPED_TRACE(count);
        EXPECT_EQ(structure_problem(wide_row(count)), "");
        Bvh both = wide_row(count);
        both.primitives[count - 3].volume = Sphere{Vec3(0, 0, 0), -1.0};
        both.nodes[count / 2].volume = Sphere{Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0), 1.0};
        EXPECT_EQ(structure_problem(both).rfind("primitive " + std::to_string(count - 3), 0), 0u) << structure_problem(both);
        Bvh node_only = wide_row(count);
        node_only.nodes[count / 2].volume = Sphere{Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0), 1.0};
        EXPECT_EQ(structure_problem(node_only).rfind("node " + std::to_string(count / 2), 0), 0u) << structure_problem(node_only);
        Bvh duplicate = wide_row(count);
        duplicate.nodes[count].primitive = 0;
        EXPECT_NE(structure_problem(duplicate).find("two leaves"), std::string::npos);
        Bvh uncovered = wide_row(count);
        uncovered.primitives.push_back(structure_box_at(-5));
        EXPECT_EQ(structure_problem(uncovered), "primitive " + std::to_string(count) + " is in no leaf");
    }
}

TEST(QueryTree, LargeTreesConvertAsSmallOnesDo) {
    // From 2^14 nodes the conversion runs as two tasks: the nodes, leaves, bounds and stack bound must be what
    // a tree with the same shape gives, checked against the Bvh directly.
    const Bvh bvh = wide_row(40'000);
    const QueryTree tree(bvh);
    ASSERT_EQ(tree.nodes().size(), bvh.nodes.size());
    EXPECT_EQ(tree.stack_bound(), 40'000u);
    EXPECT_EQ(tree.nodes()[0].leaf_count, 40'000u);
    EXPECT_DOUBLE_EQ(tree.extent_bound(), tree.nodes()[0].half_extents.sum());
    for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
        const QueryNode& q = tree.nodes()[i];
        ASSERT_EQ(q.first_child, bvh.nodes[i].first_child);
        ASSERT_EQ(q.child_count, bvh.nodes[i].child_count);
        const Aabb box = std::get<Aabb>(bvh.nodes[i].volume);
        const Aabb& copied = std::get<Aabb>(tree.volume(i));
        ASSERT_TRUE(copied.min == box.min && copied.max == box.max);
        ASSERT_NEAR((q.center - box.center()).norm(), 0.0, 1e-12);
        ASSERT_GE(q.sphere_radius, box.half_extents().norm());
        if (i > 0) {
            ASSERT_EQ(tree.primitive_nodes()[bvh.nodes[i].primitive], i);
            ASSERT_EQ(tree.leaves()[q.leaf_begin], i);
        }
    }
    // The farthest centre is the last box's, (2 x 39 999 + 0.5, 0.5, 0.5); the stand-ins' padding is 1e-12 of it.
    EXPECT_NEAR(tree.coordinate_bound(), 2.0 * 39'999 + 1.5, 1e-6);
}

/// Largest per-face (boxes) or radial (round volumes) excess of `point` over `bv`, written independently of
/// protrusion(): boxes through their corners' frame, round volumes through distances.
double point_excess(const BoundingVolume& bv, const Vec3& point) {
    if (const auto* box = std::get_if<Aabb>(&bv)) {
        double worst = -1e300;
        for (int i = 0; i < 3; ++i) worst = std::max({worst, box->min[i] - point[i], point[i] - box->max[i]});
        return worst;
    }
    if (const auto* box = std::get_if<Obb>(&bv)) {
        double worst = -1e300;
        for (int i = 0; i < 3; ++i)
            worst = std::max(worst, std::abs(box->rotation.col(i).dot(point - box->center)) - box->half_extents[i]);
        return worst;
    }
    if (const auto* sphere = std::get_if<Sphere>(&bv)) return (point - sphere->center).norm() - sphere->radius;
    const Capsule& capsule = std::get<Capsule>(bv);
    // Distance to the axis segment by dense sampling of the segment (no closed form shared with the library).
    double nearest = 1e300;
    for (int k = 0; k <= 2000; ++k) nearest = std::min(nearest, (point - (capsule.p0 + (k / 2000.0) * (capsule.p1 - capsule.p0))).norm());
    return nearest - capsule.radius;
}

/// Points of a primitive: box corners, and points on the surface of each round end (Fibonacci sphere).
std::vector<Vec3> sample_points(const BoundingVolume& primitive) {
    std::vector<Vec3> points;
    for (const Sphere& s : generating_spheres(primitive)) {
        if (s.radius == 0.0) {
            points.push_back(s.center);
            continue;
        }
        constexpr int count = 400;
        for (int k = 0; k < count; ++k) {
            const double z = 1.0 - 2.0 * (k + 0.5) / count, r = std::sqrt(1.0 - z * z);
            const double phi = k * 2.399963229728653;
            points.push_back(s.center + s.radius * Vec3(r * std::cos(phi), r * std::sin(phi), z));
        }
    }
    return points;
}

TEST(Protrusion, MatchesTheWorstSampledPointOfTheSphere) {
    SplitMix64 rng(11);
    const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * rng.uniform(); };
    const auto random_point = [&](double w) { return Vec3(uniform(-w, w), uniform(-w, w), uniform(-w, w)); };
    const Mat3 rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const std::vector<BoundingVolume> volumes{Aabb{Vec3(-1, -2, -0.5), Vec3(1, 1, 2)},
                                              Obb{Vec3(0.5, 0, 0), rotation, Vec3(1, 0.5, 2)},
                                              Sphere{Vec3(0, 1, 0), 1.5}, Capsule{Vec3(-1, 0, 0), Vec3(1, 1, 0), 0.75}};
    for (const BoundingVolume& volume : volumes) {
        for (int trial = 0; trial < 50; ++trial) {
            const Sphere s{random_point(2.5), uniform(0.0, 1.0)};
            double sampled = -1e300;
            for (const Vec3& p : sample_points(Sphere(s))) sampled = std::max(sampled, point_excess(volume, p));
            const double exact = protrusion(volume, s);
            // Sampled points lie in s, so they never reach further than the exact value; 400 points on a
            // sphere of radius <= 1 come within ~0.01 of its extreme point in any direction.
            EXPECT_LE(sampled, exact + 1e-9) << to_string(type_of(volume)) << " trial " << trial;
            EXPECT_GE(sampled, exact - 0.02) << to_string(type_of(volume)) << " trial " << trial;
            EXPECT_EQ(exact <= 0.01, contains(volume, s, 0.01)) << to_string(type_of(volume)) << " trial " << trial;
        }
    }
}

TEST(ContainmentViolations, MatchABruteForceOverSampledPointsOnShrunkTrees) {
    const std::vector<Primitive> primitives = generate_scene({.count = 24, .seed = 5});
    for (const Algorithm algorithm : {Algorithm::split, Algorithm::merge, Algorithm::insertion}) {
        Bvh bvh = build(primitives, algorithm).value();
        ASSERT_TRUE(validate(bvh)) << to_string(algorithm);
        EXPECT_TRUE(containment_violations(bvh).empty());
        // Shrink every other inner volume by 15 %: those (and perhaps nothing else) now miss primitives.
        for (std::uint32_t i = 0; i < bvh.nodes.size(); i += 2) {
            Node& node = bvh.nodes[i];
            if (node.is_leaf()) continue;
            std::visit(Overloaded{[](Aabb& b) {
                                      const Vec3 c = b.center(), h = 0.85 * b.half_extents();
                                      b = Aabb{c - h, c + h};
                                  },
                                  [](Obb& b) { b.half_extents *= 0.85; }, [](Sphere& s) { s.radius *= 0.85; },
                                  [](Capsule& c) { c.radius *= 0.85; }},
                       node.volume);
        }
        const std::vector<ContainmentViolation> violations = containment_violations(bvh);
        ASSERT_FALSE(violations.empty()) << to_string(algorithm);
        // Brute force: the worst sampled point below each node, against the reported violations.
        for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
            double worst = -1e300;
            for (std::uint32_t p : covered_primitives(bvh, i))
                for (const Vec3& point : sample_points(bvh.primitives[p].volume))
                    worst = std::max(worst, point_excess(bvh.nodes[i].volume, point));
            const auto found = std::find_if(violations.begin(), violations.end(),
                                            [&](const ContainmentViolation& v) { return v.node == i; });
            const double tolerance = containment_tolerance(bvh.nodes[i].volume);
            if (worst > tolerance) {
                ASSERT_NE(found, violations.end()) << "node " << i << " misses a point by " << worst;
                EXPECT_GE(found->protrusion, worst - 1e-12);
                EXPECT_LE(found->protrusion, worst + 0.02 * size_scale(bvh.nodes[i].volume));
            } else if (found != violations.end()) {
                // Only a round primitive's extreme point, between the samples, may be what is missed.
                EXPECT_LE(found->protrusion, 0.02 * size_scale(bvh.nodes[i].volume)) << "node " << i;
            }
        }
        // Refitting repairs exactly those volumes, keeps the shape, and the tree is then valid.
        Bvh repaired = bvh;
        EXPECT_EQ(refit_non_enclosing(repaired), violations.size());
        EXPECT_TRUE(validate(repaired)) << to_string(algorithm);
        for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
            EXPECT_EQ(repaired.nodes[i].first_child, bvh.nodes[i].first_child);
            EXPECT_EQ(repaired.nodes[i].child_count, bvh.nodes[i].child_count);
            EXPECT_EQ(type_of(repaired.nodes[i].volume), type_of(bvh.nodes[i].volume));
        }
        // And the queries on the repaired tree equal brute force over primitive pairs.
        const RigidTransform pose = RigidTransform::from_quaternion(0.9, 0.1, 0.4, 0.0, Vec3(0.5, 0.2, 0.0));
        const CollideResult result = collide(repaired, RigidTransform::identity(), repaired, pose);
        std::vector<std::pair<std::uint32_t, std::uint32_t>> expected;
        for (std::uint32_t i = 0; i < primitives.size(); ++i)
            for (std::uint32_t j = 0; j < primitives.size(); ++j)
                if (overlaps(repaired.primitives[i].volume, transformed(repaired.primitives[j].volume, pose)))
                    expected.emplace_back(i, j);
        EXPECT_EQ(result.pairs, expected) << to_string(algorithm);
    }
}

TEST(ContainmentViolations, DeepAndLargeTreesMatchANodeByNodeWalk) {
    // containment_violations reads each node's spheres as one depth-first run, kind by kind, on both cores (a
    // 40 000-deep chain took 8.6 s node by node). The walk it replaced is the reference here: every node's
    // covered primitives, their generating spheres, protrusion() through the variant; same nodes, same worst
    // primitive (ties to the lowest index), the same reach to the bit.
    std::vector<Primitive> rope;
    for (int i = 0; i < 400; ++i)  // in order along a line: insertion makes a chain about 100 deep
        rope.push_back({Capsule{Vec3(i, 0.1 * (i % 3), 0), Vec3(i + 0.8, 0, 0.1 * (i % 5)), 0.3}, ""});
    const std::vector<Primitive> scene = generate_scene({.count = 3000, .seed = 11});
    for (const auto& [primitives, algorithm] : {std::pair{rope, Algorithm::insertion}, std::pair{scene, Algorithm::split}}) {
        Bvh bvh = build(primitives, algorithm).value();
        for (std::uint32_t i = 0; i < bvh.nodes.size(); i += 3) {  // shrink every third inner volume by 10 %
            if (bvh.nodes[i].is_leaf()) continue;
            std::visit(Overloaded{[](Aabb& b) {
                                      const Vec3 c = b.center(), h = 0.9 * b.half_extents();
                                      b = Aabb{c - h, c + h};
                                  },
                                  [](Obb& b) { b.half_extents *= 0.9; }, [](Sphere& s) { s.radius *= 0.9; },
                                  [](Capsule& c) { c.radius *= 0.9; }},
                       bvh.nodes[i].volume);
        }
        std::vector<ContainmentViolation> expected;
        for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
            const BoundingVolume& volume = bvh.nodes[i].volume;
            double worst = containment_tolerance(volume);
            std::optional<std::uint32_t> primitive;
            for (std::uint32_t p : covered_primitives(bvh, i))
                for (const Sphere& s : generating_spheres(bvh.primitives[p].volume))
                    if (const double reach = protrusion(volume, s); reach > worst || (primitive && reach == worst && p < *primitive))
                        worst = reach, primitive = p;
            if (primitive) expected.push_back({i, *primitive, worst});
        }
        const std::vector<ContainmentViolation> found = containment_violations(bvh);
        ASSERT_GT(expected.size(), 10u) << to_string(algorithm);
        ASSERT_EQ(found.size(), expected.size()) << to_string(algorithm);
        for (std::size_t k = 0; k < found.size(); ++k) {
            EXPECT_EQ(found[k].node, expected[k].node);
            EXPECT_EQ(found[k].primitive, expected[k].primitive) << "node " << expected[k].node;
            EXPECT_EQ(found[k].protrusion, expected[k].protrusion) << "node " << expected[k].node;
        }
    }
}

TEST(Validate, ToleranceIsRelativeForSmallModels) {
    // A model of a millimetre: a volume 1e-6 short of its primitive (0.1 % of its size) is not "enclosing",
    // though an absolute 1e-9 floor of one unit would... not catch 1e-10 either; check both scales.
    for (const double scale : {1e-3, 1.0, 1e3}) {
        Bvh bvh = hand_laid_pairs();
        for (Primitive& p : bvh.primitives) {
            Aabb& box = std::get<Aabb>(p.volume);
            box = Aabb{box.min * scale, box.max * scale};
        }
        for (Node& node : bvh.nodes) {
            Aabb& box = std::get<Aabb>(node.volume);
            box = Aabb{box.min * scale, box.max * scale};
        }
        ASSERT_TRUE(validate(bvh)) << scale;
        // Short by 1e-7 of the model's size: far above 1e-9 relative, and far below 1e-9 absolute at 1e-3.
        std::get<Aabb>(bvh.nodes[2].volume).max.x() -= 1e-7 * scale;
        EXPECT_FALSE(validate(bvh)) << scale;
    }
}

}  // namespace
}  // namespace hbvh
